/* murk/math.h — small vector and colour types shared by the core and every plugin.
 * Header-only (static inline); no dependency beyond <math.h>. */
#ifndef MURK_MATH_H
#define MURK_MATH_H

#include <math.h>
#include <stdint.h>

#define MURK_PI 3.14159265358979323846f
#define MURK_INV_PI 0.31830988618379067154f

typedef struct murk_vec3 { float x, y, z; } murk_vec3;
/* Linear RGB; c[0..2] so that trackers can loop over channels. */
typedef struct murk_rgb { float c[3]; } murk_rgb;

typedef struct murk_ray {
    murk_vec3 o, d; /* d is unit length */
    float tmin, tmax;
} murk_ray;

/* min/max that compile to one instruction (fmaxf/fminf are libm calls unless NaN semantics can be
 * ignored). If b is NaN the result is NaN, so NaNs still reach the film's non-finite check. */
static inline float murk_maxf(float a, float b) { return a > b ? a : b; }
static inline float murk_minf(float a, float b) { return a < b ? a : b; }
/* fmaxf, fminf, fmax and fmin as C99 defines them (a quiet NaN argument yields the other one), with the very
 * results of glibc's x86-64 versions (of two equal numbers, such as -0 and +0, b), inlined: gcc calls libm
 * for them unless NaNs and signed zeros may be ignored, and the hot loops that use them (ratio tracking,
 * the majorant walk, phase functions) should make no call per step. */
static inline float murk_fmaxf(float a, float b) { return a > b || isnan(b) ? a : b; }
static inline float murk_fminf(float a, float b) { return a < b || isnan(b) ? a : b; }
static inline double murk_fmax(double a, double b) { return a > b || isnan(b) ? a : b; }
static inline double murk_fmin(double a, double b) { return a < b || isnan(b) ? a : b; }

