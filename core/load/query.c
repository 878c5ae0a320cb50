/* query.c — what a loaded scene is, for a program that embeds libmurk (murk/murk.h): its render settings,
 * integrator, media and plugins, as the murk command records them in the EXR's murk:* attributes. */
#include "plugin/plugin_loader.h"
#include "scene/scene.h"
#include "util/util.h"

MURK_API void murk_scene_get_info(const murk_scene *s, murk_scene_info *info)
{
    *info = (murk_scene_info){.width = s->width, .height = s->height, .spp = s->spp, .seed = s->seed,
                              .exposure = s->exposure, .integrator = s->integrator_plugin->desc->name,
                              .nmedia = (int)s->nmedia};
}

MURK_API const char *murk_scene_medium_name(const murk_scene *s, int i)
{
    return i >= 0 && (size_t)i < s->nmedia ? s->media[i].name : NULL;
}

MURK_API size_t murk_scene_plugins(const murk_scene *s, char *buf, size_t n)
{
    return murk_registry_describe(&s->reg, buf, n);
}
