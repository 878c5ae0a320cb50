/* draine — Draine's phase function (Draine 2003, "Scattering by interstellar dust grains. I. Optical and
 * ultraviolet", ApJ 598, eq. 4): Henyey-Greenstein of asymmetry g times (1 + alpha cos^2 theta),
 * normalised; alpha = 0 is HG, alpha = 1 with g = 0 Rayleigh's shape. Its mean cosine and the exact
 * sampler (CDF inversion) are in draine_math.h. The HG + Draine blend that fits Mie scattering by water
 * droplets is the `hg_draine` plugin. */
#include "murk/phase.h"

#include "draine_math.h"

enum { P_G, P_ALPHA, P_COUNT };
static const murk_param params[P_COUNT] = {
    [P_G] = {"g", MURK_PARAM_FLOAT, 0, {0, 0, 0}, NULL, NULL, -0.99, 0.99,
             "the asymmetry of the Henyey-Greenstein factor (the mean cosine is g only when alpha is 0: "
             "g (1 + alpha (3 + 2 g^2) / 5) / (1 + alpha (1 + 2 g^2) / 3))"},
    [P_ALPHA] = {"alpha", MURK_PARAM_FLOAT, 0, {1, 0, 0}, NULL, NULL, 0, 1000,
                 "the weight of cos^2 theta, which adds forward and backward scattering alike: 0 is "
                 "Henyey-Greenstein; Jendersie and d'Eon's water-droplet fits use 7 to 250"},
};

typedef struct draine {
    const murk_host *host;
    float g, alpha;
} draine;

static int draine_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err, (void)errlen;
    draine *d = host->alloc(sizeof *d);
    if (!d)
        return -1;
    d->host = host;
    d->g = (float)p[P_G].f[0];
    d->alpha = (float)p[P_ALPHA].f[0];
    *self = d;
    return 0;
}

static void draine_destroy(void *self)
{
    draine *d = self;
    if (d)
        d->host->free(d);
}

static float draine_eval(const void *self, murk_vec3 wo, murk_vec3 wi)
{
    const draine *d = self;
    return draine_eval_mu(d->g, d->alpha, -murk_dot(wo, wi));
}

static float draine_sample(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    const draine *d = self;
    double mu = draine_sample_mu(d->g, d->alpha, u[0]);
    *wi = murk_phase_dir(wo, (float)-mu, u[1]);
    return *pdf = draine_eval(self, wo, *wi);
}

static double draine_mean(const void *self)
{
    const draine *d = self;
    return draine_mean_cosine(d->g, d->alpha);
}

static const murk_phase_vt vt = {sizeof(murk_phase_vt), MURK_KIND_PHASE, draine_create, draine_destroy, draine_eval,
                                 draine_sample, draine_mean};

MURK_PHASE_PLUGIN("draine", "Draine (2003): Henyey-Greenstein times (1 + alpha cos^2 theta)", params, P_COUNT, &vt)
