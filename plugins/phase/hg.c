/* hg — the Henyey-Greenstein phase function (Henyey and Greenstein 1941, "Diffuse radiation in the
 * galaxy", ApJ 93), p = (1 - g^2) / (4 pi (1 + g^2 - 2 g cos theta)^(3/2)), sampled exactly by inverting
 * its CDF. The same function as a medium's built-in default (its `g` key; murk/phase.h's murk_hg_eval
 * and murk_hg_sample): `phase: { type: hg, g: G }` renders the same bits as `g: G`. */
#include "murk/phase.h"

enum { P_G, P_COUNT };
static const murk_param params[P_COUNT] = {
    [P_G] = {"g", MURK_PARAM_FLOAT, 0, {0, 0, 0}, NULL, NULL, -0.99, 0.99,
             "the asymmetry, the mean cosine of the scattering angle: > 0 scatters forwards, < 0 backwards, 0 is "
             "isotropic"},
};

typedef struct hg {
    const murk_host *host;
    float g;
} hg;

static int hg_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err, (void)errlen;
    hg *h = host->alloc(sizeof *h);
    if (!h)
        return -1;
    h->host = host;
    h->g = (float)p[P_G].f[0];
    *self = h;
    return 0;
}

static void hg_destroy(void *self)
{
    hg *h = self;
    if (h)
        h->host->free(h);
}

static float hg_eval(const void *self, murk_vec3 wo, murk_vec3 wi) { return murk_hg_eval(((const hg *)self)->g, wo, wi); }

static float hg_sample(const void *self, murk_vec3 wo, const float u[2], murk_vec3 *wi, float *pdf)
{
    *wi = murk_hg_sample(((const hg *)self)->g, wo, u, pdf);
    return *pdf;
}

static double hg_mean_cosine(const void *self) { return ((const hg *)self)->g; }

static const murk_phase_vt vt = {sizeof(murk_phase_vt), MURK_KIND_PHASE, hg_create, hg_destroy, hg_eval, hg_sample,
                                 hg_mean_cosine};

MURK_PHASE_PLUGIN("hg", "Henyey-Greenstein (1941): one lobe of asymmetry g; every medium's default", params, P_COUNT,
                  &vt)