static inline murk_vec3 murk_v3(float x, float y, float z) { murk_vec3 v = {x, y, z}; return v; }
static inline murk_vec3 murk_add(murk_vec3 a, murk_vec3 b) { return murk_v3(a.x + b.x, a.y + b.y, a.z + b.z); }
static inline murk_vec3 murk_sub(murk_vec3 a, murk_vec3 b) { return murk_v3(a.x - b.x, a.y - b.y, a.z - b.z); }
static inline murk_vec3 murk_mul(murk_vec3 a, float s) { return murk_v3(a.x * s, a.y * s, a.z * s); }
static inline murk_vec3 murk_madd(murk_vec3 a, murk_vec3 b, float s) { return murk_v3(a.x + b.x * s, a.y + b.y * s, a.z + b.z * s); }
static inline murk_vec3 murk_neg(murk_vec3 a) { return murk_v3(-a.x, -a.y, -a.z); }
static inline float murk_dot(murk_vec3 a, murk_vec3 b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
static inline murk_vec3 murk_cross(murk_vec3 a, murk_vec3 b)
{
    return murk_v3(a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x);
}
static inline float murk_length(murk_vec3 a) { return sqrtf(murk_dot(a, a)); }
static inline murk_vec3 murk_normalize(murk_vec3 a)
{
    float l = murk_length(a);
    return l > 0.0f ? murk_mul(a, 1.0f / l) : a;
}
static inline float murk_v3_get(murk_vec3 a, int i) { return i == 0 ? a.x : (i == 1 ? a.y : a.z); }
/* Componentwise minimum and maximum (fminf/fmaxf: a NaN component gives the other's). */
static inline murk_vec3 murk_vmin(murk_vec3 a, murk_vec3 b) { return murk_v3(fminf(a.x, b.x), fminf(a.y, b.y), fminf(a.z, b.z)); }
static inline murk_vec3 murk_vmax(murk_vec3 a, murk_vec3 b) { return murk_v3(fmaxf(a.x, b.x), fmaxf(a.y, b.y), fmaxf(a.z, b.z)); }

/* Orthonormal basis around unit n (Duff et al. 2017, branchless). */
static inline void murk_basis(murk_vec3 n, murk_vec3 *t, murk_vec3 *b)
{
    float sign = copysignf(1.0f, n.z);
    float a = -1.0f / (sign + n.z);
    float bb = n.x * n.y * a;
    *t = murk_v3(1.0f + sign * n.x * n.x * a, sign * bb, -sign * n.x);
    *b = murk_v3(bb, sign + n.y * n.y * a, -n.y);
}
static inline murk_vec3 murk_to_local(murk_vec3 v, murk_vec3 t, murk_vec3 b, murk_vec3 n)
{
    return murk_v3(murk_dot(v, t), murk_dot(v, b), murk_dot(v, n));
}
static inline murk_vec3 murk_from_local(murk_vec3 v, murk_vec3 t, murk_vec3 b, murk_vec3 n)
{
    return murk_add(murk_add(murk_mul(t, v.x), murk_mul(b, v.y)), murk_mul(n, v.z));
}

static inline murk_rgb murk_rgb3(float r, float g, float b) { murk_rgb c = {{r, g, b}}; return c; }
static inline murk_rgb murk_rgb1(float v) { return murk_rgb3(v, v, v); }
static inline murk_rgb murk_rgb_add(murk_rgb a, murk_rgb b) { return murk_rgb3(a.c[0] + b.c[0], a.c[1] + b.c[1], a.c[2] + b.c[2]); }
static inline murk_rgb murk_rgb_mul(murk_rgb a, murk_rgb b) { return murk_rgb3(a.c[0] * b.c[0], a.c[1] * b.c[1], a.c[2] * b.c[2]); }
static inline murk_rgb murk_rgb_scale(murk_rgb a, float s) { return murk_rgb3(a.c[0] * s, a.c[1] * s, a.c[2] * s); }
static inline float murk_rgb_max(murk_rgb a) { return murk_maxf(a.c[0], murk_maxf(a.c[1], a.c[2])); }
static inline float murk_rgb_avg(murk_rgb a) { return (a.c[0] + a.c[1] + a.c[2]) * (1.0f / 3.0f); }
static inline float murk_luminance(murk_rgb a) { return 0.2126f * a.c[0] + 0.7152f * a.c[1] + 0.0722f * a.c[2]; }
static inline int murk_rgb_is_black(murk_rgb a) { return a.c[0] == 0.0f && a.c[1] == 0.0f && a.c[2] == 0.0f; }
static inline int murk_rgb_finite(murk_rgb a) { return isfinite(a.c[0]) && isfinite(a.c[1]) && isfinite(a.c[2]); }

/* ---- Random numbers and the sampler ----------------------------------------------------------
 * murk_rng is PCG32 (O'Neill 2014). The core seeds one stream per (seed, pixel, sample) by hashing
 * those counters, so a sample's numbers never depend on which thread ran it or in which order.
 *
 * ABI 1.4 appends the sampler: murk_sample_1d/2d() draw the integrator's dimensions, one *slot* per
 * call (a 2-D slot gives a point, a 1-D slot its first coordinate). With MURK_SAMPLER_SOBOL slot s
 * of sample i of a pixel is the point i of a padded Owen-scrambled Sobol sequence (Burley 2020):
 * Sobol dimensions 0 and 1 of a shuffled index, the shuffle and both scrambles hashed from (seed,
 * pixel, s). So the first 2^k samples of every slot are stratified (one point per elementary interval
 * of area 2^-k), slots are independent of one another (padding: any number of them), and sample i is a
 * function of (seed, pixel, i) alone: any range of samples [a, b) is the same points whichever pass,
 * thread or tile renders it. murk_sample_seek() sets the next slot, so that a decision takes the same
 * slot in every sample (the integrators' slot order is documented in docs/plugins.md). With
 * MURK_SAMPLER_INDEPENDENT (and in an rng that murk_rng_seed() made) the same calls draw
 * murk_rng_float() in call order. murk_rng_float() always draws from the PCG stream, which the sampler
 * never touches: code with unbounded use of numbers (a tracker's collision loop) takes them there
 * without shifting the integrator's slots. Only the core creates the murk_rng it passes to plugins, so a
 * plugin built against ABI 1.3 (which knows state and inc only) still works unchanged. */
enum { MURK_SAMPLER_INDEPENDENT = 0, MURK_SAMPLER_SOBOL = 1 };

typedef struct murk_rng {
    uint64_t state, inc;
    /* ABI 1.4 */
    uint64_t scramble; /* hash of (seed, pixel): the sampler's per-pixel decorrelation */
    uint32_t sampler;  /* MURK_SAMPLER_* */
    uint32_t index;    /* the sample's index within its pixel */
    uint32_t dim;      /* the next slot */
    uint32_t rindex;   /* index with its bits reversed */
} murk_rng;

static inline uint64_t murk_hash64(uint64_t x)
{ /* splitmix64 finaliser */
    x += 0x9e3779b97f4a7c15ull;
    x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ull;
    x = (x ^ (x >> 27)) * 0x94d049bb133111ebull;
    return x ^ (x >> 31);
}
static inline uint32_t murk_rng_u32(murk_rng *r)
{
    uint64_t old = r->state;
    r->state = old * 6364136223846793005ull + r->inc;
    uint32_t xs = (uint32_t)(((old >> 18u) ^ old) >> 27u);
    uint32_t rot = (uint32_t)(old >> 59u);
    return (xs >> rot) | (xs << ((-rot) & 31u));
}
static inline void murk_rng_seed(murk_rng *r, uint64_t a, uint64_t b, uint64_t c)
{
    uint64_t h = murk_hash64(a ^ murk_hash64(b ^ murk_hash64(c)));
    r->state = 0u;
    r->inc = (murk_hash64(h + 1u) << 1u) | 1u;
    murk_rng_u32(r);
    r->state += h;
    murk_rng_u32(r);
    r->scramble = 0u;
    r->sampler = MURK_SAMPLER_INDEPENDENT;
    r->index = r->dim = r->rindex = 0u;
}
/* Uniform float in [0, 1): 24 random mantissa bits, never 1. */
static inline float murk_rng_float(murk_rng *r) { return (float)(murk_rng_u32(r) >> 8) * (1.0f / 16777216.0f); }

static inline uint32_t murk_reverse_bits32(uint32_t x)
{
    x = ((x >> 1) & 0x55555555u) | ((x & 0x55555555u) << 1);
    x = ((x >> 2) & 0x33333333u) | ((x & 0x33333333u) << 2);
    x = ((x >> 4) & 0x0f0f0f0fu) | ((x & 0x0f0f0f0fu) << 4);
    x = ((x >> 8) & 0x00ff00ffu) | ((x & 0x00ff00ffu) << 8);
    return (x >> 16) | (x << 16);
}

/* The stream of sample `index` of pixel `pixel` for a render seeded with `seed`, drawing its slots
 * with `sampler` (MURK_SAMPLER_*) from slot 0. What the core does before every sample. */
static inline void murk_sampler_start(murk_rng *r, uint32_t sampler, uint64_t seed, uint64_t pixel, uint32_t index)
{
    murk_rng_seed(r, seed, pixel, index);
    r->scramble = murk_hash64(murk_hash64(seed ^ 0x5851f42d4c957f2dull) ^ pixel);
    r->sampler = sampler;
    r->index = index;
    r->rindex = murk_reverse_bits32(index);
}
static inline void murk_sample_seek(murk_rng *r, uint32_t slot) { r->dim = slot; }

/* Sobol dimension 1 is Pascal's matrix mod 2: output bit j (from the top) is the XOR of the index bits
 * k (from the bottom) with j a subset of k (Lucas). That is a superset-sum over the 5-bit positions,
 * five shift-xor steps; the result has output bit j at position j, i.e. it is reversed. */
static inline uint32_t murk_sobol1_reversed(uint32_t i)
{
    i ^= (i >> 1) & 0x55555555u;
    i ^= (i >> 2) & 0x33333333u;
    i ^= (i >> 4) & 0x0f0f0f0fu;
    i ^= (i >> 8) & 0x00ff00ffu;
    i ^= (i >> 16) & 0x0000ffffu;
    return i;
}
/* A nested uniform (Owen) scramble of the bits of x, most significant first, is reverse(lk(reverse(x))):
 * lk flips each bit by a hash of the bits below it (Laine-Karras style, Vegdahl's constants). */
static inline uint32_t murk_lk_hash_(uint32_t x, uint32_t seed)
{
    x ^= x * 0x3d20adeau;
    x += seed;
    x *= (seed >> 16) | 1u;
    x ^= x * 0x05526c56u;
    x ^= x * 0x53a22864u;
    return x;
}
/* The next slot's shuffled sample index i (an Owen scramble of the index, which keeps every block of
 * 2^k consecutive indices a (0, k, 2)-net) and its scrambled Sobol coordinate 0; *h gets the slot's
 * hash. owen(sobol0(i)) = reverse(lk(i)) since sobol0 is the bit reversal. */
static inline uint32_t murk_sample_slot_(murk_rng *r, uint32_t *i, uint64_t *h)
{
    *h = murk_hash64(r->scramble + 0x9e3779b97f4a7c15ull * (uint64_t)(r->dim++ + 1u));
    *i = murk_reverse_bits32(murk_lk_hash_(r->rindex, (uint32_t)*h));
    return murk_reverse_bits32(murk_lk_hash_(*i, (uint32_t)(*h >> 32)));
}
static inline float murk_u24_(uint32_t x) { return (float)(x >> 8) * (1.0f / 16777216.0f); }
/* The next slot as a point in [0, 1)^2 (24 bits each, never 1). */
static inline void murk_sample_2d(murk_rng *r, float u[2])
{
    if (r->sampler != MURK_SAMPLER_SOBOL) {
        u[0] = murk_rng_float(r);
        u[1] = murk_rng_float(r);
        return;
    }
    /* u[0] = u24(reverse(lk(i, hi32(h)))), u[1] = u24(reverse(lk(sobol1_reversed(i), lo32(hash(h))))), as
     * murk_sample_slot_() and murk_sample_1d() compute them, with the two independent reversals done as one
     * 64-bit reversal of the pair (reversing a:b gives reverse(b):reverse(a)) */
    uint64_t h = murk_hash64(r->scramble + 0x9e3779b97f4a7c15ull * (uint64_t)(r->dim++ + 1u));
    uint32_t i = murk_reverse_bits32(murk_lk_hash_(r->rindex, (uint32_t)h));
    uint64_t ab = ((uint64_t)murk_lk_hash_(i, (uint32_t)(h >> 32)) << 32) |
                  murk_lk_hash_(murk_sobol1_reversed(i), (uint32_t)murk_hash64(h));
    ab = ((ab >> 1) & 0x5555555555555555ull) | ((ab & 0x5555555555555555ull) << 1);
    ab = ((ab >> 2) & 0x3333333333333333ull) | ((ab & 0x3333333333333333ull) << 2);
    ab = ((ab >> 4) & 0x0f0f0f0f0f0f0f0full) | ((ab & 0x0f0f0f0f0f0f0f0full) << 4);
    ab = ((ab >> 8) & 0x00ff00ff00ff00ffull) | ((ab & 0x00ff00ff00ff00ffull) << 8);
    ab = ((ab >> 16) & 0x0000ffff0000ffffull) | ((ab & 0x0000ffff0000ffffull) << 16);
    ab = (ab >> 32) | (ab << 32);
    u[0] = murk_u24_((uint32_t)ab);
    u[1] = murk_u24_((uint32_t)(ab >> 32));
}
/* The next slot as one number in [0, 1). */
static inline float murk_sample_1d(murk_rng *r)
{
    uint32_t i;
    uint64_t h;
    return r->sampler != MURK_SAMPLER_SOBOL ? murk_rng_float(r) : murk_u24_(murk_sample_slot_(r, &i, &h));
}

#endif
