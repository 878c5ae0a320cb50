/* density.h — scalar density fields, their majorant/minorant grids and a 3-D DDA. Internal to libmurk.
 *
 * A field is either a constant (infinite extent) or a grid of float voxels over a box [lo, hi] (README,
 * "Media"): voxel values sit at the CENTRES of the res[0] x res[1] x res[2] cells of that box;
 * murk_field_eval interpolates trilinearly between centres, clamps to the nearest centre in the border
 * half-cells (so the value there is constant along the clamped axis) and returns 0 outside the closed
 * box (and for NaN positions). Grid values are finite and >= 0. A grid is held dense (every voxel of
 * its box) or sparse (sparse.c: 8^3 bricks of its active voxels only; inactive voxels are 0); both
 * interpolate with the same arithmetic, so the same voxels give the same values bit for bit.
 *
 * Sources of grids:
 *   - Mitsuba 3 .vol files, dense ('V','O','L',3; float32 only; ONE channel only: files with 3 or more
 *     channels are rejected rather than silently reduced to channel 0, because a multi-channel .vol
 *     is an albedo/colour grid far more often than a density);
 *   - OpenVDB .vdb files, sparse (vdb.c, through a C++ shim over libopenvdb; a named float, half or
 *     double grid);
 *   - NanoVDB .nvdb files, sparse (the first float grid; uncompressed segments or raw grid buffers);
 *   - a procedural fBm cloud baked into a dense res^3 grid, so it is exactly as trilinear as a file grid.
 * A VDB grid's box is its active voxels' index box [min, max] grown by one voxel of zeros on every side:
 * voxel ijk's value sits at map(ijk), so the world box is the map of [min - 3/2, max + 3/2], and the field
 * is the trilinear interpolation of the file's voxels (inactive ones 0) everywhere. A map that rotates, shears or mirrors is kept as a transform:
 * the field is looked up, and its bound grid built and walked, in the grid's own index space
 * (field_impl.h, `affine`), and murk_field_bounds gives the world box around it.
 *
 * Loaders return NULL and write "path: what is wrong" into err; nothing is leaked on failure.
 *
 * The bound grid divides the field's box into cells and stores, per cell, a majorant and a minorant
 * that bound murk_field_eval over the closed cell: the max/min of every voxel whose interpolation
 * support overlaps the cell (clamped border half-cells included) — a guaranteed bound, attained
 * where the cell holds those voxels' centres. The grid covers exactly the field's box, so no cell
 * reaches outside it (outside, the density is 0 and the DDA reports zero segments).
 *
 * Fields and bound grids are immutable after creation: any number of threads may read them.
 *
 * Files (core/media): field.c the field itself; sparse.c the sparse storage; vol.c, vdb.c (+ vdb_shim.cpp),
 * nanovdb.c and cloud.c its sources; source.c the scene's field blocks; majorant.c the bound grid; dda.c
 * the walk through it. field_impl.h is what they share. */
#ifndef MURK_DENSITY_H
#define MURK_DENSITY_H

#include "util/limit.h"
#include <stddef.h>
#include <stdint.h>

#include "murk/math.h"

/* Largest dense grid accepted from a file or built procedurally, and most active voxels of a sparse one:
 * MURK_MAX_GRID_VOXELS (limit.h; 2^27 voxels, 512 MiB of floats, by default). */
#define MURK_FIELD_MAX_VOXELS murk_limit(MURK_LIMIT_GRID_VOXELS)

typedef struct murk_field murk_field;

murk_field *murk_field_constant(float value); /* NULL if value is negative or not finite */
/* A grid field over [lo, hi] copying data[((z*res[1] + y)*res[0] + x)]; NULL if a resolution is < 1,
 * the grid is too large, the box is not finite with lo < hi, a value is negative or not finite, or
 * out of memory. */
murk_field *murk_field_from_voxels(const int res[3], murk_vec3 lo, murk_vec3 hi, const float *data);
murk_field *murk_field_vol_load(const char *path, char *err, size_t errlen);
/* Writes a grid field as a 1-channel float32 .vol (temporary file + rename); -1 on error (also for a
 * constant field, which has no grid, a sparse grid whose box exceeds MURK_MAX_GRID_VOXELS, or one whose
 * map is not axis-aligned). A saved-then-loaded field is bitwise identical (a sparse grid's box and
 * voxels become a dense grid that evaluates to the same values). */
