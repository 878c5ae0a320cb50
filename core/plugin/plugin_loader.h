/* plugin_loader.h — finding, opening and validating plugin shared objects. Internal to libmurk. */
#ifndef MURK_PLUGIN_LOADER_H
#define MURK_PLUGIN_LOADER_H

#include <stddef.h>
#include "murk/plugin.h"

typedef struct murk_plugin {
    char *path;
    void *handle;
    const murk_plugin_desc *desc;
    murk_abi abi;
    const char *version; /* desc->version if the plugin's ABI has it (1.1), else NULL */
} murk_plugin;

typedef struct murk_registry {
    char **dirs;
    size_t ndirs;
    murk_plugin **loaded;
    size_t nloaded;
} murk_registry;

/* Search path: $MURK_PLUGIN_PATH (':'-separated, empty entries ignored), then the build's plugin folder
 * when this murk runs from its build tree, else the murk/plugins folder beside the libmurk.so in use
 * (a moved or DESTDIR-staged install finds its own), then the configured one. Never the current folder
 * unless a MURK_PLUGIN_PATH entry names it. */
void murk_registry_init(murk_registry *r);
/* 1 if the running program is in murk's build tree (then built-in plugins are build/plugins, and the
 * docs, examples and scenes are the sources'), 0 if it is installed. */
int murk_running_uninstalled(void);
void murk_registry_free(murk_registry *r); /* dlcloses everything it opened */
/* Finds NAME.so on the search path, opens and validates it (cached: a name is loaded once).
 * kind 0 accepts any kind. Returns NULL with err = one line naming the file and the cause. */
const murk_plugin *murk_registry_load(murk_registry *r, int kind, const char *name, char *err, size_t errlen);
/* Writes "name=path (version V, ABI M.m); ..." for every plugin loaded so far (for the EXR metadata); returns the
 * length it needed (output truncated to len - 1 characters). */
size_t murk_registry_describe(const murk_registry *r, char *buf, size_t len);
/* Opens and validates one file. Returns 0, or -1 with err. */
int murk_plugin_open(const char *path, int kind, murk_plugin *out, char *err, size_t errlen);
void murk_plugin_close(murk_plugin *p);
const char *murk_kind_name(int kind);
/* Installs handlers for SIGSEGV, SIGBUS, SIGFPE and SIGILL that print one line naming the plugin on
 * the crashing thread's stack ("murk: crashed (SIGSEGV) in plugin 'x' (path)") and then die of the
 * signal. The murk command installs them first thing. */
void murk_crash_handler_install(void);

#endif
