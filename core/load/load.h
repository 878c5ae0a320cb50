/* load.h — the scene loader's functions beyond the public murk_scene_load / murk_scene_free (murk.h):
 * the command's rules and the content hash (load.c), a shape's release (free.c). Internal to libmurk. */
#ifndef MURK_LOAD_H
#define MURK_LOAD_H

#include <stddef.h>
#include <stdint.h>

#include "scene/scene.h"

/* murk_scene_check_unused (murk/murk.h): murk_scene_load itself refuses only the unused media and
 * materials a --set made (a misspelt name); embedders may load media and materials to call them directly. */

/* The content hash a checkpoint carries: the scene file and every file it loads (meshes, density
 * grids, image textures, as named after the --set overrides), each with its path; so a resume after
 * any of them changed is refused. 0 with err if one cannot be read. */
uint64_t murk_scene_hash(const murk_scene *s, char *err, size_t errlen);

/* The `lights:` list (light_block.c): each light checked and added (render/lights.h). 0, or -1 with a
 * located err. */
int murk_load_lights(murk_scene *s, const murk_ynode *n, char *err, size_t errlen);

/* Releases what a shape owns (its triangle arrays). */
void murk_shape_free(murk_shape *sh);

#endif
