/* mediatest.h — the kit test_media.c and test_transmittance.c share: scenes of several media with
 * common keys, the density grids and rays with closed-form optical depths (ramp, checker) or a
 * quadrature reference (sinusoid), per-channel statistics over N estimates, and the z-check (stat.h)
 * with its printed line. */
#ifndef MURK_MEDIATEST_H
#define MURK_MEDIATEST_H

#include "testutil.h"
#include "stat.h"

#include "media/density.h"
#include "render/host.h"
#include "media/media.h"
#include "util/runtime.h"
#include "scene/scene.h"

/* ---- scenes ----------------------------------------------------------------------------------- */

typedef struct mt_spec {
    const char *label; /* the medium's name in the scene */
    const char *keys;  /* its own keys, e.g. "type: decomposition, control: 0.5" */
    double wmax;       /* > 0: a bound fails on purpose (weighted, heavy-tailed): the weights' stated maximum,
                        * for mt_check_bounded; 0: the z-test */
} mt_spec;

/* Writes tmp_dir()/file, a scene with one medium per spec, `LABEL: { PREFIX KEYS, COMMON }` (prefix
 * e.g. "type: delta, " or ""), and loads it; asserts that it holds n media. */
murk_scene *mt_load_media(const char *file, const char *common, const char *prefix, const mt_spec *ms, int n);

/* The two sigma sets (index: chroma 0 grey, 1 chromatic) as scene keys and as numbers per channel. */
#define MT_GREY_KEYS "sigma_a: 0.3, sigma_s: 0.9"
#define MT_CHROMA_KEYS "sigma_a: [0.2, 1, 3], sigma_s: [1, 0.5, 0.1]"
extern const double mt_sigma_a[2][3], mt_sigma_s[2][3], mt_sigma_t[2][3];
const char *mt_sigma_keys(int chroma);

/* ---- densities, grids and rays ---------------------------------------------------------------- */

/* Voxels at the centres of a res grid over [lo, hi], f(x, y, z, centre) at each; saved as
 * tmp_dir()/name (.vol). The returned path is a static buffer rotated 4 ways. */
const char *mt_save_grid(const char *name, const int res[3], murk_vec3 lo, murk_vec3 hi,
                         float (*f)(int, int, int, float, float, float));

/* 0.2 / 1.4 alternating per voxel. */
float mt_checker_f(int x, int y, int z, float cx, float cy, float cz);
/* Linear ramp along z: 0.2 + 1.1 z on [0,1]^3. Trilinear interpolation reproduces it exactly between
 * the first and last centres; in the two clamped half-cells the integral gains and loses b h^2 / 2
 * (h = half a cell), which cancel: int_0^1 density dz = 0.2 + 1.1 / 2 = 0.75 exactly. */
float mt_ramp_f(int x, int y, int z, float cx, float cy, float cz);
/* A smooth 3-D pattern in [0.05, 0.31] on [-1,1]^3 (minimum > 0, so decomposition's minorant grid is
 * non-trivial). */
float mt_sinus_f(int x, int y, int z, float cx, float cy, float cz);

/* A grid saved to tmp_dir(), a ray segment through it and its optical depth (< 0: no closed form). */
typedef struct mt_case {
    const char *grid;
    murk_ray ray;
    double D;
} mt_case;
/* checker.vol, 8^3 on [0,1]^3; a ray along x through a row of voxel centres: D = the row's mean. */
mt_case mt_checker_case(void);
/* ramp.vol, 4x4x16 on [0,1]^3; a slanted ray entering through z = 0 and leaving through z = 1, the
 * segment from outside the box to past it: D = 0.75 / d.z. */
mt_case mt_ramp_case(void);
/* sinus.vol, 16^3 on [-1,1]^3; a diagonal ray whose segment starts inside the box and ends outside
 * it: no closed form (D = -1). */
mt_case mt_sinus_case(void);

/* Optical depth at the nbins + 1 bin edges of [tmin, tmax] (midpoint rule, sub steps per bin) of the
 * field as the core interpolates it: for a grid (non-NULL), the .vol file loaded again and evaluated
 * with murk_field_eval (independent of the media plumbing); else the medium's density. */
void mt_depths(const murk_medium *m, const char *grid, const murk_ray *ray, int nbins, int sub, double *D);
/* The medium's optical depth over the segment (midpoint rule, 200000 steps). */
double mt_quadrature(const murk_medium *m, const murk_ray *ray);

/* ---- estimation ------------------------------------------------------------------------------- */

/* Per-channel sums of x - k over n samples, k the first sample (no cancellation when all are equal). */
typedef struct mt_acc {
    long n;
    double k[3], s[3], s2[3], s3[3], s4[3]; /* sums of powers of x - k */
    double amax[3];                         /* the largest |x| */
} mt_acc;

void mt_acc_add(mt_acc *a, const double x[3]);
double mt_mean(const mt_acc *a, int c);
double mt_var(const mt_acc *a, int c); /* the sample variance */
double mt_se(const mt_acc *a, int c);  /* the mean's standard error */

/* A uniform hero channel. */
int mt_hero(murk_rng *rng);
/* One transmittance() and one sample() call on ray as volpath makes them (ctx.beta = 1, each with a uniform
 * hero): *T, *ev, and x[c] = the event's weight over the mean pdf ratio (the integrator's weighting: 3x on
 * naive_spectral's hero, the balance heuristic for spectral_mis). Returns 1 if every result is finite. */
int mt_call(const murk_medium *m, const murk_ray *ray, murk_rng *rng, murk_rgb *T, murk_medium_event *ev, double x[3]);
/* Monotonic clock, seconds. */
double mt_seconds(void);

/* Checks a per-channel figure against its expectation: stat_z_ok in every channel, |mean - expect| <=
 * STAT_Z se + rel |expect| + 1e-7 (float rounding). Prints one line: head, then mean +- se (expected, z)
 * per channel, then tail. Returns 1 if a channel failed. */
int mt_check(const char *head, const mt_acc *a, const double expect[3], double rel, const char *tail);
/* A figure whose samples may be heavy-tailed (weighted collisions where a bound fails on purpose), judged
 * by a bound that holds for any distribution on [-W, W] instead of the normal approximation: the
 * empirical Bernstein bound (Maurer and Pontil 2009, theorem 4, both sides),
 *   |mean - expect| <= sqrt(2 V L / n) + 7 R L / (3 (n - 1)),  L = ln(4 / alpha), R = 2 W,
 * V the sample variance, alpha = stat_tail2(STAT_Z) (counted as one decision per channel). W is the
 * weights' maximum: wmax, derived or stated by the caller, or the largest |sample| if that is larger (a
 * stated maximum is not a proof; the figure never fails for exceeding it, it widens the bound). Prints
 * one line like mt_check's with the bound in place of the se and the largest |sample|, and returns 1 if a
 * channel failed. */
int mt_check_bounded(const char *head, const mt_acc *a, const double expect[3], double wmax, const char *tail);
/* The same bound for must-fail cases: the largest over the channels of STAT_Z |mean - expect| / bound
 * (above STAT_Z exactly when mt_check_bounded fails the channel). */
double mt_zmax_bounded(const mt_acc *a, const double expect[3], double wmax);
/* The same test, neither printed nor counted (for must-fail cases): the largest over the channels of
 * (|mean - expect| - slack) / se; the figure fails mt_check exactly when it exceeds STAT_Z. */
double mt_zmax(const mt_acc *a, const double expect[3], double rel);

#endif
