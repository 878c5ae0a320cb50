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
#include "image/image.h"
#include "yaml/yamldoc.h"

/* Parses a texture map node; values must lie in [lo, hi] (the parameter's range; PNG texels are in
 * [0,1] and must fit it too). scene_path resolves relative file names. NULL with a located error. */
murk_texture *murk_texture_parse(const murk_ynode *n, const char *scene_path, double lo, double hi, char *err,
                                 size_t errlen);
void murk_texture_eval(const murk_texture *t, const murk_hit *hit, float out[3]);

/* An image texture of img's texels (taken: img is cleared), wrapping, scale 1, named name (load/asset.c's
 * textures of a file's materials, external or embedded). Texels must be in [0, 1]. */
murk_texture *murk_texture_from_image(murk_image *img, const char *name);

/* What a glTF metallic-roughness material gives one ggx parameter, evaluated per hit from its textures
 * (load/asset.c; the glTF 2.0 specification, Appendix B, "fresnel_mix"):
 *   base = baseColorTexture.rgb x baseColorFactor,  metallic = metallicRoughnessTexture.b x metallicFactor,
 *   roughness = metallicRoughnessTexture.g x roughnessFactor   (each clamped to [0, 1]; no texture: 1)
 *   ALBEDO    base (1 - metallic)
 *   SPECULAR  0.04 (1 - metallic) + base metallic
 *   ROUGHNESS roughness
 * base and mr are image textures the scene keeps (either may be NULL); the result refers to them. */
typedef enum { MURK_GLTF_ALBEDO, MURK_GLTF_SPECULAR, MURK_GLTF_ROUGHNESS } murk_gltf_param;
murk_texture *murk_texture_gltf(murk_gltf_param which, const murk_texture *base, const float base_factor[3],
                                const murk_texture *mr, float metallic, float roughness);
void murk_texture_average(const murk_texture *t, double out[3]);
void murk_texture_free(murk_texture *t);
/* Bytes the texture holds (its texels as floats, and itself); *name (if name) its file as the scene names it,
 * or "checker". */
size_t murk_texture_bytes(const murk_texture *t, const char **name);

#endif