int murk_field_vol_save(const char *path, const murk_field *f, char *err, size_t errlen);
/* An RGB grid from a .vol of 1 channel (grey: out[0] = out[1] = out[2], one field) or 3 channels (three
 * fields, one per channel, each checked like a density grid). Returns the file's channel count, or -1
 * with err (out[] NULL). */
int murk_field_vol_load3(const char *path, murk_field *out[3], char *err, size_t errlen);
murk_field *murk_field_nvdb_load(const char *path, char *err, size_t errlen);
/* The float (or half, or double) grid called `grid` of an OpenVDB file; NULL grid: the file's only grid.
 * When the file has no such grid the error names the grids it has and *no_such_grid (if not NULL) is set
 * to 1. Without OpenVDB support in the build, NULL with an error that says so. */
murk_field *murk_field_vdb_load(const char *path, const char *grid, int *no_such_grid, char *err, size_t errlen);
/* 1 if this murk was built with OpenVDB support (murk_field_vdb_load can read files). */
int murk_field_vdb_supported(void);
/* fBm cloud in [lo, hi]: res^3 voxels (2..1024), frequency in features per box width (> 0),
 * octaves 1..16, coverage in [0, 1] (larger fills more of the box). Deterministic for a seed; the
 * outermost voxel layer is 0 so the density falls to 0 at the box faces; normalised so the maximum
 * voxel is exactly 1 (unless the cloud is empty). NULL on invalid arguments or out of memory. */
murk_field *murk_field_cloud(murk_vec3 lo, murk_vec3 hi, int res, uint64_t seed, float frequency,
                             int octaves, float coverage);

float murk_field_eval(const murk_field *f, murk_vec3 p);
/* lo/hi = the box (±INFINITY and *infinite = 1 for a constant field). Any pointer may be NULL. */
void murk_field_bounds(const murk_field *f, murk_vec3 *lo, murk_vec3 *hi, int *infinite);
/* Max / min of murk_field_eval over the box (the voxel extremes; outside the box it is 0). */
float murk_field_max(const murk_field *f);
float murk_field_min(const murk_field *f);
/* Grid access for savers and tests: resolution (1,1,1 for a constant) and voxels (NULL for a
 * constant or a sparse grid), data[((z*res[1] + y)*res[0] + x)]. */
void murk_field_grid(const murk_field *f, int res[3], const float **data);
/* The voxel (x, y, z) of a grid's box (0 <= x < res[0], ...; the value for a constant). */
float murk_field_voxel(const murk_field *f, int x, int y, int z);
/* What a field is and holds, for `murk info` and the render summary. */
typedef struct murk_field_info {
    int sparse;            /* 1: bricks of active voxels (.vdb, .nvdb); 0: dense grid or constant */
    int held_dense;        /* 1: a sparse grid (.vdb, .nvdb) held dense, its dense form being no larger than
                              its sparse form (sparse.c, murk_sparse_end); sparse is 0 then */
    int grid;              /* 1: a grid (dense or sparse); 0: a constant */
    int transformed;       /* 1: a map that rotates, shears or mirrors (looked up in index space) */
    uint64_t active;       /* sparse or held_dense: active voxels of the source grid */
    size_t bricks;         /* sparse: distinct 8^3 bricks (shared constant bricks once) */
    size_t bytes;          /* memory held: the voxels (dense), or bricks, nodes and tables (sparse) */
    size_t sparse_bytes;   /* sparse: its bricks, nodes and tables; held_dense: what they held before */
} murk_field_info;
void murk_field_describe(const murk_field *f, murk_field_info *info);
void murk_field_free(murk_field *f);

/* Majorant/minorant grid over the field's box; cell (x,y,z) is maj/min[(z*res[1] + y)*res[0] + x].
 * For a constant field: one cell, lo/hi = ∓INFINITY, maj = min = the value. */
typedef struct murk_bound_grid {
    int res[3];
    murk_vec3 lo, hi;
    double h[3], inv_h[3]; /* a cell's size per axis and its reciprocal (the DDA's, set once here) */
    float *maj, *min;
} murk_bound_grid;

