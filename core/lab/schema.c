/* schema.c — plugins' parameter schemas as data (murk/lab.h), for a program that describes plugins as
 * `murk plugins NAME` prints them: a plugin found on the search path and opened as a scene would open
 * it (murk_registry_load: ABI and descriptor checked, no plugin code run but its entry function), and
 * the keys every medium takes besides its tracker's own, and the names of the plugins found. Part of libmurklab. */
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "util/util.h"
#include "murk/lab.h"

#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

struct murk_lab_plugin {
    murk_registry reg; /* its own search path and handle: closing it dlcloses the plugin */
};

MURK_API murk_lab_plugin *murk_lab_plugin_open(const char *name, murk_lab_plugin_info *info, char *err,
                                               size_t errlen)
{
    murk_lab_plugin *lp = calloc(1, sizeof *lp);
    if (!lp) {
        snprintf(err, errlen, "out of memory");
        return NULL;
    }
    murk_registry_init(&lp->reg);
    const murk_plugin *p = murk_registry_load(&lp->reg, 0, name, err, errlen);
    if (!p) {
        murk_lab_plugin_close(lp);
        return NULL;
    }
    const murk_plugin_desc *d = p->desc;
    *info = (murk_lab_plugin_info){.name = d->name, .description = d->description, .version = p->version,
                                   .path = p->path, .kind = (int)d->kind, .abi = p->abi, .params = d->params,
                                   .nparams = d->nparams};
    return lp;
}

MURK_API void murk_lab_plugin_close(murk_lab_plugin *lp)
{
    if (!lp)
        return;
    murk_registry_free(&lp->reg);
    free(lp);
}

MURK_API const murk_param *murk_lab_medium_params(uint32_t *n)
{
    *n = MURK_MEDIUM_NCORE;
    return murk_medium_core_params;
}

static int by_name(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

MURK_API char *murk_lab_plugin_names(void)
{
    murk_registry reg;
    murk_registry_init(&reg);
    char **names = NULL;
    size_t n = 0, len = 1;
    for (size_t i = 0; i < reg.ndirs; i++) {
        DIR *d = opendir(reg.dirs[i]);
        for (struct dirent *e; d && (e = readdir(d));) {
            size_t l = strlen(e->d_name), k = 0;
            if (l <= 3 || strcmp(e->d_name + l - 3, ".so") != 0)
                continue;
            while (k < n && (strlen(names[k]) != l - 3 || strncmp(names[k], e->d_name, l - 3) != 0))
                k++;
            if (k < n) /* found twice: a scene loads the first */
                continue;
            names = murk_xrealloc(names, (n + 1) * sizeof *names);
            names[n] = murk_strdup(e->d_name);
            names[n++][l - 3] = 0;
            len += l - 2;
        }
        if (d)
            closedir(d);
    }
    murk_registry_free(&reg);
    if (n)
        qsort(names, n, sizeof *names, by_name);
    char *out = malloc(len), *p = out;
    for (size_t k = 0; k < n; k++) {
        if (out)
            p += sprintf(p, "%s\n", names[k]);
        free(names[k]);
    }
    free(names);
    if (out)
        *p = 0;
    return out;
}
