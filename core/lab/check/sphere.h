/* sphere.h — numerical integration over the sphere of directions and Pearson's chi-square test: the
 * statistics behind `murk check` for materials, shared with the BSDF test programs (tests/bsdftest.c).
 * Internal to libmurk (the tests link its objects directly).
 *
 * The sphere is cut into ntheta x nphi cells in a frame whose +z axis is `pole`: x in [0, 1] uniform
 * with cos(theta') = 1 - 2 x^warp, phi' in [0, 2 pi) uniform. warp 1 gives cells uniform in cos theta
 * (equal solid angle); warp > 1 refines around the pole (put it on a specular peak). Each cell is
 * integrated by nested, globally adaptive Gauss-Kronrod (7/15) quadrature to the tolerance
 * max(tol, 1e-6 |integral|) (tol in units of the integrand times steradians), within a fixed budget of
 * subintervals; the error estimates (|K15 - G7| summed, inner errors propagated) are reported, also
 * where the budget stopped the refinement. */
#ifndef MURK_CHECK_SPHERE_H
#define MURK_CHECK_SPHERE_H

#include "murk/math.h"

typedef struct murk_sph_grid {
    int ntheta, nphi;
    murk_vec3 pole; /* unit; {0,0,0} means +z */
    double warp;    /* >= 1; 0 means 1 */
} murk_sph_grid;

typedef double (*murk_sph_fn)(void *ctx, murk_vec3 w);

/* Integral of fn over one cell (it, ip); *err (may be NULL) receives the summed error estimate. */
double murk_sph_integrate_cell(murk_sph_fn fn, void *ctx, const murk_sph_grid *g, int it, int ip, double tol,
                               double *err);
/* Integral of fn over the whole sphere (sum over cells, each with tolerance tol). */
double murk_sph_integrate(murk_sph_fn fn, void *ctx, const murk_sph_grid *g, double tol, double *err);
/* The cell that contains direction w (unit), as it * nphi + ip. */
int murk_sph_cell_of(const murk_sph_grid *g, murk_vec3 w);

/* Pearson chi-square test of observed counts against expected counts, merging bins (in order of
 * increasing expectation) until each holds at least min_expected. Returns the p-value (0 when a bin
 * with expectation 0 holds a count). */
double murk_chi2_test(const double *observed, const double *expected, int nbins, double min_expected, int *dof_out);

#endif
