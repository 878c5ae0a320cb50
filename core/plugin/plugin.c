/* plugin.c — the plugin loader. The ABI version is a data symbol, read from the file's ELF dynamic
 * symbol table before the object is even loaded, so no plugin code (not even an ELF constructor) runs
 * before it is checked; then the entry function's descriptor is checked field by field. Every refusal
 * is one line naming the file and the cause. */
#define _GNU_SOURCE /* dladdr() */
#include "plugin/plugin_loader.h"
#include "util/file.h"
#include "util/runtime.h"
#include "util/util.h"

#include "murk/integrator.h"
#include "murk/material.h"
#include "murk/medium.h"
#include "murk/phase.h"
#include "murk/transmittance.h"

#include <dirent.h>
#include <errno.h>
#include <dlfcn.h>
#include <elf.h>
#include <execinfo.h>
#include <signal.h>
#include <link.h>
#include <stdarg.h>
#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

const char *murk_kind_name(int kind)
{
    switch (kind) {
    case MURK_KIND_MATERIAL: return "material";
    case MURK_KIND_MEDIUM: return "medium";
    case MURK_KIND_INTEGRATOR: return "integrator";
    case MURK_KIND_TRANSMITTANCE: return "transmittance";
    case MURK_KIND_PHASE: return "phase";
    default: return "unknown-kind";
    }
}

static const char *article(int kind) { return kind == MURK_KIND_INTEGRATOR ? "an" : "a"; }

static void add_dir(murk_registry *r, const char *d, size_t len)
{
    if (len == 0)
        return;
    char *s = murk_xmalloc(len + 1);
    memcpy(s, d, len);
    for (size_t i = 0; i < r->ndirs; i++)
        if (strcmp(r->dirs[i], s) == 0) {
            free(s);
            return;
        }
    r->dirs = murk_xrealloc(r->dirs, (r->ndirs + 1) * sizeof *r->dirs);
    r->dirs[r->ndirs++] = s;
}

/* 1 if the running program lives in murk's build tree (plugin_loader.h). */
int murk_running_uninstalled(void)
{
    char exe[PATH_MAX], root[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0)
        return 0;
    exe[n] = 0;
    if (!realpath(MURK_BUILD_ROOT, root))
        return 0;
    size_t rl = strlen(root);
    return strncmp(exe, root, rl) == 0 && exe[rl] == '/';
}

/* The plugin folder of the libmurk this code runs in: DIR/murk/plugins for DIR/libmurk.so, so that an
 * install that was moved, or staged with DESTDIR, finds its own built-in plugins (MURK_PLUGINDIR, the
 * configured prefix's folder, is only the fallback). 0, or -1 if the library's file is unknown. */
static int plugindir_beside_libmurk(char *out, size_t n)
{
    char lib[PATH_MAX];
    if (murk_library_dir(lib, sizeof lib) != 0)
        return -1;
    int k = snprintf(out, n, "%s/murk/plugins", lib);
    return k > 0 && (size_t)k < n ? 0 : -1;
}

void murk_registry_init(murk_registry *r)
{
    memset(r, 0, sizeof *r);
    const char *env = getenv("MURK_PLUGIN_PATH");
    if (env) {
        for (const char *p = env;;) {
            const char *c = strchr(p, ':');
            add_dir(r, p, c ? (size_t)(c - p) : strlen(p));
            if (!c)
                break;
            p = c + 1;
        }
    }
    if (murk_running_uninstalled()) {
        add_dir(r, MURK_BUILD_PLUGINDIR, strlen(MURK_BUILD_PLUGINDIR));
        return;
    }
    char beside[PATH_MAX];
    if (plugindir_beside_libmurk(beside, sizeof beside) == 0)
        add_dir(r, beside, strlen(beside));
    add_dir(r, MURK_PLUGINDIR, strlen(MURK_PLUGINDIR));
}

void murk_plugin_close(murk_plugin *p)
{
    if (p->handle)
        dlclose(p->handle);
    free(p->path);
    memset(p, 0, sizeof *p);
}

void murk_registry_free(murk_registry *r)
{
    for (size_t i = 0; i < r->nloaded; i++) {
        murk_plugin_close(r->loaded[i]);
        free(r->loaded[i]);
    }
    for (size_t i = 0; i < r->ndirs; i++)
        free(r->dirs[i]);
    free(r->loaded);
    free(r->dirs);
    memset(r, 0, sizeof *r);
}

/* The ABI 1.0 size of a kind's vtable: plugins built against 1.0 headers have exactly this, later
 * minors more (methods are appended; the host checks MURK_HAS before calling one of those). */
