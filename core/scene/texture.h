/* texture.h — textures for colour and float material parameters. Internal to libmurk.
 *
 * In a scene, a texturable parameter takes a number / [r,g,b] (constant) or a map:
 *   { texture: checker, even: [r,g,b], odd: [r,g,b], scale: 8 }     squares of size 1/scale in (u,v)
 *   { texture: image, file: img.png, srgb: true, scale: [su, sv] }   PNG, bilinear, wrapping in u and v
 * (u,v): quads span [0,1]^2 from center-u-v; spheres use (phi/2pi, theta/pi) with theta from +y;
 * meshes use the OBJ's vt (0 without); each box face is a quad. Image row 0 is v = 1 (top). */
#ifndef MURK_TEXTURE_H
#define MURK_TEXTURE_H

#include <stddef.h>
#include "murk/plugin.h"
#include "yaml/yamldoc.h"

/* Parses a texture map node; values must lie in [lo, hi] (the parameter's range; PNG texels are in
 * [0,1] and must fit it too). scene_path resolves relative file names. NULL with a located error. */
murk_texture *murk_texture_parse(const murk_ynode *n, const char *scene_path, double lo, double hi, char *err,
                                 size_t errlen);
void murk_texture_eval(const murk_texture *t, const murk_hit *hit, float out[3]);
void murk_texture_average(const murk_texture *t, double out[3]);
void murk_texture_free(murk_texture *t);
/* Bytes the texture holds (its texels as floats, and itself); *name (if name) its file as the scene names it,
 * or "checker". */
size_t murk_texture_bytes(const murk_texture *t, const char **name);

#endif
