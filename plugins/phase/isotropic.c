/* isotropic — the isotropic phase function, p = 1 / (4 pi): every direction alike, sampled uniformly
 * over the sphere. No parameters. */
#include "murk/phase.h"

static int iso_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)host, (void)p, (void)err, (void)errlen;
    *self = NULL; /* no state */
    return 0;
}

static void iso_destroy(void *self) { (void)self; }

static float iso_eval(const void *self, murk_vec3 wo, murk_vec3 wi)
{
    (void)self, (void)wo, (void)wi;
    return 1.0f / (4.0f * MURK_PI);
}

static float iso_sample(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    (void)self;
    *wi = murk_phase_dir(wo, 1.0f - 2.0f * u[0], u[1]);
    return *pdf = 1.0f / (4.0f * MURK_PI);
}

static double iso_mean_cosine(const void *self)
{
    (void)self;
    return 0.0;
}

static const murk_phase_vt vt = {sizeof(murk_phase_vt), MURK_KIND_PHASE, iso_create, iso_destroy, iso_eval, iso_sample,
                                 iso_mean_cosine};

MURK_PHASE_PLUGIN("isotropic", "isotropic scattering, 1 / (4 pi)", NULL, 0, &vt)