static size_t vtable_min_size(int kind)
{
    switch (kind) {
    case MURK_KIND_MATERIAL: return MURK_MATERIAL_VT_SIZE_1_0;
    case MURK_KIND_MEDIUM: return MURK_MEDIUM_VT_SIZE_1_0;
    case MURK_KIND_INTEGRATOR: return MURK_INTEGRATOR_VT_SIZE_1_0;
    case MURK_KIND_TRANSMITTANCE: return MURK_TRANSMITTANCE_VT_SIZE_1_2; /* the kind's first ABI */
    case MURK_KIND_PHASE: return MURK_PHASE_VT_SIZE_1_9;
    default: return 0;
    }
}

static int fail(char *err, size_t errlen, const char *path, const char *fmt, ...) MURK_PRINTF(4, 5);
static int fail(char *err, size_t errlen, const char *path, const char *fmt, ...)
{
    int k = snprintf(err, errlen, "plugin %s: ", path);
    va_list ap;
    va_start(ap, fmt);
    if (k >= 0 && (size_t)k < errlen)
        vsnprintf(err + k, errlen - (size_t)k, fmt, ap);
    va_end(ap);
    return -1;
}

static int check_params(const murk_plugin_desc *d, const char *path, char *err, size_t errlen)
{
    if (d->nparams && !d->params)
        return fail(err, errlen, path, "descriptor lists %u parameters but no table", d->nparams);
    for (uint32_t i = 0; i < d->nparams; i++) {
        const murk_param *p = &d->params[i];
        if (!p->name || !*p->name)
            return fail(err, errlen, path, "parameter %u has no name", i);
        if (p->type < MURK_PARAM_FLOAT || p->type > MURK_PARAM_ENUM)
            return fail(err, errlen, path, "parameter '%s' has unknown type %u", p->name, p->type);
        if (p->type == MURK_PARAM_ENUM && (!p->choices || !p->def_str))
            return fail(err, errlen, path, "enum parameter '%s' needs choices and a default", p->name);
        if (!p->doc)
            return fail(err, errlen, path, "parameter '%s' has no doc line", p->name);
        if (strcmp(p->name, "type") == 0)
            return fail(err, errlen, path, "parameter name 'type' is reserved");
        for (uint32_t j = 0; j < i; j++)
            if (strcmp(d->params[j].name, p->name) == 0)
                return fail(err, errlen, path, "parameter '%s' declared twice", p->name);
    }
    return 0;
}

/* Reads the plugin's murk_plugin_abi straight from the file's dynamic symbol table, so that a plugin
 * built for another ABI is refused before any of its code — ELF constructors included, which dlopen()
 * would run — gets a chance to execute. 0 found, 1 not an ELF shared object of this machine's class,
 * 2 no such symbol, -1 unreadable (errno). */
static int elf_read_abi(const char *path, murk_abi *abi)
{
    FILE *f = fopen(path, "rb");
    if (!f)
        return -1;
    unsigned char *buf = NULL;
    size_t n = 0, cap = 0;
    for (;;) {
        if (n == cap) {
            if (cap >= ((size_t)256 << 20)) { /* no plugin is this large */
                free(buf);
                fclose(f);
                return 1;
            }
            cap = cap ? 2 * cap : 65536;
            buf = murk_xrealloc(buf, cap);
        }
        size_t r = fread(buf + n, 1, cap - n, f);
        n += r;
        if (r == 0)
            break;
    }
    fclose(f);
    int rc = 1;
    const ElfW(Ehdr) *eh = (const void *)buf;
    if (n < sizeof *eh || memcmp(eh->e_ident, ELFMAG, SELFMAG) != 0 ||
        eh->e_ident[EI_CLASS] != (sizeof(void *) == 8 ? ELFCLASS64 : ELFCLASS32) || eh->e_shentsize != sizeof(ElfW(Shdr)) ||
        eh->e_shoff > n || (size_t)eh->e_shnum * sizeof(ElfW(Shdr)) > n - eh->e_shoff)
        goto done;
    const ElfW(Shdr) *sh = (const void *)(buf + eh->e_shoff);
    rc = 2;
    for (size_t i = 0; i < eh->e_shnum; i++) {
        if (sh[i].sh_type != SHT_DYNSYM || sh[i].sh_link >= eh->e_shnum || sh[i].sh_entsize != sizeof(ElfW(Sym)))
            continue;
        const ElfW(Shdr) *strs = &sh[sh[i].sh_link];
        if (sh[i].sh_offset > n || sh[i].sh_size > n - sh[i].sh_offset || strs->sh_offset > n ||
            strs->sh_size > n - strs->sh_offset)
            continue;
        const ElfW(Sym) *sym = (const void *)(buf + sh[i].sh_offset);
        const char *names = (const char *)(buf + strs->sh_offset);
        for (size_t k = 0; k < sh[i].sh_size / sizeof *sym; k++) {
            if (sym[k].st_name >= strs->sh_size || sym[k].st_shndx == SHN_UNDEF || sym[k].st_shndx >= eh->e_shnum ||
                strnlen(names + sym[k].st_name, strs->sh_size - sym[k].st_name) == strs->sh_size - sym[k].st_name ||
                strcmp(names + sym[k].st_name, MURK_PLUGIN_ABI_SYMBOL) != 0)
                continue;
            const ElfW(Shdr) *sec = &sh[sym[k].st_shndx];
            if (sym[k].st_size < sizeof *abi || sec->sh_type == SHT_NOBITS || sym[k].st_value < sec->sh_addr)
                goto done;
            size_t off = sec->sh_offset + (size_t)(sym[k].st_value - sec->sh_addr);
            if (off > n || n - off < sizeof *abi)
                goto done;
            memcpy(abi, buf + off, sizeof *abi);
            rc = 0;
            goto done;
        }
    }
done:
    free(buf);
    return rc;
}

