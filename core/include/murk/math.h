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
/* The largest |component| of v: the scale of a point's coordinates, for offsets and tolerances. */
static inline float murk_maxabs(murk_vec3 v) { return murk_maxf(fabsf(v.x), murk_maxf(fabsf(v.y), fabsf(v.z))); }

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
/* u[0] = u24(reverse(hi32(ab))), u[1] = u24(reverse(lo32(ab))): the two reversals as one of 64 bits
 * (reversing a:b gives reverse(b):reverse(a)). */
static inline void murk_u24_pair_(uint64_t ab, float u[2])
{
    ab = ((ab >> 1) & 0x5555555555555555ull) | ((ab & 0x5555555555555555ull) << 1);
    ab = ((ab >> 2) & 0x3333333333333333ull) | ((ab & 0x3333333333333333ull) << 2);
    ab = ((ab >> 4) & 0x0f0f0f0f0f0f0f0full) | ((ab & 0x0f0f0f0f0f0f0f0full) << 4);
    ab = ((ab >> 8) & 0x00ff00ff00ff00ffull) | ((ab & 0x00ff00ff00ff00ffull) << 8);
    ab = ((ab >> 16) & 0x0000ffff0000ffffull) | ((ab & 0x0000ffff0000ffffull) << 16);
    ab = (ab >> 32) | (ab << 32);
    u[0] = murk_u24_((uint32_t)ab);
    u[1] = murk_u24_((uint32_t)(ab >> 32));
}
/* The next slot as a point in [0, 1)^2 (24 bits each, never 1). */
static inline void murk_sample_2d(murk_rng *r, float u[2])
{
    if (r->sampler != MURK_SAMPLER_SOBOL) {
        u[0] = murk_rng_float(r);
        u[1] = murk_rng_float(r);
        return;
    }
    /* u[0] = u24(reverse(lk(i, hi32(h)))), u[1] = u24(reverse(lk(sobol1_reversed(i), lo32(hash(h))))), as
     * murk_sample_slot_() and murk_sample_1d() compute them, both reversals as one (murk_u24_pair_) */
    uint64_t h = murk_hash64(r->scramble + 0x9e3779b97f4a7c15ull * (uint64_t)(r->dim++ + 1u));
    uint32_t i = murk_reverse_bits32(murk_lk_hash_(r->rindex, (uint32_t)h));
    uint64_t ab = ((uint64_t)murk_lk_hash_(i, (uint32_t)(h >> 32)) << 32) |
                  murk_lk_hash_(murk_sobol1_reversed(i), (uint32_t)murk_hash64(h));
    murk_u24_pair_(ab, u);
}
/* Sobol dimensions 2 and 3 (Joe and Kuo 2008's third and fourth: x^2 + x + 1 with m = 1, 3 and
 * x^3 + x + 1 with m = 1, 3, 1), bit-reversed and four index bits at a time: entry [n][v] is the XOR of
 * the reversed generator-matrix columns 31 - 4n - b, b = 0..3, for the bits b set in v, dimension 3 in
 * the high word. Indexed by the nibbles of reverse(i), it gives reverse(sobol2(i)) : reverse(sobol3(i))
 * with no reversal computed. */
