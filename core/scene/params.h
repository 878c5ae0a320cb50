/* params.h — plugin parameter blocks of a scene, shared by the blocks that instantiate plugins (the
 * scene loader, load.c, and the media loader, media.c). Internal to libmurk. */
#ifndef MURK_PARAMS_H
#define MURK_PARAMS_H

#include <stddef.h>

#include "murk/murk.h"
#include "murk/medium.h"
#include "murk/plugin.h"
#include "plugin/plugin_loader.h"
#include "yaml/yamldoc.h"

/* A parameter array of n values kept for the scene's lifetime (freed with the scene). */
murk_value *murk_scene_keep_params(murk_scene *s, size_t n);
/* Fills values[] in schema order from the map's keys (all keys but those in skip[]); `who` names the
 * block in messages, e.g. "material 'metal' (ggx)". A key that a --set of the block's type dropped is
 * noted (an info line) if note_drops; 0 for a read that another read of the same block follows (the
 * media's core keys, before the tracker's), so that the note comes once. Returns 0, or -1 with a
 * located error. */
int murk_scene_read_plugin_params(murk_scene *s, const murk_plugin_desc *d, const murk_ynode *map, const char *who,
                                  const char *const *skip, size_t nskip, int note_drops, murk_value *values,
                                  char *err, size_t errlen);

/* One plugin instance from a scene block — the only path by which the core instantiates plugins of
 * any kind: finds the plugin `type` of `kind` on the search path (a refusal is reported at type_node),
 * reads its parameters from `map` (keys in skip[] belong to the caller; map may be a scalar, which
 * has none), and calls its create() with the services table `host` (for media and transmittance
 * estimators with `data`). `block`
 * prefixes a refusal of the plugin ("material 'metal'"), `who` parameter and create() errors
 * ("material 'metal' (ggx)"). On success *plugin and *self are set (the parameters are kept with the
 * scene, as create()'s contract promises). */
int murk_scene_instantiate(murk_scene *s, const murk_host *host, int kind, const murk_ynode *type_node,
                           const char *type, const murk_ynode *map, const char *block, const char *who,
                           const char *const *skip, size_t nskip, const murk_medium_data *data,
                           const murk_plugin **plugin, void **self, char *err, size_t errlen);

/* A parameter given a texture made in C (load/asset.c: the textures of a file's material) instead of
 * what the map says. */
typedef struct murk_param_texture { const char *name; const murk_texture *tex; } murk_param_texture;
/* murk_scene_instantiate, with the parameters named in tex[] (texturable ones) taking those textures,
 * their averages as plain values, before create(). */
int murk_scene_instantiate_textured(murk_scene *s, const murk_host *host, int kind, const murk_ynode *type_node,
                                    const char *type, const murk_ynode *map, const char *who,
                                    const murk_param_texture *tex, size_t ntex, const murk_plugin **plugin, void **self,
                                    char *err, size_t errlen);
/* Hands t to the scene, which frees it with itself; returns t. */
murk_texture *murk_scene_keep_texture(murk_scene *s, murk_texture *t);

#endif