/* ---- crash reports ----------------------------------------------------------------------------- *
 * Every plugin file opened is remembered (path and name, copies never freed, so the signal handler
 * can read them at any time). On SIGSEGV, SIGBUS, SIGFPE or SIGILL the handler walks the crashing
 * thread's stack and names the innermost plugin on it — the one whose code was running, or called
 * what crashed — in one line, then dies of the same signal (exit status 128 + signal). */
enum { MAX_REMEMBERED = 256 };
static struct { char *path, *name; } remembered[MAX_REMEMBERED];
static volatile int nremembered;

static void remember(const char *path, const char *name)
{
    if (nremembered < MAX_REMEMBERED) {
        remembered[nremembered].path = murk_strdup(path);
        remembered[nremembered].name = murk_strdup(name);
        nremembered++;
    }
}

static void crash_handler(int sig)
{
    void *frames[64];
    int n = backtrace(frames, 64);
    const char *name = NULL, *path = NULL;
    for (int i = 0; i < n && !name; i++) {
        Dl_info di;
        if (!dladdr(frames[i], &di) || !di.dli_fname)
            continue;
        for (int k = 0; k < nremembered; k++)
            if (strcmp(di.dli_fname, remembered[k].path) == 0) {
                name = remembered[k].name;
                path = remembered[k].path;
                break;
            }
    }
    const char *what = sig == SIGSEGV ? "SIGSEGV" : sig == SIGBUS ? "SIGBUS" : sig == SIGFPE ? "SIGFPE" : "SIGILL";
    char buf[1200];
    int len = name ? snprintf(buf, sizeof buf, "murk: crashed (%s) in plugin '%s' (%s)\n", what, name, path)
                   : snprintf(buf, sizeof buf, "murk: crashed (%s) outside any plugin\n", what);
    if (len > 0 && write(STDERR_FILENO, buf, (size_t)len) < 0)
        len = 0;
    signal(sig, SIG_DFL);
    raise(sig);
}

void murk_crash_handler_install(void)
{
    void *warm[1];
    backtrace(warm, 1); /* loads the unwinder now, not inside the handler */
    static const int sigs[] = {SIGSEGV, SIGBUS, SIGFPE, SIGILL};
    for (size_t i = 0; i < sizeof sigs / sizeof sigs[0]; i++) {
        struct sigaction sa;
        memset(&sa, 0, sizeof sa);
        sa.sa_handler = crash_handler;
        sigemptyset(&sa.sa_mask);
        sa.sa_flags = SA_RESETHAND;
        sigaction(sigs[i], &sa, NULL);
    }
}

