/* sky.c — an analytic daylight sky: Preetham, Shirley and Smits 1999, "A Practical Analytic Model for
 * Daylight" (SIGGRAPH 99), tabulated once into a lat-long environment map, and the matching sun.
 *
 * Why Preetham and not Hosek and Wilkie 2012: the latter needs its fitted dataset tables, which Debian
 * does not package and murk may not download; Preetham's model is closed form (the Perez et al. 1993
 * luminance distribution with coefficients linear in the turbidity T, and polynomial zenith values).
 *
 * Sky: luminance Y and chromaticity x, y at view angle theta from the zenith and angle gamma from the sun
 * are zenith value x F(theta, gamma) / F(0, theta_s), F(theta, gamma) = (1 + A e^(B / cos theta))
 * (1 + C e^(D gamma) + E cos^2 gamma) (the paper's eq. 3 and Appendix A.2), converted xyY -> XYZ ->
 * linear Rec. 709 RGB (negative channels clamped to 0). Y is in kcd/m^2; murk's radiance unit is it over
 * the luminous efficacy 683 lm/W (x 1000 / 683), so a sky and the sun below share one scale. The model
 * covers the upper hemisphere: below the horizon the map is black (the ground is the scene's business).
 * Tabulated at MURK_SKY_W x MURK_SKY_H texels (0.7 degrees each), read bilinearly (envmap.h).
 *
 * Sun: the extraterrestrial solar illuminance 128 klx (over 683 lm/W: 187 W/m^2 in murk's unit) times
 * the transmittance of Rayleigh scattering and of aerosols (Angstrom's law, alpha = 1.3, beta = 0.04608 T
 * - 0.04586: the paper's Appendix A.3) at 650, 550 and 450 nm for R, G and B, along the relative air mass
 * of Kasten and Young 1989; ozone and water vapour are left out. The sun is a distant light of angular
 * diameter 0.53 degrees with that irradiance.
 *
 * Sun below the horizon: Preetham's model is for daylight only (its zenith luminance turns negative a
 * little below the horizon): the sky is black and there is no sun, and murk says so when it loads. */
#include "render/lights.h"
#include "render/envmap.h"
#include "util/util.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>

/* The Perez function F(theta, gamma) for coefficients c[5] = A..E. */
static double perez(const double c[5], double cos_theta, double gamma)
{
    double cg = cos(gamma);
    return (1.0 + c[0] * exp(c[1] / cos_theta)) * (1.0 + c[2] * exp(c[3] * gamma) + c[4] * cg * cg);
}

typedef struct preetham {
    double cY[5], cx[5], cy[5]; /* Perez coefficients of Y, x, y */
    double Yz, xz, yz;          /* zenith values */
    double theta_s;
    murk_vec3 sun;
} preetham;

static void preetham_init(preetham *p, double T, double theta_s, murk_vec3 sun)
{
    const double cY[5] = {0.1787 * T - 1.4630, -0.3554 * T + 0.4275, -0.0227 * T + 5.3251, 0.1206 * T - 2.5771,
                          -0.0670 * T + 0.3703};
    const double cx[5] = {-0.0193 * T - 0.2592, -0.0665 * T + 0.0008, -0.0004 * T + 0.2125, -0.0641 * T - 0.8989,
                          -0.0033 * T + 0.0452};
    const double cy[5] = {-0.0167 * T - 0.2608, -0.0950 * T + 0.0092, -0.0079 * T + 0.2102, -0.0441 * T - 1.6537,
                          -0.0109 * T + 0.0529};
    for (int k = 0; k < 5; k++)
        p->cY[k] = cY[k], p->cx[k] = cx[k], p->cy[k] = cy[k];
    double t = theta_s, t2 = t * t, t3 = t2 * t, chi = (4.0 / 9.0 - T / 120.0) * (M_PI - 2.0 * t);
    p->Yz = (4.0453 * T - 4.9710) * tan(chi) - 0.2155 * T + 2.4192;
    p->xz = T * T * (0.00166 * t3 - 0.00375 * t2 + 0.00209 * t) + T * (-0.02903 * t3 + 0.06377 * t2 - 0.03202 * t + 0.00394) +
            (0.11693 * t3 - 0.21196 * t2 + 0.06052 * t + 0.25886);
    p->yz = T * T * (0.00275 * t3 - 0.00610 * t2 + 0.00317 * t) + T * (-0.04214 * t3 + 0.08970 * t2 - 0.04153 * t + 0.00516) +
            (0.15346 * t3 - 0.26756 * t2 + 0.06670 * t + 0.26688);
    p->theta_s = theta_s;
    p->sun = sun;
}

