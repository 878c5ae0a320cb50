/* rayleigh — Rayleigh scattering by particles much smaller than the wavelength (Lord Rayleigh 1871;
 * unpolarised light, e.g. Chandrasekhar 1960, "Radiative Transfer", §17): p = 3 / (16 pi) (1 + cos^2
 * theta). Sampled exactly: the CDF of mu = cos theta, F(mu) = (mu^3 + 3 mu + 4) / 8, is inverted in
 * closed form (Cardano: mu = A - 1 / A, A = cbrt(w + sqrt(w^2 + 1)), w = 4 u - 2). The wavelength
 * dependence (sigma_s ~ lambda^-4) belongs to the medium's sigma_s, not here. No parameters. */
#include "murk/phase.h"

static int ray_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)host, (void)p, (void)err, (void)errlen;
    *self = NULL; /* no state */
    return 0;
}

static void ray_destroy(void *self) { (void)self; }

static float ray_eval(const void *self, murk_vec3 wo, murk_vec3 wi)
{
    (void)self;
    float mu = murk_dot(wo, wi); /* mu^2 is the same for cos theta = -dot(wo, wi) */
    return (3.0f / (16.0f * MURK_PI)) * (1.0f + mu * mu);
}

static float ray_sample(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    double w = 4.0 * (double)u[0] - 2.0, a = cbrt(fabs(w) + sqrt(w * w + 1.0));
    double mu = copysign(a - 1.0 / a, w); /* odd in w: the same accuracy on both sides */
    *wi = murk_phase_dir(wo, (float)-mu, u[1]);
    return *pdf = ray_eval(self, wo, *wi);
}

static double ray_mean_cosine(const void *self)
{
    (void)self;
    return 0.0;
}

static const murk_phase_vt vt = {sizeof(murk_phase_vt), MURK_KIND_PHASE, ray_create, ray_destroy, ray_eval, ray_sample,
                                 ray_mean_cosine};

MURK_PHASE_PLUGIN("rayleigh", "Rayleigh scattering, 3 / (16 pi) (1 + cos^2 theta)", NULL, 0, &vt)