int murk_plugin_open(const char *path, int kind, murk_plugin *out, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    murk_abi abicopy;
    switch (elf_read_abi(path, &abicopy)) {
    case -1: return fail(err, errlen, path, "cannot read: %s", strerror(errno));
    case 1: return fail(err, errlen, path, "not an ELF shared object for this machine");
    case 2: return fail(err, errlen, path, "no '%s' symbol: not a murk plugin", MURK_PLUGIN_ABI_SYMBOL);
    default: break;
    }
    if (abicopy.major != MURK_ABI_MAJOR)
        return fail(err, errlen, path,
                    "built for plugin ABI %u.%u, this murk has ABI %d.%d (major versions differ: rebuild the plugin)",
                    abicopy.major, abicopy.minor, MURK_ABI_MAJOR, MURK_ABI_MINOR);
    if (abicopy.minor > MURK_ABI_MINOR)
        return fail(err, errlen, path, "needs plugin ABI %u.%u, this murk has ABI %d.%d (upgrade murk)", abicopy.major,
                    abicopy.minor, MURK_ABI_MAJOR, MURK_ABI_MINOR);
    dlerror();
    void *h = dlopen(path, RTLD_NOW | RTLD_LOCAL);
    if (!h)
        return fail(err, errlen, path, "cannot load: %s", dlerror());
    const murk_abi *abi = dlsym(h, MURK_PLUGIN_ABI_SYMBOL);
    if (!abi || abi->major != abicopy.major || abi->minor != abicopy.minor) {
        dlclose(h);
        return fail(err, errlen, path, "'%s' as loaded differs from the file's symbol table", MURK_PLUGIN_ABI_SYMBOL);
    }
    union {
        void *obj;
        const murk_plugin_desc *(*fn)(void);
    } entry;
    entry.obj = dlsym(h, MURK_PLUGIN_ENTRY_SYMBOL);
    if (!entry.obj) {
        dlclose(h);
        return fail(err, errlen, path, "no '%s' function", MURK_PLUGIN_ENTRY_SYMBOL);
    }
    const murk_plugin_desc *d = entry.fn();
    int rc = 0;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    size_t blen = strlen(base);
    if (blen > 3 && strcmp(base + blen - 3, ".so") == 0)
        blen -= 3;
    if (!d)
        rc = fail(err, errlen, path, "%s() returned no descriptor", MURK_PLUGIN_ENTRY_SYMBOL);
    else if (d->struct_size < MURK_PLUGIN_DESC_SIZE_1_0)
        rc = fail(err, errlen, path, "descriptor struct_size is %u bytes, expected at least %zu for ABI %u.%u",
                  d->struct_size, (size_t)MURK_PLUGIN_DESC_SIZE_1_0, abicopy.major, abicopy.minor);
    else if (d->kind < MURK_KIND_MATERIAL || d->kind > MURK_KIND_PHASE)
        rc = fail(err, errlen, path, "unknown plugin kind %u", d->kind);
    else if (!d->name || strlen(d->name) != blen || strncmp(d->name, base, blen) != 0)
        rc = fail(err, errlen, path, "declares the name '%s' but its file is named '%.*s.so' (names must match)",
                  d->name ? d->name : "(null)", (int)blen, base);
    else if (kind && (int)d->kind != kind)
        rc = fail(err, errlen, path, "'%s' is %s %s plugin, not %s %s", d->name, article((int)d->kind),
                  murk_kind_name((int)d->kind), article(kind), murk_kind_name(kind));
    else if (!d->vtable)
        rc = fail(err, errlen, path, "descriptor has no vtable");
    else if (((const murk_vt_head *)d->vtable)->kind != d->kind)
        rc = fail(err, errlen, path, "declares %s %s plugin but its vtable is marked kind %u (%s): use the "
                  "MURK_<KIND>_PLUGIN macro of that kind's header", article((int)d->kind), murk_kind_name((int)d->kind),
                  ((const murk_vt_head *)d->vtable)->kind, murk_kind_name((int)((const murk_vt_head *)d->vtable)->kind));
    else if (((const murk_vt_head *)d->vtable)->size < vtable_min_size((int)d->kind))
        rc = fail(err, errlen, path, "%s vtable is %u bytes, expected at least %zu", murk_kind_name((int)d->kind),
                  ((const murk_vt_head *)d->vtable)->size, vtable_min_size((int)d->kind));
    else
        rc = check_params(d, path, err, errlen);
    if (rc == 0 && !d->description)
        rc = fail(err, errlen, path, "descriptor has no description");
    if (rc != 0) {
        dlclose(h);
        return -1;
    }
    out->path = murk_strdup(path);
    out->version = MURK_HAS(d->struct_size, murk_plugin_desc, version) ? d->version : NULL;
    remember(path, d->name);
    out->handle = h;
    out->desc = d;
    out->abi = abicopy;
    return 0;
}