static const uint64_t murk_sobol23_[8][16] = {
    {0x0000000000000000ull, 0xc900a00aaaaa00a3ull, 0x4500400477770071ull, 0x8c00e00edddd00d2ull,
     0x2e0030033939003aull, 0xe700900993930099ull, 0x6b0070074e4e004bull, 0xa200d00de4e400e8ull,
     0x1f00100116160017ull, 0xd600b00bbcbc00b4ull, 0x5a00500561610066ull, 0x9300f00fcbcb00c5ull,
     0x310020022f2f002dull, 0xf80080088585008eull, 0x740060065858005cull, 0xbd00c00cf2f200ffull},
    {0x0000000000000000ull, 0x0a000b6d09a30009ull, 0x0400079e06710006ull, 0x0e000cf30fd2000full,
     0x030002a7033a0003ull, 0x090009ca0a99000aull, 0x07000539054b0005ull, 0x0d000e540ce8000cull,
     0x0100011a01170001ull, 0x0b000a7708b40008ull, 0x0500068407660007ull, 0x0f000de90ec5000eull,
     0x020003bd022d0002ull, 0x080008d00b8e000bull, 0x06000423045c0004ull, 0x0c000f4e0dff000dull},
    {0x0000000000000000ull, 0x00b6dba400a3aaaaull, 0x0079e7db00717777ull, 0x00cf3c7f00d2ddddull,
     0x002a7289003a3939ull, 0x009ca92d00999393ull, 0x00539552004b4e4eull, 0x00e54ef600e8e4e4ull,
     0x0011a10500171616ull, 0x00a77aa100b4bcbcull, 0x006846de00666161ull, 0x00de9d7a00c5cbcbull,
     0x003bd38c002d2f2full, 0x008d0828008e8585ull, 0x00423457005c5858ull, 0x00f4eff300fff2f2ull},
    {0x0000000000000000ull, 0x000c9bae000909a3ull, 0x000457df00060671ull, 0x0008cc71000f0fd2ull,
     0x0002e28a0003033aull, 0x000e7924000a0a99ull, 0x0006b5550005054bull, 0x000a2efb000c0ce8ull,
     0x0001f10400010117ull, 0x000d6aaa000808b4ull, 0x0005a6db00070766ull, 0x00093d75000e0ec5ull,
     0x0003138e0002022dull, 0x000f8820000b0b8eull, 0x000744510004045cull, 0x000bdfff000d0dffull},
    {0x0000000000000000ull, 0x0000a0c30000aa09ull, 0x0000404100007706ull, 0x0000e0820000dd0full,
     0x0000302d00003903ull, 0x000090ee0000930aull, 0x0000706c00004e05ull, 0x0000d0af0000e40cull,
     0x0000101e00001601ull, 0x0000b0dd0000bc08ull, 0x0000505f00006107ull, 0x0000f09c0000cb0eull,
     0x0000203300002f02ull, 0x000080f00000850bull, 0x0000607200005804ull, 0x0000c0b10000f20dull},
    {0x0000000000000000ull, 0x00000b67000009aaull, 0x0000079a00000677ull, 0x00000cfd00000fddull,
     0x000002a400000339ull, 0x000009c300000a93ull, 0x0000053e0000054eull, 0x00000e5900000ce4ull,
     0x0000011b00000116ull, 0x00000a7c000008bcull, 0x0000068100000761ull, 0x00000de600000ecbull,
     0x000003bf0000022full, 0x000008d800000b85ull, 0x0000042500000458ull, 0x00000f4200000df2ull},
    {0x0000000000000000ull, 0x000000c9000000a3ull, 0x0000004500000071ull, 0x0000008c000000d2ull,
     0x0000002e0000003aull, 0x000000e700000099ull, 0x0000006b0000004bull, 0x000000a2000000e8ull,
     0x0000001f00000017ull, 0x000000d6000000b4ull, 0x0000005a00000066ull, 0x00000093000000c5ull,
     0x000000310000002dull, 0x000000f80000008eull, 0x000000740000005cull, 0x000000bd000000ffull},
    {0x0000000000000000ull, 0x0000000a00000009ull, 0x0000000400000006ull, 0x0000000e0000000full,
     0x0000000300000003ull, 0x000000090000000aull, 0x0000000700000005ull, 0x0000000d0000000cull,
     0x0000000100000001ull, 0x0000000b00000008ull, 0x0000000500000007ull, 0x0000000f0000000eull,
     0x0000000200000002ull, 0x000000080000000bull, 0x0000000600000004ull, 0x0000000c0000000dull},
};

/* The next 2-D draw as the partner of slot `with`: Sobol dimensions 2 and 3 of that slot's shuffled
 * index (whose dimensions 0 and 1 are its own point), each with a nested uniform scramble of its own.
 * The two points together are then one 4-D Owen-scrambled Sobol point (Burley 2020 pads with blocks of
 * any dimension): the first 2^k samples of a pixel stratify the pair jointly, e.g. a vertex's light
 * point with the direction or distance that placed the vertex, which two independent slots do not.
 * The partner's own 2-D projection is a (t, k, 2)-net with t <= 2 rather than 0. With
 * MURK_SAMPLER_INDEPENDENT it is murk_sample_2d. Takes the next slot's place (the slot counter advances).
 * u[0] = u24(reverse(lk(reverse(sobol2(i)), lo32(g)))), u[1] the same of sobol3 with hi32(g), g a hash of
 * the slot's hash; both reversals of the result as one (murk_u24_pair_). */
static inline void murk_sample_2d_with(murk_rng *r, uint32_t with, float u[2])
{
    if (r->sampler != MURK_SAMPLER_SOBOL) {
        murk_sample_2d(r, u);
        return;
    }
    r->dim++;
    uint64_t h = murk_hash64(r->scramble + 0x9e3779b97f4a7c15ull * (uint64_t)(with + 1u)), x = 0u;
    uint32_t ri = murk_lk_hash_(r->rindex, (uint32_t)h); /* reverse(i), i the slot's shuffled index */
    for (int n = 0; n < 8; n++)
        x ^= murk_sobol23_[n][(ri >> (4 * n)) & 15u];
    uint64_t g = murk_hash64(h ^ 0xd1b54a32d192ed03ull);
    uint64_t ab = ((uint64_t)murk_lk_hash_((uint32_t)x, (uint32_t)g) << 32) |
                  murk_lk_hash_((uint32_t)(x >> 32), (uint32_t)(g >> 32));
    murk_u24_pair_(ab, u);
}
/* The next slot as one number in [0, 1). */
static inline float murk_sample_1d(murk_rng *r)
{
    uint32_t i;
    uint64_t h;
    return r->sampler != MURK_SAMPLER_SOBOL ? murk_rng_float(r) : murk_u24_(murk_sample_slot_(r, &i, &h));
}

#endif
