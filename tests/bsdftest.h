/* bsdftest.h — helpers shared by the material (BSDF) test programs: load a material plugin with a fake
 * host, build its parameter array from the schema, and check sample() against pdf() statistically.
 * Link with bsdftest.c, testutil.c, -lcmocka -ldl -lm. */
#ifndef MURK_BSDFTEST_H
#define MURK_BSDFTEST_H

#include <stdint.h>

#include "murk/material.h"
#include "lab/check/sphere.h"
#include "testutil.h"

/* ---- Instances ------------------------------------------------------------------------------- */
/* One parameter override: RGB parameters take v[0..2], numbers v[0]. */
typedef struct bt_set {
    const char *name;
    double v[3];
} bt_set;
#define BT_F(name, x) ((bt_set){(name), {(x), (x), (x)}})
#define BT_RGB(name, r, g, b) ((bt_set){(name), {(r), (g), (b)}})

typedef struct bt_mat {
    void *dl;
    const murk_plugin_desc *desc;
    const murk_material_vt *vt;
    void *self;
    murk_value *vals; /* in schema order, as create() received them */
} bt_mat;

/* The fake host: calloc-backed zeroing alloc, free, log to stderr; tex_eval aborts (no textures). */
const murk_host *bt_host(void);
/* Number of MURK_LOG_WARN messages plugins have logged through the fake host so far. */
long bt_warnings(void);
/* A hit record to pass to eval/pdf/sample (no textures are used, so its content is irrelevant). */
const murk_hit *bt_hit(void);

/* Loads build_path(rel) (e.g. "plugins/ggx.so"), checks murk_plugin_abi and the descriptor (material
 * kind, name == file basename, struct sizes, defaults inside their ranges), builds the parameter array
 * from the schema defaults plus the overrides (which get set = 1) and creates an instance. Any failure
 * fails the current cmocka test. */
bt_mat *bt_create(const char *rel, const bt_set *sets, int nsets);
void bt_destroy(bt_mat *m);

static inline murk_rgb bt_eval(const bt_mat *m, murk_vec3 wo, murk_vec3 wi)
{
    return m->vt->eval(m->self, bt_hit(), wo, wi);
}
static inline float bt_pdf(const bt_mat *m, murk_vec3 wo, murk_vec3 wi)
{
    return m->vt->pdf(m->self, bt_hit(), wo, wi);
}
static inline int bt_sample(const bt_mat *m, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
    return m->vt->sample(m->self, bt_hit(), wo, u, s);
}

/* Unit direction with polar angle theta (radians, from +z) and azimuth phi. */
murk_vec3 bt_dir(double theta, double phi);

/* ---- Numerical integration over the sphere --------------------------------------------------- *
 * The sphere is cut into ntheta x nphi cells in a frame whose +z axis is `pole`: x in [0, 1] uniform
 * with cos(theta') = 1 - 2 x^warp, phi' in [0, 2 pi) uniform. warp 1 gives cells uniform in cos theta
 * (equal solid angle); warp > 1 refines around the pole, which the tests put on the specular peak.
 * Each cell is integrated by nested, globally adaptive Gauss-Kronrod (7/15) quadrature to the
 * tolerance max(tol, 1e-6 |integral|) (tol in units of the integrand times steradians), within a fixed
 * budget of subintervals; the error estimates (|K15 - G7| summed, inner errors propagated) are
 * reported, also where the budget stopped the refinement. */
typedef murk_sph_grid bt_grid; /* ntheta, nphi, pole, warp: see core/lab/check/sphere.h */

typedef murk_sph_fn bt_fn;

/* Integral of fn over one cell (it, ip); *err receives the summed error estimate. */
double bt_integrate_cell(bt_fn fn, void *ctx, const bt_grid *g, int it, int ip, double tol, double *err);
/* Integral of fn over the whole sphere (sum over cells, each with tolerance tol). */
double bt_integrate_sphere(bt_fn fn, void *ctx, const bt_grid *g, double tol, double *err);
/* The cell that contains direction w (unit), as it * nphi + ip. */
int bt_cell_of(const bt_grid *g, murk_vec3 w);

/* ---- Chi-square test of sample() against a pdf ----------------------------------------------- */
typedef struct bt_chi2_result {
    double p;            /* p-value */
    int dof;
    long n, valid;       /* samples drawn, samples sample() returned 1 for */
    double pdf_integral; /* integral of the reference pdf over the sphere */
    double pdf_err;      /* its quadrature error estimate */
    long mismatch;       /* valid samples whose s.pdf / s.f disagree with the sampler's own pdf()/eval()
                          * (relative 1e-3) or which are not finite / not unit */
    double max_rel_mismatch;
} bt_chi2_result;

/* Draws n samples from `sampler` at wo (murk_rng seeded with seed), bins the valid ones on grid g,
 * integrates pdf_fn (a reference solid-angle pdf; NULL = sampler's own pdf()) over every cell for the
 * expected counts, adds one cell for "no sample" (expected n (1 - integral of the pdf)) and runs
 * chi2_test with minimum expectation 5. Prints one summary line to stderr (tagged with `label`). */
typedef double (*bt_pdf_fn)(void *ctx, murk_vec3 wo, murk_vec3 wi);
double bt_chi2(const char *label, const bt_mat *sampler, bt_pdf_fn pdf_fn, void *pdf_ctx, murk_vec3 wo, long n,
               uint64_t seed, const bt_grid *g, bt_chi2_result *res);
/* A bt_pdf_fn that calls a material's pdf(): pass the bt_mat as ctx. */
double bt_mat_pdf(void *mat, murk_vec3 wo, murk_vec3 wi);

/* ---- Directional albedo ------------------------------------------------------------------------ */
/* Importance-sampled E(wo) = mean of f cos / pdf per channel (0 for "no sample"), with the standard
 * error of the mean in sigma[]. */
void bt_albedo_is(const bt_mat *m, murk_vec3 wo, long n, uint64_t seed, double mean[3], double sigma[3]);
/* Deterministic E(wo) = integral of eval(wo, wi)[channel] * max(0, wi.z) over the sphere. */
double bt_albedo_quad(const bt_mat *m, murk_vec3 wo, int channel, const bt_grid *g, double tol, double *err);

#endif