/* target_res cells along the box's longest axis, proportionally fewer (at least 1) along the others
 * (a constant field always gets one cell). Returns 0, or -1 if target_res < 1, the grid would exceed
 * MURK_FIELD_MAX_VOXELS cells, or out of memory (g is then zeroed). */
int murk_bound_grid_build(const murk_field *f, int target_res, murk_bound_grid *g);
/* The ray in the bound grid's space: the same ray for a field without a transform, else the ray mapped
 * to the grid's local space (the same parameter t reaches the same point). */
murk_ray murk_field_local_ray(const murk_field *f, const murk_ray *r);
void murk_bound_grid_free(murk_bound_grid *g);

/* DDA over a bound grid. murk_dda_next yields consecutive half-open segments [ta, tb) that exactly
 * tile [t0, t1]: the first ta is t0, each ta equals the previous tb bitwise, the last tb is t1.
 * The parts of [t0, t1] outside the grid box (or the whole range, for a ray missing the box) come
 * out as segments with maj = min = 0 and cell = {-1,-1,-1} — the density is 0 there — so a tracker
 * can treat every segment alike. Segments inside the box carry their cell's bounds and index.
 * Yields nothing when !(t0 < t1) (including NaN). t1 may be INFINITY. The ray direction need not be
 * unit length; zero and -0 components are fine; r->tmin/tmax are ignored (t0/t1 rule). */
typedef struct murk_dda {
    const murk_bound_grid *g;
    double o[3], d[3];    /* ray origin and direction */
    double inv_d[3];      /* 1/d (0 where d is 0) */
    float t, t1;          /* start of the next segment; end of the range */
    float tin, tout;      /* the ray's parameter range inside the grid box (tin > tout: missed) */
    int phase;            /* before the box, entering, inside, after the box, done */
    int idx[3], step[3];  /* current cell and step direction per axis */
    int cell[3];          /* the cell of the segment last returned ({-1,-1,-1} outside the box) */
} murk_dda;

void murk_dda_init(murk_dda *it, const murk_bound_grid *g, const murk_ray *r, float t0, float t1);
/* Returns 1 and fills the outputs (any may be NULL) for the next segment, 0 when done. */
int murk_dda_next(murk_dda *it, float *ta, float *tb, float *maj, float *min);

/* ---- Blackbody emission (blackbody.c) -------------------------------------------------------------
 * Planck's law at temperature T (kelvin), normalised to its peak (as pbrt-v4), integrated against the CIE
 * 1931 2-degree colour-matching functions (5 nm, 360..830 nm) over the integral of ybar: CIE XYZ; then
 * linear sRGB (D65), negative channels set to 0. T <= 0 or not finite: black. */
void murk_blackbody_xyz(double T, double xyz[3]);
/* Row i (360 + 5 i nm, i in [0, 94]) of the CIE 1931 table blackbody.c integrates with: xbar, ybar, zbar. */
void murk_cie1931(int i, double cmf[3]);
murk_rgb murk_blackbody_rgb(double T);

/* murk_blackbody_rgb tabulated over [0, tmax] in n equal steps (at most 1 K apart, at most
 * MURK_BLACKBODY_TABLE_MAX + 1 entries), linearly interpolated by murk_blackbody_lookup and clamped at
 * tmax: what a temperature field's lookups use. */
#define MURK_BLACKBODY_TABLE_MAX 65536
typedef struct murk_blackbody_table {
    int n;
    float step, inv_step;
    murk_rgb *rgb; /* n + 1 entries (the last repeated) */
} murk_blackbody_table;
int murk_blackbody_table_build(murk_blackbody_table *t, double tmax); /* -1: out of memory */
void murk_blackbody_table_free(murk_blackbody_table *t);

static inline murk_rgb murk_blackbody_lookup(const murk_blackbody_table *t, float T)
{
    float x = T * t->inv_step;
    if (!(x > 0.0f))
        return t->rgb[0];
    if (x >= (float)(t->n - 1))
        return t->rgb[t->n - 1];
    int i = (int)x;
    float w = x - (float)i;
    murk_rgb a = t->rgb[i], b = t->rgb[i + 1];
    return murk_rgb3(a.c[0] + w * (b.c[0] - a.c[0]), a.c[1] + w * (b.c[1] - a.c[1]), a.c[2] + w * (b.c[2] - a.c[2]));
}

#endif
