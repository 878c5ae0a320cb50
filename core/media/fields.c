/* fields.c — a medium's albedo, emission and temperature fields: reading them from the scene and
 * evaluating them (fields.h). */
#include "media/fields.h"
#include "media/media.h"
#include "util/runtime.h"
#include "util/util.h"
#include "yaml/yread.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static void field3_free(murk_field3 *f)
{
    for (int k = 0; k < 3; k++)
        if (f->ch[k] && (k == 0 || f->ch[k] != f->ch[k - 1]))
            murk_field_free(f->ch[k]);
    memset(f, 0, sizeof *f);
}

static murk_rgb field3_eval(const murk_field3 *f, murk_vec3 p)
{
    if (!f->ch[0])
        return f->c;
    float r = murk_field_eval(f->ch[0], p);
    if (f->ch[1] == f->ch[0])
        return murk_rgb1(r);
    return murk_rgb3(r, murk_field_eval(f->ch[1], p), murk_field_eval(f->ch[2], p));
}

/* A grid field's first voxel above hi, reported at node n (albedo above 1). Voxels are counted in the grid's
 * box: a .vol's own voxel indices; for a sparse grid (.vdb, .nvdb) the box starts one voxel below its active
 * voxels' index box (density.h), so that is said. */
static int check_max(const murk_field3 *f, const murk_ynode *n, const char *what, double hi, char *err, size_t errlen)
{
    for (int k = 0; k < 3; k++) {
        if (!f->ch[k] || !(murk_field_max(f->ch[k]) > hi))
            continue;
        int res[3];
        murk_field_grid(f->ch[k], res, NULL);
        long x = 0, y = 0, z = 0;
        float v = murk_field_max(f->ch[k]);
        for (z = 0; z < res[2]; z++)
            for (y = 0; y < res[1]; y++)
                for (x = 0; x < res[0]; x++)
                    if ((v = murk_field_voxel(f->ch[k], (int)x, (int)y, (int)z)) > hi)
                        goto found;
    found:;
        murk_field_info fi;
        murk_field_describe(f->ch[k], &fi);
        return murk_yerr(err, errlen, n, "%s: value %g at voxel (%ld, %ld, %ld)%s%s is above %g", what, (double)v,
                         x, y, z, fi.sparse || fi.held_dense ? " of the grid's box" : "",
                         f->ch[1] != f->ch[0] ? (k == 0 ? " (red)" : k == 1 ? " (green)" : " (blue)") : "", hi);
    }
    return 0;
}

/* An RGB field: a constant ([r, g, b], a number, { constant: ... }) with values in [0, hi], or a grid or
 * procedural field (murk_media_scalar_field, or a 3-channel .vol). *constant says which. */
static int load_field3(const murk_scene *s, const murk_ynode *n, const char *what, double hi, murk_field3 *out,
                       int *constant, char *err, size_t errlen)
{
    memset(out, 0, sizeof *out);
    const murk_ynode *c = n->kind == MURK_Y_MAP && n->n == 1 ? murk_ymap_get(n, "constant") : NULL;
    char label[96];
    snprintf(label, sizeof label, "%s%s", what, c ? ".constant" : "");
    if (n->kind != MURK_Y_MAP || c) {
        double v[3];
        if (murk_yread_rgb(c ? c : n, label, 0.0, hi, v, err, errlen))
            return -1;
        out->c = murk_rgb3((float)v[0], (float)v[1], (float)v[2]);
        *constant = 1;
        return 0;
    }
    *constant = 0;
    const murk_ynode *g = murk_ymap_get(n, "grid");
    size_t len = g && g->kind == MURK_Y_SCALAR ? strlen(g->str) : 0;
    if (n->n == 1 && len > 4 && !strcmp(g->str + len - 4, ".vol")) {
        char *path = murk_path_relative_to(s->doc.file, g->str), ferr[768];
        int rc = murk_field_vol_load3(path, out->ch, ferr, sizeof ferr);
        free(path);
        if (rc < 0)
            return murk_yerr(err, errlen, g, "%s grid: %s", what, ferr);
    } else {
        out->ch[0] = out->ch[1] = out->ch[2] = murk_media_scalar_field(s, n, what, err, errlen);
        if (!out->ch[0])
            return -1;
    }
    if (check_max(out, g ? g : n, what, hi, err, errlen)) {
        field3_free(out);
        return -1;
    }
    return 0;
}