static int valid_name(const char *name)
{
    if (!*name || strlen(name) > 64)
        return 0;
    for (const char *c = name; *c; c++)
        if (!((*c >= 'a' && *c <= 'z') || (*c >= 'A' && *c <= 'Z') || (*c >= '0' && *c <= '9') || *c == '_' || *c == '-'))
            return 0;
    return 1;
}

/* A plugin found in search folder `used` hides files of the same name later on the path (a
 * MURK_PLUGIN_PATH entry can replace a built-in): say so once per name, naming both files. */
static void warn_shadowed(const murk_registry *r, size_t used, const char *name, const char *path)
{
    for (size_t j = used + 1; j < r->ndirs; j++) {
        char other[4096];
        snprintf(other, sizeof other, "%s/%s.so", r->dirs[j], name);
        if (access(other, F_OK) == 0) {
            murk_log(MURK_LOG_WARN, "plugin '%s': %s hides %s (it comes first on the plugin search path)", name,
                     path, other);
            return;
        }
    }
}

size_t murk_registry_describe(const murk_registry *r, char *buf, size_t len)
{
    size_t k = 0;
    if (len)
        buf[0] = 0;
    for (size_t i = 0; i < r->nloaded && k < len; i++) {
        const murk_plugin *p = r->loaded[i];
        int n = snprintf(buf + k, len - k, "%s%s=%s (version %s, ABI %u.%u)", i ? "; " : "", p->desc->name, p->path,
                         p->version ? p->version : "none", p->abi.major, p->abi.minor);
        if (n < 0)
            break;
        k += (size_t)n;
    }
    return k;
}

const murk_plugin *murk_registry_load(murk_registry *r, int kind, const char *name, char *err, size_t errlen)
{
    for (size_t i = 0; i < r->nloaded; i++)
        if (strcmp(r->loaded[i]->desc->name, name) == 0) {
            const murk_plugin *p = r->loaded[i];
            if (kind && (int)p->desc->kind != kind) {
                fail(err, errlen, p->path, "'%s' is %s %s plugin, not %s %s", name, article((int)p->desc->kind),
                     murk_kind_name((int)p->desc->kind), article(kind), murk_kind_name(kind));
                return NULL;
            }
            return p;
        }
    if (!valid_name(name)) {
        snprintf(err, errlen, "'%s' is not a plugin name (letters, digits, '_' and '-' only)", name);
        return NULL;
    }
    for (size_t i = 0; i < r->ndirs; i++) {
        size_t n = strlen(r->dirs[i]) + strlen(name) + 8;
        char *path = murk_xmalloc(n);
        snprintf(path, n, "%s/%s.so", r->dirs[i], name);
        if (access(path, F_OK) != 0) {
            free(path);
            continue;
        }
        murk_plugin *p = murk_xmalloc(sizeof *p);
        int rc = murk_plugin_open(path, kind, p, err, errlen);
        free(path);
        if (rc != 0) {
            free(p);
            return NULL;
        }
        r->loaded = murk_xrealloc(r->loaded, (r->nloaded + 1) * sizeof *r->loaded);
        r->loaded[r->nloaded++] = p;
        warn_shadowed(r, i, name, p->path);
        return p;
    }
    /* nothing by that name: suggest the closest plugin file on the path */
    char *cand[256];
    size_t nc = 0;
    for (size_t i = 0; i < r->ndirs; i++) {
        DIR *d = opendir(r->dirs[i]);
        struct dirent *e;
        while (d && (e = readdir(d)) && nc < 256) {
            size_t l = strlen(e->d_name);
            if (l > 3 && strcmp(e->d_name + l - 3, ".so") == 0) {
                cand[nc] = murk_strdup(e->d_name);
                cand[nc++][l - 3] = 0;
            }
        }
        if (d)
            closedir(d);
    }
    const char *sug = murk_did_you_mean(name, (const char *const *)cand, nc);
    int k;
    if (sug)
        k = snprintf(err, errlen, "no %s%splugin '%s' (did you mean '%s'?; searched", kind ? murk_kind_name(kind) : "",
                     kind ? " " : "", name, sug);
    else
        k = snprintf(err, errlen, "no %s%splugin '%s' (searched", kind ? murk_kind_name(kind) : "", kind ? " " : "", name);
    for (size_t i = 0; i < nc; i++)
        free(cand[i]);
    for (size_t i = 0; i < r->ndirs && k > 0 && (size_t)k < errlen; i++)
        k += snprintf(err + k, errlen - (size_t)k, "%s %s", i ? "," : "", r->dirs[i]);
    if (k > 0 && (size_t)k < errlen)
        snprintf(err + k, errlen - (size_t)k, ")");
    return NULL;
}
