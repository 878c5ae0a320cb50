/* fields.h — a medium's fields beside its density: the single-scattering albedo, emission and temperature
 * (the scene's `albedo`, `emission`, `temperature`, `temperature_scale`, `temperature_offset` keys; murk/medium.h
 * has what they mean to trackers). Internal to core/media (fields.c; media.c holds one per medium).
 *
 *   albedo: [r, g, b] | V | { constant: V|[r,g,b] }   folded into sigma_s and sigma_a at load (no field)
 *   albedo: { grid: F.vol } | { grid: F.nvdb } | { vdb: F.vdb, grid: NAME } | { cloud: {...} }   a field: a(p)
 *   emission: [r, g, b] | V | { constant: ... } | { grid: ... } | { vdb: ... } | { cloud: ... }   Le(p), per unit
 *             absorption
 *   temperature: { grid: ... } | { vdb: ... } | { constant: V } | { cloud: {...} }   T(p) = (value - offset) x
 *             scale kelvin
 *
 * Le(p) = emission(p) x blackbody(T(p)) per channel, where a missing `emission` is 1 when the medium has a
 * temperature and a missing temperature leaves emission(p) alone. Grids: .vol of 1 channel (grey) or 3
 * (RGB), NanoVDB's first float grid (grey), an OpenVDB file's named float, half or double grid (grey: murk
 * reads scalar grids only, so a vec3s grid is refused and an RGB albedo comes from a 3-channel .vol). All
 * go through source.c, so every field's values are finite and >= 0 (a located error otherwise). Each field
 * has its own box (values 0 outside it), whatever the density's: boxes and resolutions may differ. */
#ifndef MURK_FIELDS_H
#define MURK_FIELDS_H

#include "media/density.h"
#include "murk/medium.h"
#include "scene/scene.h"

/* An RGB field: a constant or three scalar fields (one, shared, for a grey grid). */
typedef struct murk_field3 {
    murk_field *ch[3]; /* NULL: the constant c */
    murk_rgb c;
} murk_field3;

typedef struct murk_medium_fields {
    uint32_t flags;                 /* MURK_FIELD_* */
    murk_field3 albedo, emission;   /* albedo: with MURK_FIELD_ALBEDO; emission: 1 when only a temperature */
    murk_field *temperature;        /* NULL: none */
    float t_scale, t_offset;
    murk_blackbody_table bb;
} murk_medium_fields;

/* Reads the medium map m's field keys (who names the medium in messages): fills f, folds a constant
 * albedo into md->sigma_a / sigma_s (their sum kept) and sets md->fields. t_scale and t_offset are the
 * values of the temperature_scale / temperature_offset keys, t_set whether either was given. Returns 0,
 * or -1 with a located error (f freed). */
int murk_fields_load(const murk_scene *s, const murk_ynode *m, const char *who, double t_scale, double t_offset,
                     int t_set, murk_medium_fields *f, murk_medium_data *md, char *err, size_t errlen);
murk_rgb murk_fields_albedo(const murk_medium_fields *f, murk_vec3 p);
murk_rgb murk_fields_emission(const murk_medium_fields *f, murk_vec3 p);
void murk_fields_free(murk_medium_fields *f);

#endif