/* temperature: the field and its blackbody table over the temperatures it reaches. */
static int load_temperature(const murk_scene *s, const murk_ynode *tn, murk_medium_fields *f, char *err, size_t errlen)
{
    f->temperature = murk_media_scalar_field(s, tn, "temperature", err, errlen);
    if (!f->temperature)
        return -1;
    double a = ((double)murk_field_min(f->temperature) - f->t_offset) * f->t_scale;
    double b = ((double)murk_field_max(f->temperature) - f->t_offset) * f->t_scale;
    if (murk_blackbody_table_build(&f->bb, fmax(fmax(a, b), 1.0)) != 0)
        return murk_yerr(err, errlen, tn, "temperature: out of memory");
    return 0;
}

int murk_fields_load(const murk_scene *s, const murk_ynode *m, const char *who, double t_scale, double t_offset,
                     int t_set, murk_medium_fields *f, murk_medium_data *md, char *err, size_t errlen)
{
    memset(f, 0, sizeof *f);
    const murk_ynode *an = murk_ymap_get(m, "albedo"), *en = murk_ymap_get(m, "emission");
    const murk_ynode *tn = murk_ymap_get(m, "temperature");
    f->t_scale = (float)t_scale;
    f->t_offset = (float)t_offset;
    if (t_set && !tn)
        return murk_yerr(err, errlen, murk_ymap_get(m, "temperature_scale") ? murk_ymap_get(m, "temperature_scale")
                                                                             : murk_ymap_get(m, "temperature_offset"),
                         "%s: temperature_scale and temperature_offset need a temperature field", who);
    int constant = 1;
    if (an && load_field3(s, an, "albedo", 1.0, &f->albedo, &constant, err, errlen))
        goto fail;
    if (an && constant) { /* a constant albedo is the sigmas' own split: sigma_s = a sigma_t, no field */
        for (int k = 0; k < 3; k++) {
            float st = md->sigma_a.c[k] + md->sigma_s.c[k];
            md->sigma_s.c[k] = f->albedo.c.c[k] * st;
            md->sigma_a.c[k] = (1.0f - f->albedo.c.c[k]) * st;
        }
    } else if (an) {
        f->flags |= MURK_FIELD_ALBEDO;
    }
    f->emission.c = murk_rgb1(1.0f);
    constant = 1;
    if (en && load_field3(s, en, "emission", 1e30, &f->emission, &constant, err, errlen))
        goto fail;
    if (tn && load_temperature(s, tn, f, err, errlen))
        goto fail;
    if (tn || (en && !(constant && murk_rgb_is_black(f->emission.c))))
        f->flags |= MURK_FIELD_EMISSION;
    if ((f->flags & MURK_FIELD_EMISSION) && !(f->flags & MURK_FIELD_ALBEDO) && murk_rgb_is_black(md->sigma_a))
        murk_log(MURK_LOG_WARN, "%s: emission is radiance per unit absorption, and sigma_a is 0: the medium emits "
                 "nothing", who);
    md->fields = f->flags;
    return 0;
fail:
    murk_fields_free(f);
    return -1;
}

murk_rgb murk_fields_albedo(const murk_medium_fields *f, murk_vec3 p) { return field3_eval(&f->albedo, p); }

murk_rgb murk_fields_emission(const murk_medium_fields *f, murk_vec3 p)
{
    murk_rgb e = field3_eval(&f->emission, p);
    if (!f->temperature)
        return e;
    float T = (murk_field_eval(f->temperature, p) - f->t_offset) * f->t_scale;
    return murk_rgb_mul(e, murk_blackbody_lookup(&f->bb, T));
}

void murk_fields_free(murk_medium_fields *f)
{
    field3_free(&f->albedo);
    field3_free(&f->emission);
    murk_field_free(f->temperature);
    murk_blackbody_table_free(&f->bb);
    memset(f, 0, sizeof *f);
}
