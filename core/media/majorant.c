/* majorant.c — the bound grid over a density field: per cell a majorant and a minorant of the field
 * (see density.h for the guarantee). Trackers walk it with the DDA in dda.c. A grid whose map is not
 * axis-aligned (field_impl.h, `affine`) gets its bound grid over its local box; the walk transforms
 * the ray (media.c). */
#include "media/field_impl.h"

#include <math.h>
#include <stdlib.h>
#include <string.h>

/* The cell size per axis and its reciprocal, which every DDA walk uses (infinite for an infinite box). */
static void cell_size(murk_bound_grid *g)
{
    for (int a = 0; a < 3; a++) {
        g->h[a] = ((double)murk_v3_get(g->hi, a) - murk_v3_get(g->lo, a)) / g->res[a];
        g->inv_h[a] = 1.0 / g->h[a];
    }
}

int murk_bound_grid_build(const murk_field *f, int target_res, murk_bound_grid *g)
{
    memset(g, 0, sizeof *g);
    if (target_res < 1)
        return -1;
    if (f->kind == FIELD_CONSTANT) {
        g->res[0] = g->res[1] = g->res[2] = 1;
        g->lo = f->lo;
        g->hi = f->hi;
        cell_size(g);
        g->maj = malloc(sizeof *g->maj);
        g->min = malloc(sizeof *g->min);
        if (!g->maj || !g->min) {
            murk_bound_grid_free(g);
            return -1;
        }
        g->maj[0] = g->min[0] = f->value;
        return 0;
    }
    double ext[3], emax = 0.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = (double)murk_v3_get(f->hi, a) - murk_v3_get(f->lo, a);
        emax = fmax(emax, ext[a]);
    }
    for (int a = 0; a < 3; a++) {
        double r = ceil(target_res * ext[a] / emax - 1e-9);
        g->res[a] = r < 1.0 ? 1 : (r > target_res ? target_res : (int)r);
    }
    if (murk_voxel_count(g->res[0], g->res[1], g->res[2]) == 0) {
        memset(g, 0, sizeof *g);
        return -1;
    }
    g->lo = f->lo;
    g->hi = f->hi;
    cell_size(g);
    size_t n = (size_t)g->res[0] * (size_t)g->res[1] * (size_t)g->res[2];
    g->maj = malloc(n * sizeof *g->maj);
    g->min = malloc(n * sizeof *g->min);
    if (!g->maj || !g->min) {
        murk_bound_grid_free(g);
        return -1;
    }
    /* Per axis and bound cell: the voxel index range whose interpolation support overlaps the cell.
     * In continuous index space u = (w - lo) * res / ext - 1/2 voxel i has support (i-1, i+1), and
     * the clamped border half-cells use voxel 0 / res-1 only; so the range is
     * [floor(clamp(ua)), ceil(clamp(ub))], widened by 1e-3 voxel so that neither float rounding
     * in eval nor a DDA segment overshooting its cell by a rounding error can reach a voxel
     * outside it. The bound grid's box is the field's box, so no cell reaches outside it (where
     * the density, 0, would force min = 0). */
    int *range[3];
    for (int a = 0; a < 3; a++) {
        range[a] = malloc(2 * (size_t)g->res[a] * sizeof(int));
        if (!range[a]) {
            for (int b = 0; b < a; b++)
                free(range[b]);
            murk_bound_grid_free(g);
            return -1;
        }
        int nv = f->res[a];
        double lo = murk_v3_get(f->lo, a), cell = ext[a] / g->res[a], s = nv / ext[a];
        for (int c = 0; c < g->res[a]; c++) {
            double wa = lo + c * cell, wb = lo + (c + 1) * cell;
            double ua = (wa - lo) * s - 0.5 - 1e-3, ub = (wb - lo) * s - 0.5 + 1e-3;
            ua = ua < 0.0 ? 0.0 : (ua > nv - 1 ? nv - 1 : ua);
            ub = ub < 0.0 ? 0.0 : (ub > nv - 1 ? nv - 1 : ub);
            range[a][2 * c] = (int)floor(ua);
            range[a][2 * c + 1] = (int)ceil(ub);
        }
    }
    size_t k = 0;
    for (int cz = 0; cz < g->res[2]; cz++)
        for (int cy = 0; cy < g->res[1]; cy++)
            for (int cx = 0; cx < g->res[0]; cx++, k++) {
                int a[3] = {range[0][2 * cx], range[1][2 * cy], range[2][2 * cz]};
                int b[3] = {range[0][2 * cx + 1], range[1][2 * cy + 1], range[2][2 * cz + 1]};
                murk_field_range(f, a, b, &g->maj[k], &g->min[k]);
            }
    for (int a = 0; a < 3; a++)
        free(range[a]);
    return 0;
}

void murk_bound_grid_free(murk_bound_grid *g)
{
    free(g->maj);
    free(g->min);
    g->maj = g->min = NULL;
}
