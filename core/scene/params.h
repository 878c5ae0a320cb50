/* params.h — plugin parameter blocks of a scene, shared by the blocks that instantiate plugins (the
 * scene loader, load.c, and the media loader, media.c). Internal to libmurk. */
#ifndef MURK_PARAMS_H
#define MURK_PARAMS_H

#include <stddef.h>

#include "murk/murk.h"
#include "murk/plugin.h"
#include "yamldoc.h"

/* A parameter array of n values kept for the scene's lifetime (freed with the scene). */
murk_value *murk_scene_keep_params(murk_scene *s, size_t n);
/* Fills values[] in schema order from the map's keys (all keys but those in skip[]); `who` names the
 * block in messages, e.g. "material 'metal' (ggx)". Returns 0, or -1 with a located error. */
int murk_scene_read_plugin_params(murk_scene *s, const murk_plugin_desc *d, const murk_ynode *map, const char *who,
                                  const char *const *skip, size_t nskip, murk_value *values, char *err,
                                  size_t errlen);

#endif
