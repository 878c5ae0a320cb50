/* cloud.c — the procedural cloud: fBm gradient noise shaped into a ball, baked into a grid field so
 * that it interpolates and bounds exactly like a file grid (see murk_field_cloud in density.h). */
#include "media/field_impl.h"
#include "util/util.h"

#include <math.h>
#include <stdlib.h>

static uint64_t lattice_hash(uint64_t seed, int64_t x, int64_t y, int64_t z)
{
    uint64_t h = (uint64_t)x * 0x9e3779b97f4a7c15ull ^ (uint64_t)y * 0xc2b2ae3d27d4eb4full ^
                 (uint64_t)z * 0x165667b19e3779f9ull;
    return murk_hash64(h ^ murk_hash64(seed));
}

static double fade(double t) { return t * t * t * (t * (t * 6.0 - 15.0) + 10.0); }

/* Gradient noise (Perlin 2002 style: quintic fade, 12 edge gradients), roughly in [-1, 1]. */
static double gradient_noise(uint64_t seed, double x, double y, double z)
{
    static const signed char G[12][3] = {{1, 1, 0}, {-1, 1, 0}, {1, -1, 0}, {-1, -1, 0}, {1, 0, 1}, {-1, 0, 1},
                                         {1, 0, -1}, {-1, 0, -1}, {0, 1, 1}, {0, -1, 1}, {0, 1, -1}, {0, -1, -1}};
    double fx = floor(x), fy = floor(y), fz = floor(z);
    int64_t ix = (int64_t)fx, iy = (int64_t)fy, iz = (int64_t)fz;
    double dx = x - fx, dy = y - fy, dz = z - fz;
    double c[8];
    for (int k = 0; k < 8; k++) {
        int ox = k & 1, oy = (k >> 1) & 1, oz = (k >> 2) & 1;
        const signed char *g = G[lattice_hash(seed, ix + ox, iy + oy, iz + oz) % 12u];
        c[k] = g[0] * (dx - ox) + g[1] * (dy - oy) + g[2] * (dz - oz);
    }
    double u = fade(dx), v = fade(dy), w = fade(dz);
    double x00 = c[0] + u * (c[1] - c[0]), x10 = c[2] + u * (c[3] - c[2]);
    double x01 = c[4] + u * (c[5] - c[4]), x11 = c[6] + u * (c[7] - c[6]);
    double y0 = x00 + v * (x10 - x00), y1 = x01 + v * (x11 - x01);
    return y0 + w * (y1 - y0);
}

static double smoothstep01(double a, double b, double x)
{
    double t = (x - a) / (b - a);
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    return t * t * (3.0 - 2.0 * t);
}

MURK_API murk_field *murk_field_cloud(murk_vec3 lo, murk_vec3 hi, int res, uint64_t seed, float frequency, int octaves,
                             float coverage)
{
    if (!murk_box_ok(lo, hi) || res < 2 || res > 1024 || !(frequency > 0.0f) || !isfinite(frequency) || octaves < 1 ||
        octaves > 16 || !(coverage >= 0.0f && coverage <= 1.0f))
        return NULL;
    uint64_t n = murk_voxel_count(res, res, res);
    if (n == 0)
        return NULL;
    float *data = malloc((size_t)n * sizeof *data);
    if (!data)
        return NULL;
    double ext[3], emax = 0.0;
    for (int a = 0; a < 3; a++) {
        ext[a] = (double)murk_v3_get(hi, a) - murk_v3_get(lo, a);
        emax = fmax(emax, ext[a]);
    }
    /* Per-octave seeds and offsets decorrelate the octaves. */
    uint64_t oseed[16];
    double off[16][3], norm = 0.0;
    for (int o = 0; o < octaves; o++) {
        oseed[o] = murk_hash64(seed + 0x51ed27u * (uint64_t)(o + 1));
        for (int a = 0; a < 3; a++)
            off[o][a] = (double)(murk_hash64(oseed[o] + (uint64_t)a) >> 40) * (1.0 / 16777216.0) * 64.0;
        norm += ldexp(1.0, -o);
    }
    double vmax = 0.0;
    size_t i = 0;
    for (int z = 0; z < res; z++)
        for (int y = 0; y < res; y++)
            for (int x = 0; x < res; x++, i++) {
                int c[3] = {x, y, z};
                if (x == 0 || y == 0 || z == 0 || x == res - 1 || y == res - 1 || z == res - 1) {
                    data[i] = 0.0f; /* the outermost layer: density reaches 0 at the faces */
                    continue;
                }
                double q[3], np[3], r2 = 0.0, window = 1.0;
                for (int a = 0; a < 3; a++) {
                    double t = (c[a] + 0.5) / res;                /* 0..1 across the box */
                    q[a] = 2.0 * t - 1.0;                         /* -1..1 */
                    np[a] = t * ext[a] / emax * frequency;        /* isotropic noise space */
                    r2 += q[a] * q[a];
                    window *= smoothstep01(0.0, 0.2, 1.0 - fabs(q[a]));
                }
                double sum = 0.0;
                for (int o = 0; o < octaves; o++) {
                    double s = ldexp(1.0, o);
                    sum += ldexp(1.0, -o) * gradient_noise(oseed[o], np[0] * s + off[o][0], np[1] * s + off[o][1],
                                                           np[2] * s + off[o][2]);
                }
                double fbm = sum / norm;                          /* roughly -0.7..0.7 */
                double shape = 1.0 - sqrt(r2);                    /* 1 at the centre, <= 0 outside the ball */
                double d = (shape + 0.8 * fbm - 0.6 * (1.0 - coverage)) * window;
                d = d > 0.0 ? d : 0.0;
                data[i] = (float)d;
                vmax = fmax(vmax, (double)data[i]);
            }
    if (vmax > 0.0) {
        float peak = (float)vmax; /* divide (not multiply by a reciprocal) so the maximum is exactly 1 */
        for (size_t k = 0; k < (size_t)n; k++)
            data[k] /= peak;
    }
    int r[3] = {res, res, res};
    return murk_field_wrap(r, lo, hi, data);
}
