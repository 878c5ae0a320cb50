/* schema.c — plugins' parameter schemas as data (murk/lab.h), for a program that describes plugins as
 * `murk plugins NAME` prints them: a plugin found on the search path and opened as a scene would open
 * it (murk_registry_load: ABI and descriptor checked, no plugin code run but its entry function), and
 * the keys every medium takes besides its tracker's own. Part of libmurklab. */
#include "media/media.h"
#include "plugin/plugin_loader.h"
#include "util/util.h"
#include "murk/lab.h"

#include <stdio.h>
#include <stdlib.h>

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