/* Linear Rec. 709 radiance (murk's unit) of the sky towards unit direction d (y up). */
static void preetham_rgb(const preetham *p, murk_vec3 d, float out[3])
{
    out[0] = out[1] = out[2] = 0.0f;
    if (!(d.y > 0.0f))
        return; /* below the horizon: black */
    double ct = fmax((double)d.y, 1e-3), gamma = acos(fmin(1.0, fmax(-1.0, (double)murk_dot(d, p->sun))));
    double Y = p->Yz * perez(p->cY, ct, gamma) / perez(p->cY, 1.0, p->theta_s);
    double x = p->xz * perez(p->cx, ct, gamma) / perez(p->cx, 1.0, p->theta_s);
    double y = p->yz * perez(p->cy, ct, gamma) / perez(p->cy, 1.0, p->theta_s);
    if (!(Y > 0.0) || !(y > 0.0))
        return;
    Y *= 1000.0 / 683.0;
    double X = x * Y / y, Z = (1.0 - x - y) * Y / y;
    out[0] = (float)fmax(0.0, 3.2404542 * X - 1.5371385 * Y - 0.4985314 * Z);
    out[1] = (float)fmax(0.0, -0.9692660 * X + 1.8760108 * Y + 0.0415560 * Z);
    out[2] = (float)fmax(0.0, 0.0556434 * X - 0.2040259 * Y + 1.0572252 * Z);
}

murk_rgb murk_sky_sun_irradiance(double cos_theta_s, double turbidity)
{
    if (!(cos_theta_s > 0.0))
        return murk_rgb1(0.0f);
    double deg = acos(cos_theta_s) * 180.0 / M_PI;
    double m = 1.0 / (cos_theta_s + 0.50572 * pow(96.07995 - deg, -1.6364)); /* Kasten and Young 1989 */
    double beta = 0.04608 * turbidity - 0.04586;
    static const double lambda[3] = {0.650, 0.550, 0.450}; /* micrometres */
    murk_rgb E;
    for (int c = 0; c < 3; c++) {
        double tr = exp(-0.008735 * pow(lambda[c], -4.08) * m); /* Rayleigh */
        double ta = exp(-beta * pow(lambda[c], -1.3) * m);      /* aerosols */
        E.c[c] = (float)(128000.0 / 683.0 * tr * ta);
    }
    return E;
}

float *murk_sky_table(murk_vec3 sun_dir, double turbidity, int w, int h)
{
    murk_vec3 sun = murk_normalize(sun_dir);
    preetham p;
    preetham_init(&p, turbidity, acos(fmin(1.0, fmax(-1.0, (double)sun.y))), sun);
    float *rgb = murk_xmalloc(3 * (size_t)w * (size_t)h * sizeof *rgb);
    for (int j = 0; j < h; j++) {
        double theta = M_PI * (j + 0.5) / h;
        for (int i = 0; i < w; i++) {
            double phi = 2.0 * M_PI * ((i + 0.5) / w - 0.5); /* envmap.h's mapping, no rotation */
            murk_vec3 d = murk_v3((float)(sin(theta) * sin(phi)), (float)cos(theta), (float)(-sin(theta) * cos(phi)));
            preetham_rgb(&p, d, &rgb[3 * ((size_t)j * (size_t)w + (size_t)i)]);
        }
    }
    return rgb;
}
