/* ggx — a Lambertian base under a GGX microfacet specular coat (reflection only).
 *
 * Parameters
 *   albedo     RGB in [0,1], default 0.5, texturable. Reflectance of the diffuse base: with specular 0
 *              the material is exactly Lambertian with f = albedo / pi.
 *   specular   RGB in [0,1], default 0.04, texturable. F0, the normal-incidence reflectance of the coat
 *              in Schlick's Fresnel F(c) = F0 + (1 - F0)(1 - c)^5 (0.04 ~ plastics and glass, 1 = a
 *              perfect mirror coat: no light reaches the base).
 *   roughness  float in [0,1], default 0.5, texturable. Perceptual roughness; the GGX width is
 *              alpha = roughness^2.
 *   alpha      float in [0,1], optional, texturable. The GGX width itself; when the scene gives it, it
 *              overrides roughness (alpha = value, not squared). Giving both is allowed: alpha wins and
 *              create() logs a warning.
 *   The effective alpha is clamped to [0.001, 1]: roughness 0 (or alpha 0) is a very sharp but finite
 *   GGX lobe, never a delta lobe, so eval/pdf/sample stay one smooth, MIS-able distribution.
 *
 * Model (local shading frame, n = +z, mu = cos theta):
 *   f = f_spec + f_diff
 *   f_spec(wo,wi) = F(wo.h) D(h) V(mu_o, mu_i),  h = normalize(wo + wi)
 *     D  GGX / Trowbridge-Reitz NDF (Walter et al. 2007): alpha^2 / (pi (alpha^2 h.z^2 + h.x^2 + h.y^2)^2)
 *     V  height-correlated Smith (Heitz 2014) G2 / (4 mu_o mu_i) = 0.5 / (mu_i R(mu_o) + mu_o R(mu_i)),
 *        R(mu) = sqrt(mu^2 (1 - alpha^2) + alpha^2)
 *   f_diff(wo,wi) = albedo (1 - F0) / pi * (1 - M(mu_o)) (1 - M(mu_i)) / (1 - Mavg)
 *
 * Energy conservation (the weighting of the diffuse lobe). Let
 *   E_F(wo) = integral over visible microfacet normals of F(wo.h) D_wo(h) dh = F0 + (1 - F0) M(mu_o),
 *   M(mu) = integral of (1 - wo.h)^5 D_wo(h) dh,   D_wo = G1(wo) max(0, wo.h) D(h) / mu_o (the VNDF),
 * the fraction of the light arriving from wo that the coat's microfacets reflect (Fresnel-weighted).
 * Because the height-correlated G2 <= G1(wo), the specular lobe's directional albedo
 * E_spec(wo) = integral of f_spec cos <= E_F(wo). The diffuse lobe above is a Kelemen & Szirmay-Kalos
 * (2001) style separable, symmetric (hence reciprocal) lobe whose normalisation
 * Mavg = integral of M(mu) 2 mu dmu makes its directional albedo exactly albedo (1 - E_F(wo)). So
 *   E(wo) = E_spec(wo) + albedo (1 - E_F(wo)) <= E_F(wo) + 1 - E_F(wo) = 1
 * for every albedo, specular and roughness; with albedo 1 the only loss is the coat's
 * single-scattering shortfall E_F - E_spec (no multiple-scattering compensation). f is symmetric in
 * (wo, wi) term by term, so reciprocal. M has no closed form: it is tabulated below over
 * (t = sqrt(mu), r = sqrt(alpha)) and read bilinearly; every table entry carries a local safety margin
 * so that the interpolated M is never below the true M (checked densely by the generator), which keeps
 * the bound E <= 1 rigorous. Mavg is integrated exactly from that same interpolant. To regenerate, run
 *     cc -O2 -DMURK_GGX_GENERATE_TABLES -I core/include plugins/materials/ggx.c -lm -o ggxgen && ./ggxgen
 * (about 10 s) and paste its output over the BEGIN..END GENERATED TABLES block.
 *
 * Sampling: with probability P_spec the coat (visible-normal sampling of GGX with the spherical-cap
 * method of Dupuy & Benyoub 2023, then mirror reflection), otherwise the base (cosine-weighted
 * hemisphere). P_spec = lum(E_F(wo)) / (lum(E_F(wo)) + lum(albedo (1 - E_F(wo)))), the lobes'
 * expected contributions, clamped to [0.05, 0.95] when both lobes are non-zero (exactly 1 when the base
 * is black, 0 when the coat is). pdf() is the exact mixture P_spec pdf_spec + (1 - P_spec) pdf_diff with
 * pdf_spec = D(h) G1(wo) / (4 mu_o); coat samples that reflect below the horizon are rejected (sample()
 * returns 0), so pdf() integrates to 1 minus that rejected mass.
 *
 * Robustness: wo.z or wi.z below 1e-9 (the horizon, below it, NaN) gives f = 0 and pdf = 0; sample()
 * returns 0 there and for rejected or zero-pdf samples. No formula divides by mu or tan theta alone, so
 * grazing directions (wo.z = 1e-7) stay finite, and with alpha >= 0.001 every output is bounded. */
#include "murk/material.h"

#include <string.h>

enum { P_ALBEDO, P_SPECULAR, P_ROUGHNESS, P_ALPHA, P_COUNT };

static const murk_param params[P_COUNT] = {
    [P_ALBEDO] = {"albedo", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.5, 0.5, 0.5}, NULL, NULL, 0.0, 1.0,
                  "reflectance of the diffuse base (Lambertian under the coat)"},
    [P_SPECULAR] = {"specular", MURK_PARAM_RGB, MURK_PARAM_TEXTURABLE, {0.04, 0.04, 0.04}, NULL, NULL, 0.0, 1.0,
                    "normal-incidence reflectance F0 of the coat (Schlick Fresnel)"},
    [P_ROUGHNESS] = {"roughness", MURK_PARAM_FLOAT, MURK_PARAM_TEXTURABLE, {0.5, 0, 0}, NULL, NULL, 0.0, 1.0,
                     "perceptual roughness; GGX alpha = roughness^2 (clamped to >= 0.001)"},
    [P_ALPHA] = {"alpha", MURK_PARAM_FLOAT, MURK_PARAM_TEXTURABLE, {0.0, 0, 0}, NULL, NULL, 0.0, 1.0,
                 "GGX alpha directly; if given it overrides roughness (clamped to >= 0.001)"},
};

#define GGX_ALPHA_MIN 1e-3f
/* Cosines below this count as the horizon: it bounds f <= 0.5 D_max / (2 GGX_MU_MIN GGX_ALPHA_MIN) ~ 1e17
 * and pdf <= D_max / (2 GGX_ALPHA_MIN) ~ 2e8, so nothing overflows even for subnormal cosines. */
#define GGX_MU_MIN 1e-9f
#define GGX_PSPEC_MIN 0.05f
#define GGX_PSPEC_MAX 0.95f

/* ---- Tables --------------------------------------------------------------------------------------
 * ggx_m[j][i] = M(mu = t_i^2, alpha = max(r_j^2, GGX_ALPHA_MIN)) + safety margin, t_i = i / (N - 1),
 * r_j = j / (N - 1); ggx_mavg[j] = exact integral of the (piecewise linear in mu) interpolant times
 * 2 mu over [0, 1]. Generated by the MURK_GGX_GENERATE_TABLES program at the end of this file. */
#define GGX_TAB_N 32
/* BEGIN GENERATED TABLES */
/* generated by MURK_GGX_GENERATE_TABLES: quadrature error 3.3e-05, largest margin 0.0093 */
static const float ggx_m[GGX_TAB_N][GGX_TAB_N] = {
    {9.73773837e-01f, 9.86091733e-01f, 9.79039252e-01f, 9.54076886e-01f, 9.19895053e-01f, 8.77114475e-01f,
     8.26839089e-01f, 7.70330489e-01f, 7.08956838e-01f, 6.44159198e-01f, 5.77411115e-01f, 5.10203004e-01f,
     4.44087505e-01f, 3.80191743e-01f, 3.19670290e-01f, 2.63513982e-01f, 2.12511465e-01f, 1.67228460e-01f,
     1.27995878e-01f, 9.49080884e-02f, 6.78315163e-02f, 4.64240350e-02f, 3.01646721e-02f, 1.83928218e-02f,
     1.03553850e-02f, 5.25957346e-03f, 2.32826988e-03f, 8.53887701e-04f, 2.45634728e-04f, 6.39476639e-05f,
     3.45941771e-05f, 3.35616787e-05f},
    {9.75347281e-01f, 9.90567505e-01f, 9.83962059e-01f, 9.60262001e-01f, 9.23941374e-01f, 8.79695058e-01f,
     8.28564286e-01f, 7.71528006e-01f, 7.09807932e-01f, 6.44771457e-01f, 5.77853203e-01f, 5.10549843e-01f,
     4.44276243e-01f, 3.80244106e-01f, 3.19668323e-01f, 2.63512820e-01f, 2.12510884e-01f, 1.67228252e-01f,
     1.27995923e-01f, 9.49082747e-02f, 6.78317621e-02f, 4.64242883e-02f, 3.01648993e-02f, 1.83930080e-02f,
     1.03555219e-02f, 5.25966380e-03f, 2.32832250e-03f, 8.53913487e-04f, 2.45644449e-04f, 6.39499631e-05f,
     3.45943627e-05f, 3.35616787e-05f},
    {9.18897271e-01f, 9.34369206e-01f, 9.47053254e-01f, 9.39074457e-01f, 9.12322044e-01f, 8.72970641e-01f,
     8.24206054e-01f, 7.68543899e-01f, 7.07714498e-01f, 6.43291414e-01f, 5.76810300e-01f, 5.09826303e-01f,
     4.43786800e-01f, 3.79925728e-01f, 3.19418609e-01f, 2.63317019e-01f, 2.12409079e-01f, 1.67191103e-01f,
     1.28000662e-01f, 9.49375331e-02f, 6.78726807e-02f, 4.64677550e-02f, 3.02049480e-02f, 1.84262507e-02f,
     1.03806239e-02f, 5.27681597e-03f, 2.33873888e-03f, 8.59339663e-04f, 2.47914315e-04f, 6.46179687e-05f,
     3.46953784e-05f, 3.35627592e-05f},
    {8.46800745e-01f, 8.56934965e-01f, 8.76494408e-01f, 8.85048032e-01f, 8.75478089e-01f, 8.47304106e-01f,
     8.06604326e-01f, 7.56178796e-01f, 6.98863387e-01f, 6.36911273e-01f, 5.72222590e-01f, 5.06532490e-01f,
     4.41481829e-01f, 3.78367633e-01f, 3.18414301e-01f, 2.62665242e-01f, 2.12029874e-01f, 1.67035401e-01f,
     1.27992675e-01f, 9.50189978e-02f, 6.79999292e-02f, 4.66094092e-02f, 3.03399395e-02f, 1.85420159e-02f,
     1.04714157e-02f, 5.34205744e-03f, 2.38140323e-03f, 8.84398120e-04f, 2.60908360e-04f, 7.04701743e-05f,
     3.69143236e-05f, 3.40505649e-05f},
    {7.72316396e-01f, 7.78052270e-01f, 7.93995202e-01f, 8.09649467e-01f, 8.13039839e-01f, 8.00235450e-01f,
     7.71381974e-01f, 7.29894638e-01f, 6.79548442e-01f, 6.22724533e-01f, 5.61857522e-01f, 4.99022454e-01f,
     4.36111152e-01f, 3.74672681e-01f, 3.15980196e-01f, 2.61166781e-01f, 2.11137176e-01f, 1.66639447e-01f,
     1.27930060e-01f, 9.51626599e-02f, 6.82536364e-02f, 4.69031818e-02f, 3.06261033e-02f, 1.87915452e-02f,
     1.06703695e-02f, 5.48803993e-03f, 2.48004170e-03f, 9.45901731e-04f, 2.96868442e-04f, 9.11492098e-05f,
     4.93681291e-05f, 4.15397844e-05f},
    {6.97886229e-01f, 7.01714098e-01f, 7.12752581e-01f, 7.27204442e-01f, 7.37040877e-01f, 7.35115409e-01f,
     7.19043493e-01f, 6.89280629e-01f, 6.48253262e-01f, 5.98913491e-01f, 5.44108331e-01f, 4.85989302e-01f,
     4.26661342e-01f, 3.68035913e-01f, 3.11524779e-01f, 2.58354962e-01f, 2.09527567e-01f, 1.65845394e-01f,
     1.27735198e-01f, 9.53478068e-02f, 6.86504468e-02f, 4.73873392e-02f, 3.11111789e-02f, 1.92232039e-02f,
     1.10206269e-02f, 5.74948173e-03f, 2.65997811e-03f, 1.06059364e-03f, 3.66077729e-04f, 1.33422116e-04f,
     7.86214878e-05f, 6.57098790e-05f},
    {6.25817716e-01f, 6.28588736e-01f, 6.36231303e-01f, 6.47643626e-01f, 6.57818556e-01f, 6.61784291e-01f,
     6.55041099e-01f, 6.36150479e-01f, 6.05747759e-01f, 5.65706551e-01f, 5.18530488e-01f, 4.66725171e-01f,
     4.12536353e-01f, 3.57882261e-01f, 3.04575115e-01f, 2.53863752e-01f, 2.06878319e-01f, 1.64477587e-01f,
     1.27300933e-01f, 9.55204293e-02f, 6.91751987e-02f, 4.80729155e-02f, 3.18218581e-02f, 1.98710319e-02f,
     1.15574738e-02f, 6.15880825e-03f, 2.94837332e-03f, 1.24930241e-03f, 4.82948584e-04f, 2.05954217e-04f,
     1.29156630e-04f, 1.10546949e-04f},
    {5.57856679e-01f, 5.59856534e-01f, 5.65464377e-01f, 5.73706150e-01f, 5.82521260e-01f, 5.87955356e-01f,
     5.86605012e-01f, 5.75873017e-01f, 5.54874957e-01f, 5.24341941e-01f, 4.85841215e-01f, 4.41518694e-01f,
     3.93558234e-01f, 3.44074517e-01f, 2.94857889e-01f, 2.47427344e-01f, 2.02953249e-01f, 1.62396356e-01f,
     1.26501292e-01f, 9.55982059e-02f, 6.97822422e-02f, 4.89428937e-02f, 3.27616557e-02f, 2.07516812e-02f,
     1.23044532e-02f, 6.74161268e-03f, 3.36951693e-03f, 1.53306697e-03f, 6.64470077e-04f, 3.21605796e-04f,
     2.09893493e-04f, 1.82785428e-04f},
    {4.95003372e-01f, 4.96437699e-01f, 5.00498295e-01f, 5.06409466e-01f, 5.13232946e-01f, 5.18511772e-01f,
     5.19485891e-01f, 5.13769567e-01f, 4.99991328e-01f, 4.77704316e-01f, 4.47658628e-01f, 4.11233515e-01f,
     3.70280832e-01f, 3.26704830e-01f, 2.82393366e-01f, 2.38936737e-01f, 1.97598219e-01f, 1.59420684e-01f,
     1.25206798e-01f, 9.54793245e-02f, 7.03996643e-02f, 4.99533005e-02f, 3.39101851e-02f, 2.18628813e-02f,
     1.32716931e-02f, 7.51514034e-03f, 3.94337485e-03f, 1.93135941e-03f, 9.27739311e-04f, 4.94510750e-04f,
     3.32296506e-04f, 2.92271347e-04f},
    {4.37738389e-01f, 4.38756883e-01f, 4.41655815e-01f, 4.45939034e-01f, 4.50822115e-01f, 4.55154538e-01f,
     4.56870854e-01f, 4.54028279e-01f, 4.45033193e-01f, 4.29143310e-01f, 4.06383157e-01f, 3.77441138e-01f,
     3.43555003e-01f, 3.06329608e-01f, 2.67404616e-01f, 2.28464305e-01f, 1.90767810e-01f, 1.55433714e-01f,
     1.23308279e-01f, 9.50556695e-02f, 7.09377974e-02f, 5.10379486e-02f, 3.52251157e-02f, 2.31834929e-02f,
     1.44548975e-02f, 8.48689768e-03f, 4.68433136e-03f, 2.46122968e-03f, 1.28940050e-03f, 7.39259296e-04f,
     5.08809753e-04f, 4.50502324e-04f},
    {3.86180907e-01f, 3.86893660e-01f, 3.88927400e-01f, 3.91953766e-01f, 3.95383298e-01f, 3.98551941e-01f,
     4.00154352e-01f, 3.98706883e-01f, 3.92848909e-01f, 3.81581217e-01f, 3.64588916e-01f, 3.42013687e-01f,
     3.14701349e-01f, 2.83708751e-01f, 2.50407666e-01f, 2.16214806e-01f, 1.82543188e-01f, 1.50403306e-01f,
     1.20735437e-01f, 9.42278504e-02f, 7.13003576e-02f, 5.21159023e-02f, 3.66464667e-02f, 2.46753898e-02f,
     1.58355422e-02f, 9.65387188e-03f, 5.60002448e-03f, 3.13622179e-03f, 1.76496082e-03f, 1.07068091e-03f,
     7.52647291e-04f, 6.70331414e-04f},
    {3.40204775e-01f, 3.40693146e-01f, 3.42086792e-01f, 3.44162524e-01f, 3.46523523e-01f, 3.48617941e-01f,
     3.49788070e-01f, 3.48889053e-01f, 3.44871819e-01f, 3.36822957e-01f, 3.24173540e-01f, 3.06861907e-01f,
     2.85153925e-01f, 2.59856790e-01f, 2.31976300e-01f, 2.02640995e-01f, 1.73088700e-01f, 1.44392729e-01f,
     1.17425434e-01f, 9.29195732e-02f, 7.13966638e-02f, 5.31006604e-02f, 3.81027311e-02f, 2.62869000e-02f,
     1.73822585e-02f, 1.10025164e-02f, 6.69056736e-03f, 3.96535173e-03f, 2.36790115e-03f, 1.50332868e-03f,
     1.07767025e-03f, 9.65879008e-04f},
    {2.99524218e-01f, 2.99848616e-01f, 3.00771892e-01f, 3.02139312e-01f, 3.03678215e-01f, 3.04982185e-01f,
     3.05610389e-01f, 3.04845989e-01f, 3.01867545e-01f, 2.95932442e-01f, 2.86461741e-01f, 2.73195356e-01f,
     2.56197214e-01f, 2.35843286e-01f, 2.12854236e-01f, 1.88165516e-01f, 1.62699580e-01f, 1.37516126e-01f,
     1.13402791e-01f, 9.10947621e-02f, 7.11529180e-02f, 5.39096892e-02f, 3.95179614e-02f, 2.79573966e-02f,
     1.90532524e-02f, 1.25095351e-02f, 7.94827938e-03f, 4.95232921e-03f, 3.10882204e-03f, 2.05083215e-03f,
     1.49810163e-03f, 1.35243137e-03f},
    {2.63757348e-01f, 2.63962567e-01f, 2.64542937e-01f, 2.65389502e-01f, 2.66311914e-01f, 2.67028302e-01f,
     2.67172337e-01f, 2.66369194e-01f, 2.63970286e-01f, 2.59407490e-01f, 2.52182186e-01f, 2.41959020e-01f,
     2.28683695e-01f, 2.12494835e-01f, 1.93817943e-01f, 1.73312649e-01f, 1.51757151e-01f, 1.29970983e-01f,
     1.08750902e-01f, 8.87454897e-02f, 7.05208406e-02f, 5.44731393e-02f, 4.08190563e-02f, 2.96225604e-02f,
     2.07995307e-02f, 1.41433896e-02f, 9.35795810e-03f, 6.09510625e-03f, 3.99472145e-03f, 2.72524077e-03f,
     2.02813419e-03f, 1.84630428e-03f},
    {2.32472315e-01f, 2.32591644e-01f, 2.32924357e-01f, 2.33392984e-01f, 2.33862966e-01f, 2.34136581e-01f,
     2.33948246e-01f, 2.33017325e-01f, 2.30949685e-01f, 2.27287695e-01f, 2.21633360e-01f, 2.13674605e-01f,
     2.03255653e-01f, 1.90428942e-01f, 1.75394744e-01f, 1.58577949e-01f, 1.40567824e-01f, 1.22013107e-01f,
     1.03590839e-01f, 8.59084353e-02f, 6.94828033e-02f, 5.47405183e-02f, 4.19423133e-02f, 3.12197283e-02f,
     2.25686282e-02f, 1.58664230e-02f, 1.08976932e-02f, 7.38580246e-03f, 5.02846949e-03f, 3.53641622e-03f,
     2.68148957e-03f, 2.46466789e-03f},
    {2.05220476e-01f, 2.05278531e-01f, 2.05434516e-01f, 2.05632910e-01f, 2.05777869e-01f, 2.05729514e-01f,
     2.05300689e-01f, 2.04258263e-01f, 2.02394456e-01f, 1.99342012e-01f, 1.94796905e-01f, 1.88497081e-01f,
     1.80267632e-01f, 1.70079008e-01f, 1.58028007e-01f, 1.44358724e-01f, 1.29471287e-01f, 1.13867499e-01f,
     9.80745405e-02f, 8.26562792e-02f, 6.80581778e-02f, 5.46846166e-02f, 4.28385623e-02f, 3.26927975e-02f,
     2.43084654e-02f, 1.76373944e-02f, 1.25401421e-02f, 8.81101191e-03f, 6.20851899e-03f, 4.49151685e-03f,
     3.47097032e-03f, 3.22533748e-03f},
    {1.81559041e-01f, 1.81574002e-01f, 1.81605771e-01f, 1.81614414e-01f, 1.81531355e-01f, 1.81257114e-01f,
     1.80659220e-01f, 1.79571986e-01f, 1.77823499e-01f, 1.75202712e-01f, 1.71456993e-01f, 1.66378826e-01f,
     1.59809709e-01f, 1.51671648e-01f, 1.42012328e-01f, 1.30951166e-01f, 1.18742608e-01f, 1.05748564e-01f,
     9.23845768e-02f, 7.90881589e-02f, 6.62786514e-02f, 5.43055981e-02f, 4.34762947e-02f, 3.39961275e-02f,
     2.59709638e-02f, 1.94142032e-02f, 1.42541854e-02f, 1.03524774e-02f, 7.52887549e-03f, 5.59460465e-03f,
     4.40802425e-03f, 4.14653029e-03f},
    {1.61066011e-01f, 1.61051244e-01f, 1.60997495e-01f, 1.60876006e-01f, 1.60637692e-01f, 1.60211638e-01f,
     1.59503907e-01f, 1.58397257e-01f, 1.56752914e-01f, 1.54450461e-01f, 1.51296929e-01f, 1.47129938e-01f,
     1.41817763e-01f, 1.35277122e-01f, 1.27501145e-01f, 1.18560299e-01f, 1.08600311e-01f, 9.78609249e-02f,
     8.66550803e-02f, 7.53118694e-02f, 6.42025396e-02f, 5.36223426e-02f, 4.38455455e-02f, 3.50971110e-02f,
     2.75150500e-02f, 2.11565439e-02f, 1.60067938e-02f, 1.19880764e-02f, 8.97933636e-03f, 6.84640883e-03f,
     5.50234877e-03f, 5.24659595e-03f},
    {1.43349364e-01f, 1.43314630e-01f, 1.43203661e-01f, 1.42995819e-01f, 1.42656028e-01f, 1.42133892e-01f,
     1.41362876e-01f, 1.40260145e-01f, 1.38727576e-01f, 1.36663690e-01f, 1.33962572e-01f, 1.30487174e-01f,
     1.26133725e-01f, 1.20826960e-01f, 1.14535339e-01f, 1.07294835e-01f, 9.91850197e-02f, 9.03566405e-02f,
     8.10270831e-02f, 7.14529306e-02f, 6.19087890e-02f, 5.26634529e-02f, 4.39514145e-02f, 3.59807834e-02f,
     2.89088134e-02f, 2.28282362e-02f, 1.77649483e-02f, 1.36930337e-02f, 1.05459671e-02f, 8.24425090e-03f,
     6.76155277e-03f, 6.54372992e-03f},
    {1.28051668e-01f, 1.28004059e-01f, 1.27856418e-01f, 1.27594054e-01f, 1.27192095e-01f, 1.26614898e-01f,
     1.25815645e-01f, 1.24736145e-01f, 1.23307437e-01f, 1.21451549e-01f, 1.19100332e-01f, 1.16160311e-01f,
     1.12546392e-01f, 1.08196214e-01f, 1.03074372e-01f, 9.71850976e-02f, 9.05789137e-02f, 8.33430290e-02f,
     7.56188557e-02f, 6.75947741e-02f, 5.94733171e-02f, 5.14793880e-02f, 4.38075177e-02f, 3.66404057e-02f,
     3.01342923e-02f, 2.43990496e-02f, 1.94974300e-02f, 1.54412435e-02f, 1.22117884e-02f, 9.78214480e-03f,
     8.19089916e-03f, 8.05567019e-03f},
    {1.14851952e-01f, 1.14796579e-01f, 1.14627048e-01f, 1.14333056e-01f, 1.13897182e-01f, 1.13294542e-01f,
     1.12492524e-01f, 1.11450695e-01f, 1.10121123e-01f, 1.08449437e-01f, 1.06377967e-01f, 1.03860743e-01f,
     1.00824907e-01f, 9.72216874e-02f, 9.30185169e-02f, 8.82062837e-02f, 8.28104317e-02f, 7.68836662e-02f,
     7.05133528e-02f, 6.38261437e-02f, 5.69743738e-02f, 5.01271598e-02f, 4.34435941e-02f, 3.70810442e-02f,
     3.11786141e-02f, 2.58487668e-02f, 2.11763587e-02f, 1.72066092e-02f, 1.39576057e-02f, 1.14510506e-02f,
     9.79313161e-03f, 9.79940128e-03f},
    {1.03465296e-01f, 1.03405774e-01f, 1.03224874e-01f, 1.02915503e-01f, 1.02465719e-01f, 1.01858497e-01f,
     1.01071544e-01f, 1.00077271e-01f, 9.88429636e-02f, 9.73313600e-02f, 9.55018997e-02f, 9.33174789e-02f,
     9.07399133e-02f, 8.77253488e-02f, 8.42468441e-02f, 8.02918896e-02f, 7.58673921e-02f, 7.10082054e-02f,
     6.57646507e-02f, 6.02172427e-02f, 5.44750057e-02f, 4.86603528e-02f, 4.28995863e-02f, 3.73181514e-02f,
     3.20358798e-02f, 2.71618646e-02f, 2.27793418e-02f, 1.89642757e-02f, 1.57629102e-02f, 1.32392701e-02f,
     1.15684001e-02f, 1.17908604e-02f},
    {9.36411470e-02f, 9.35800225e-02f, 9.33950990e-02f, 9.30816904e-02f, 9.26318616e-02f, 9.20343548e-02f,
     9.12744105e-02f, 9.03337449e-02f, 8.91906694e-02f, 8.78203735e-02f, 8.61956626e-02f, 8.42880979e-02f,
     8.20757151e-02f, 7.95298368e-02f, 7.66266510e-02f, 7.33541250e-02f, 6.97122142e-02f, 6.57171309e-02f,
     6.14027008e-02f, 5.68169579e-02f, 5.20302653e-02f, 4.71307859e-02f, 4.22150753e-02f, 3.73758972e-02f,
     3.27150151e-02f, 2.83253435e-02f, 2.42918357e-02f, 2.06916817e-02f, 1.76068041e-02f, 1.51329413e-02f,
     1.35142831e-02f, 1.40446685e-02f},
    {8.51607993e-02f, 8.50998312e-02f, 8.49159434e-02f, 8.46062154e-02f, 8.41657072e-02f, 8.35873485e-02f,
     8.28619078e-02f, 8.19778815e-02f, 8.09215531e-02f, 7.96771646e-02f, 7.82273188e-02f, 7.65535682e-02f,
     7.46374652e-02f, 7.24676549e-02f, 7.00247437e-02f, 6.72978908e-02f, 6.42844811e-02f, 6.09912612e-02f,
     5.74378148e-02f, 5.36546037e-02f, 4.96838726e-02f, 4.55844924e-02f, 4.14305739e-02f, 3.72847356e-02f,
     3.32280919e-02f, 2.93383673e-02f, 2.56945770e-02f, 2.23722216e-02f, 1.94688607e-02f, 1.71166118e-02f,
     1.56258959e-02f, 1.65738892e-02f},
    {7.78345317e-02f, 7.77748823e-02f, 7.75954053e-02f, 7.72944689e-02f, 7.68693313e-02f, 7.63160363e-02f,
     7.56293461e-02f, 7.48026967e-02f, 7.38281831e-02f, 7.26966113e-02f, 7.13977069e-02f, 6.99204281e-02f,
     6.82535321e-02f, 6.63863122e-02f, 6.43143728e-02f, 6.20263889e-02f, 5.95191941e-02f, 5.67955002e-02f,
     5.38649634e-02f, 5.07468395e-02f, 4.74671312e-02f, 4.40614298e-02f, 4.05814797e-02f, 3.70733589e-02f,
     3.35938446e-02f, 3.02068815e-02f, 2.69803666e-02f, 2.39880215e-02f, 2.13298909e-02f, 1.91738345e-02f,
     1.78960804e-02f, 1.93898175e-02f},
    {7.14985132e-02f, 7.14409426e-02f, 7.12680295e-02f, 7.09791034e-02f, 7.05730319e-02f, 7.00481236e-02f,
     6.94020912e-02f, 6.86319545e-02f, 6.77340031e-02f, 6.67038187e-02f, 6.55362904e-02f, 6.42258227e-02f,
     6.27665520e-02f, 6.11527711e-02f, 5.93794659e-02f, 5.74463941e-02f, 5.53487614e-02f, 5.30873165e-02f,
     5.06672896e-02f, 4.80988100e-02f, 4.53988910e-02f, 4.25889343e-02f, 3.97006162e-02f, 3.67702991e-02f,
     3.38328443e-02f, 3.09398286e-02f, 2.81469878e-02f, 2.55245976e-02f, 2.31725574e-02f, 2.12877616e-02f,
     2.03156658e-02f, 2.25018244e-02f},
    {6.60118088e-02f, 6.59567788e-02f, 6.57917112e-02f, 6.55166581e-02f, 6.51316643e-02f, 6.46366924e-02f,
     6.40315935e-02f, 6.33159801e-02f, 6.24891892e-02f, 6.15502372e-02f, 6.04977868e-02f, 5.93301877e-02f,
     5.80455810e-02f, 5.66420779e-02f, 5.51180094e-02f, 5.34722805e-02f, 5.17068245e-02f, 4.98218648e-02f,
     4.78196703e-02f, 4.57062609e-02f, 4.34909873e-02f, 4.11880910e-02f, 3.88160385e-02f, 3.64018306e-02f,
     3.39673385e-02f, 3.15503776e-02f, 2.91974228e-02f, 2.69738939e-02f, 2.49819458e-02f, 2.34417114e-02f,
     2.28737723e-02f, 2.59172283e-02f},
    {6.12535253e-02f, 6.12012818e-02f, 6.10447451e-02f, 6.07844777e-02f, 6.04213849e-02f, 5.99566437e-02f,
     5.93916327e-02f, 5.87278530e-02f, 5.79668358e-02f, 5.71100563e-02f, 5.61588965e-02f, 5.51145785e-02f,
     5.39781861e-02f, 5.27507104e-02f, 5.14331385e-02f, 5.00265993e-02f, 4.85325940e-02f, 4.69538607e-02f,
     4.52945456e-02f, 4.35570627e-02f, 4.17474471e-02f, 3.98740098e-02f, 3.79488468e-02f, 3.59920189e-02f,
     3.40172611e-02f, 3.20517980e-02f, 3.01363543e-02f, 2.83324886e-02f, 2.67453399e-02f, 2.56196540e-02f,
     2.55581494e-02f, 2.96412241e-02f},
    {5.71202077e-02f, 5.70708476e-02f, 5.69230840e-02f, 5.66778593e-02f, 5.63366897e-02f, 5.59016243e-02f,
     5.53751513e-02f, 5.47601096e-02f, 5.40595911e-02f, 5.32768518e-02f, 5.24151996e-02f, 5.14779389e-02f,
     5.04683033e-02f, 4.93894331e-02f, 4.82443795e-02f, 4.70361337e-02f, 4.57677320e-02f, 4.44423556e-02f,
     4.30635400e-02f, 4.16364037e-02f, 4.01654169e-02f, 3.86558548e-02f, 3.71156633e-02f, 3.55609991e-02f,
     3.40021290e-02f, 3.24596018e-02f, 3.09721678e-02f, 2.95986459e-02f, 2.84530595e-02f, 2.78066341e-02f,
     2.83555295e-02f, 3.36768590e-02f},
    {5.35234176e-02f, 5.34769371e-02f, 5.33379093e-02f, 5.31075336e-02f, 5.27877733e-02f, 5.23812920e-02f,
     5.18913567e-02f, 5.13217635e-02f, 5.06767072e-02f, 4.99606915e-02f, 4.91784029e-02f, 4.83346283e-02f,
     4.74341586e-02f, 4.64817323e-02f, 4.54819836e-02f, 4.44394238e-02f, 4.33584824e-02f, 4.22435217e-02f,
     4.10989784e-02f, 3.99294905e-02f, 3.87401618e-02f, 3.75370272e-02f, 3.63276899e-02f, 3.51252966e-02f,
     3.39395814e-02f, 3.27895805e-02f, 3.17133404e-02f, 3.07734236e-02f, 3.00979000e-02f, 2.99890805e-02f,
     3.12519856e-02f, 3.80250402e-02f},
    {5.03876582e-02f, 5.03439903e-02f, 5.02134599e-02f, 4.99974526e-02f, 4.96982411e-02f, 4.93189134e-02f,
     4.88632917e-02f, 4.83358204e-02f, 4.77414690e-02f, 4.70856093e-02f, 4.63738963e-02f, 4.56121564e-02f,
     4.48063090e-02f, 4.39622551e-02f, 4.30858396e-02f, 4.21828032e-02f, 4.12587821e-02f, 4.03193235e-02f,
     3.93699780e-02f, 3.84164229e-02f, 3.74647044e-02f, 3.65216024e-02f, 3.55952792e-02f, 3.46978381e-02f,
     3.38449627e-02f, 3.30553837e-02f, 3.23702954e-02f, 3.18604484e-02f, 3.16753872e-02f, 3.21550332e-02f,
     3.42332684e-02f, 4.26845998e-02f},
    {4.76484969e-02f, 4.76075299e-02f, 4.74851392e-02f, 4.72828411e-02f, 4.70031127e-02f, 4.66493331e-02f,
     4.62256931e-02f, 4.57370877e-02f, 4.51890044e-02f, 4.45874110e-02f, 4.39386219e-02f, 4.32491973e-02f,
     4.25258391e-02f, 4.17753085e-02f, 4.10043634e-02f, 4.02197167e-02f, 3.94280367e-02f, 3.86359841e-02f,
     3.78502905e-02f, 3.70779186e-02f, 3.63263339e-02f, 3.56039293e-02f, 3.49207744e-02f, 3.42898928e-02f,
     3.37311141e-02f, 3.32701504e-02f, 3.29537727e-02f, 3.28658633e-02f, 3.31829786e-02f, 3.42942588e-02f,
     3.72851267e-02f, 4.76523675e-02f},
};
static const float ggx_mavg[GGX_TAB_N] = {
    4.78287898e-02f, 4.78455015e-02f, 4.78041321e-02f, 4.76334430e-02f, 4.72677648e-02f, 4.66703251e-02f,
    4.58345823e-02f, 4.47846204e-02f, 4.35637459e-02f, 4.22268771e-02f, 4.08332646e-02f, 3.94380018e-02f,
    3.80890444e-02f, 3.68266590e-02f, 3.56794037e-02f, 3.46676558e-02f, 3.38037349e-02f, 3.30931768e-02f,
    3.25369909e-02f, 3.21313851e-02f, 3.18704918e-02f, 3.17462198e-02f, 3.17497663e-02f, 3.18716243e-02f,
    3.21023762e-02f, 3.24324854e-02f, 3.28533575e-02f, 3.33565585e-02f, 3.39343734e-02f, 3.45795453e-02f,
    3.52855995e-02f, 3.60462293e-02f,
};
/* END GENERATED TABLES */

typedef struct ggx {
    const murk_host *host;
    murk_value p[P_COUNT];
    int use_alpha;
} ggx;

/* Parameter values at one hit. */
typedef struct ggx_shade {
    murk_rgb albedo, f0;
    float alpha; /* clamped to [GGX_ALPHA_MIN, 1] */
    float r;     /* sqrt(alpha): the table's second axis */
    float mavg;  /* Mavg(alpha) */
} ggx_shade;

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; } /* NaN -> 0 */
static int above(float z) { return z >= GGX_MU_MIN; }                                /* NaN -> 0 */

static void ggx_shade_at(const ggx *g, const murk_hit *hit, ggx_shade *sh)
{
    float v[3];
    murk_value_eval(g->host, &g->p[P_ALBEDO], hit, v);
    sh->albedo = murk_rgb3(clamp01(v[0]), clamp01(v[1]), clamp01(v[2]));
    murk_value_eval(g->host, &g->p[P_SPECULAR], hit, v);
    sh->f0 = murk_rgb3(clamp01(v[0]), clamp01(v[1]), clamp01(v[2]));
    float a;
    if (g->use_alpha) {
        murk_value_eval(g->host, &g->p[P_ALPHA], hit, v);
        a = clamp01(v[0]);
    } else {
        murk_value_eval(g->host, &g->p[P_ROUGHNESS], hit, v);
        float rough = clamp01(v[0]);
        a = rough * rough;
    }
    sh->alpha = a > GGX_ALPHA_MIN ? a : GGX_ALPHA_MIN;
    sh->r = sqrtf(sh->alpha);
    float x = sh->r * (float)(GGX_TAB_N - 1);
    int j = (int)x;
    if (j > GGX_TAB_N - 2)
        j = GGX_TAB_N - 2;
    float fr = x - (float)j;
    sh->mavg = ggx_mavg[j] + (ggx_mavg[j + 1] - ggx_mavg[j]) * fr;
}

/* Bilinear lookup of M(mu, alpha), mu in [0, 1]. */
static float ggx_m_lookup(const ggx_shade *sh, float mu)
{
    float t = sqrtf(clamp01(mu)) * (float)(GGX_TAB_N - 1);
    int i = (int)t;
    if (i > GGX_TAB_N - 2)
        i = GGX_TAB_N - 2;
    float ft = t - (float)i;
    float x = sh->r * (float)(GGX_TAB_N - 1);
    int j = (int)x;
    if (j > GGX_TAB_N - 2)
        j = GGX_TAB_N - 2;
    float fr = x - (float)j;
    float m0 = ggx_m[j][i] + (ggx_m[j][i + 1] - ggx_m[j][i]) * ft;
    float m1 = ggx_m[j + 1][i] + (ggx_m[j + 1][i + 1] - ggx_m[j + 1][i]) * ft;
    return m0 + (m1 - m0) * fr;
}

/* Probability of sampling the coat, from the lobes' expected contributions at wo. mo = M(mu_o). */
static float ggx_pspec(const ggx_shade *sh, float mo)
{
    murk_rgb ef, ed;
    for (int c = 0; c < 3; c++) {
        float f0 = sh->f0.c[c];
        ef.c[c] = f0 + (1.0f - f0) * mo;
        ed.c[c] = sh->albedo.c[c] * (1.0f - f0) * (1.0f - mo);
    }
    float ws = murk_luminance(ef), wd = murk_luminance(ed);
    if (!(wd > 0.0f))
        return 1.0f;
    if (!(ws > 0.0f))
        return 0.0f;
    float p = ws / (ws + wd);
    return p < GGX_PSPEC_MIN ? GGX_PSPEC_MIN : (p > GGX_PSPEC_MAX ? GGX_PSPEC_MAX : p);
}

static float ggx_R(float mu, float a2) { return sqrtf(mu * mu * (1.0f - a2) + a2); }

/* GGX D for the unit half vector h (h.z > 0). Bounded by 1 / (pi alpha^2). */
static float ggx_D(murk_vec3 h, float a2)
{
    float d = a2 * h.z * h.z + (h.x * h.x + h.y * h.y);
    return a2 / (MURK_PI * d * d);
}

/* Unit half vector of wo and wi (both above the horizon); 0 if they are (nearly) opposite. */
static int ggx_half(murk_vec3 wo, murk_vec3 wi, murk_vec3 *h)
{
    murk_vec3 s = murk_add(wo, wi);
    float l2 = murk_dot(s, s);
    if (!(l2 > 1e-12f))
        return 0;
    *h = murk_mul(s, 1.0f / sqrtf(l2));
    return 1;
}

static murk_rgb ggx_eval_sh(const ggx_shade *sh, murk_vec3 wo, murk_vec3 wi)
{
    murk_rgb f = murk_rgb1(0.0f);
    if (!above(wo.z) || !above(wi.z))
        return f;
    float mu_o = fminf(wo.z, 1.0f), mu_i = fminf(wi.z, 1.0f);
    /* diffuse base */
    float kd = (1.0f - ggx_m_lookup(sh, mu_o)) * (1.0f - ggx_m_lookup(sh, mu_i)) /
               fmaxf(1.0f - sh->mavg, 1e-6f) * MURK_INV_PI;
    for (int c = 0; c < 3; c++)
        f.c[c] = sh->albedo.c[c] * (1.0f - sh->f0.c[c]) * kd;
    /* specular coat */
    murk_vec3 h;
    if (ggx_half(wo, wi, &h)) {
        float a2 = sh->alpha * sh->alpha;
        float dv = ggx_D(h, a2) * 0.5f / (mu_i * ggx_R(mu_o, a2) + mu_o * ggx_R(mu_i, a2));
        float c = clamp01(murk_dot(wo, h));
        float x = 1.0f - c, x2 = x * x, x5 = x2 * x2 * x;
        for (int k = 0; k < 3; k++) {
            float fr = sh->f0.c[k] + (1.0f - sh->f0.c[k]) * x5;
            f.c[k] += fr * dv;
        }
    }
    return f;
}

static float ggx_pdf_sh(const ggx_shade *sh, murk_vec3 wo, murk_vec3 wi)
{
    if (!above(wo.z) || !above(wi.z))
        return 0.0f;
    float mu_o = fminf(wo.z, 1.0f), mu_i = fminf(wi.z, 1.0f);
    float ps = ggx_pspec(sh, ggx_m_lookup(sh, mu_o));
    float pdf = (1.0f - ps) * mu_i * MURK_INV_PI;
    murk_vec3 h;
    if (ps > 0.0f && ggx_half(wo, wi, &h)) {
        float a2 = sh->alpha * sh->alpha;
        /* D_wo(h) / (4 wo.h) = G1(wo) D(h) / (4 mu_o), G1 = 2 mu_o / (mu_o + R(mu_o)) */
        pdf += ps * ggx_D(h, a2) * 0.5f / (mu_o + ggx_R(mu_o, a2));
    }
    return pdf;
}

/* Visible GGX normal for wo (wo.z > 0), spherical caps (Dupuy & Benyoub 2023). */
static murk_vec3 ggx_sample_vndf(murk_vec3 wo, float alpha, float u0, float u1)
{
    /* to the hemisphere configuration (alpha = 1) */
    murk_vec3 ws = murk_normalize(murk_v3(alpha * wo.x, alpha * wo.y, wo.z));
    /* uniform point on the unit sphere's cap z in (-ws.z, 1]; the half vector of it and ws is a
     * visible normal of the hemisphere configuration */
    float phi = 2.0f * MURK_PI * u0;
    float z = (1.0f - u1) * (1.0f + ws.z) - ws.z;
    float st = sqrtf(clamp01(1.0f - z * z));
    murk_vec3 hs = murk_v3(st * cosf(phi) + ws.x, st * sinf(phi) + ws.y, z + ws.z);
    /* back to the ellipsoid configuration */
    return murk_normalize(murk_v3(alpha * hs.x, alpha * hs.y, fmaxf(hs.z, 0.0f)));
}

/* ---- Plugin interface ---------------------------------------------------------------------- */
static int ggx_create(const murk_host *host, const murk_value *p, void **self, char *err, size_t errlen)
{
    (void)err;
    (void)errlen;
    ggx *g = host->alloc(sizeof *g);
    if (!g)
        return -1;
    g->host = host;
    memcpy(g->p, p, sizeof g->p);
    g->use_alpha = p[P_ALPHA].set != 0;
    if (g->use_alpha && p[P_ROUGHNESS].set && host->log)
        host->log(MURK_LOG_WARN, "ggx: both 'roughness' and 'alpha' given; 'alpha' overrides 'roughness'");
    *self = g;
    return 0;
}

static void ggx_destroy(void *self)
{
    ggx *g = self;
    if (g)
        g->host->free(g);
}

static murk_rgb ggx_eval(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    if (!above(wo.z) || !above(wi.z))
        return murk_rgb1(0.0f);
    ggx_shade sh;
    ggx_shade_at(self, hit, &sh);
    return ggx_eval_sh(&sh, wo, wi);
}

static float ggx_pdf(const void *self, const murk_hit *hit, murk_vec3 wo, murk_vec3 wi)
{
    if (!above(wo.z) || !above(wi.z))
        return 0.0f;
    ggx_shade sh;
    ggx_shade_at(self, hit, &sh);
    return ggx_pdf_sh(&sh, wo, wi);
}

static int ggx_sample(const void *self, const murk_hit *hit, murk_vec3 wo, const float u[3], murk_bsdf_sample *s)
{
    memset(s, 0, sizeof *s);
    if (!above(wo.z))
        return 0;
    ggx_shade sh;
    ggx_shade_at(self, hit, &sh);
    float ps = ggx_pspec(&sh, ggx_m_lookup(&sh, fminf(wo.z, 1.0f)));
    murk_vec3 wi;
    if (u[2] < ps) {
        murk_vec3 h = ggx_sample_vndf(wo, sh.alpha, u[0], u[1]);
        float c = murk_dot(wo, h);
        if (!(c > 0.0f))
            return 0;
        wi = murk_normalize(murk_sub(murk_mul(h, 2.0f * c), wo));
    } else {
        float r = sqrtf(u[0]), phi = 2.0f * MURK_PI * u[1];
        wi = murk_v3(r * cosf(phi), r * sinf(phi), sqrtf(fmaxf(0.0f, 1.0f - u[0])));
    }
    if (!above(wi.z))
        return 0;
    float pdf = ggx_pdf_sh(&sh, wo, wi);
    murk_rgb f = ggx_eval_sh(&sh, wo, wi);
    if (!(pdf > 0.0f) || !isfinite(pdf) || !murk_rgb_finite(f))
        return 0;
    s->wi = wi;
    s->f = f;
    s->pdf = pdf;
    s->delta = 0;
    return 1;
}

static const murk_material_vt vt = {
    sizeof(murk_material_vt), MURK_KIND_MATERIAL, ggx_create, ggx_destroy, ggx_eval, ggx_pdf, ggx_sample,
};

MURK_MATERIAL_PLUGIN("ggx", "Lambertian base under a GGX specular coat (energy-conserving, reciprocal)", params,
                     P_COUNT, &vt)

#ifdef MURK_GGX_GENERATE_TABLES
/* ---- Table generator (not part of the plugin) ----------------------------------------------------
 * Prints the BEGIN..END GENERATED TABLES block. M is integrated in double precision over the unit
 * square of the spherical-cap VNDF parameterisation (where the integrand is bounded and smooth) with
 * tensor Gauss-Legendre quadrature. Safety margins: every table cell is checked at 6 x 6 interior points
 * against the directly integrated M; the cell's largest shortfall of the bilinear interpolant (x 1.25,
 * plus the quadrature error bound and float rounding) is added to the cell's four corners, and a second,
 * differently placed set of check points must then show no shortfall. */
#include <stdio.h>
#include <stdlib.h>

static void gen_gauss_legendre(int n, double *x, double *w)
{ /* nodes and weights on [0, 1] */
    const double pi = 3.14159265358979323846;
    for (int i = 0; i < n; i++) {
        double z = cos(pi * (i + 0.75) / (n + 0.5)), dp = 1.0;
        for (int it = 0; it < 100; it++) {
            double p0 = 1.0, p1 = 0.0;
            for (int k = 0; k < n; k++) {
                double p2 = p1;
                p1 = p0;
                p0 = ((2.0 * k + 1.0) * z * p1 - k * p2) / (k + 1.0);
            }
            dp = n * (z * p0 - p1) / (z * z - 1.0);
            double dz = p0 / dp;
            z -= dz;
            if (fabs(dz) < 1e-16)
                break;
        }
        x[i] = 0.5 * (1.0 - z);
        w[i] = 1.0 / ((1.0 - z * z) * dp * dp);
    }
}

static double gen_M(double mu, double alpha, int n, const double *x, const double *w)
{
    const double pi = 3.14159265358979323846;
    double ox = sqrt(fmax(0.0, 1.0 - mu * mu)), oz = mu;
    double sx = alpha * ox, sz = oz, l = sqrt(sx * sx + sz * sz);
    sx /= l;
    sz /= l;
    double sum = 0.0;
    for (int i = 0; i < n; i++) {
        double cp = cos(2.0 * pi * x[i]), sp = sin(2.0 * pi * x[i]);
        for (int j = 0; j < n; j++) {
            double z = (1.0 - x[j]) * (1.0 + sz) - sz, st = sqrt(fmax(0.0, 1.0 - z * z));
            double hx = alpha * (st * cp + sx), hy = alpha * st * sp, hz = z + sz;
            double hl = sqrt(hx * hx + hy * hy + hz * hz);
            if (!(hl > 0.0))
                continue;
            double c = (ox * hx + oz * hz) / hl;
            c = c < 0.0 ? 0.0 : (c > 1.0 ? 1.0 : c);
            double t = 1.0 - c;
            sum += w[i] * w[j] * t * t * t * t * t;
        }
    }
    return sum;
}

enum { GEN_N = GGX_TAB_N, GEN_Q = 128, GEN_Q2 = 64 };
static double gen_xq[GEN_Q], gen_wq[GEN_Q];

static double gen_alpha(double r) { return fmax(r * r, (double)GGX_ALPHA_MIN); }
static double gen_true(double t, double r) { return gen_M(t * t, gen_alpha(r), GEN_Q, gen_xq, gen_wq); }
static double gen_interp(double T[GEN_N][GEN_N], double t, double r)
{
    double x = t * (GEN_N - 1), y = r * (GEN_N - 1);
    int i = (int)x, j = (int)y;
    if (i > GEN_N - 2)
        i = GEN_N - 2;
    if (j > GEN_N - 2)
        j = GEN_N - 2;
    double ft = x - i, fr = y - j;
    double a = T[j][i] + (T[j][i + 1] - T[j][i]) * ft, b = T[j + 1][i] + (T[j + 1][i + 1] - T[j + 1][i]) * ft;
    return a + (b - a) * fr;
}

int main(void)
{
    static double T[GEN_N][GEN_N], cellm[GEN_N - 1][GEN_N - 1];
    double x2[GEN_Q2], w2[GEN_Q2];
    gen_gauss_legendre(GEN_Q, gen_xq, gen_wq);
    gen_gauss_legendre(GEN_Q2, x2, w2);
    double qerr = 0.0;
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double t = i / (double)(GEN_N - 1), r = j / (double)(GEN_N - 1);
            T[j][i] = gen_true(t, r);
            qerr = fmax(qerr, fabs(T[j][i] - gen_M(t * t, gen_alpha(r), GEN_Q2, x2, w2)));
        }
    double maxdef = 0.0, maxmargin = 0.0;
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++) {
            double def = 0.0;
            for (int b = 0; b < 6; b++)
                for (int a = 0; a < 6; a++) {
                    double t = (i + (a + 0.5) / 6.0) / (GEN_N - 1), r = (j + (b + 0.5) / 6.0) / (GEN_N - 1);
                    def = fmax(def, gen_true(t, r) - gen_interp(T, t, r));
                }
            maxdef = fmax(maxdef, def);
            cellm[j][i] = 1.25 * def + qerr + 1e-6;
        }
    static double S[GEN_N][GEN_N];
    for (int j = 0; j < GEN_N; j++)
        for (int i = 0; i < GEN_N; i++) {
            double m = 0.0;
            for (int b = j - 1; b <= j; b++)
                for (int a = i - 1; a <= i; a++)
                    if (a >= 0 && b >= 0 && a < GEN_N - 1 && b < GEN_N - 1)
                        m = fmax(m, cellm[b][a]);
            maxmargin = fmax(maxmargin, m);
            float v = (float)fmin(1.0, T[j][i] + m);
            if ((double)v < fmin(1.0, T[j][i] + m))
                v = nextafterf(v, 2.0f);
            S[j][i] = v;
        }
    /* independent verification */
    double worst = -1.0;
    for (int j = 0; j < GEN_N - 1; j++)
        for (int i = 0; i < GEN_N - 1; i++)
            for (int b = 0; b < 5; b++)
                for (int a = 0; a < 5; a++) {
                    double t = (i + (a + 0.37) / 5.0) / (GEN_N - 1), r = (j + (b + 0.61) / 5.0) / (GEN_N - 1);
                    worst = fmax(worst, gen_true(t, r) - gen_interp(S, t, r));
                }
    fprintf(stderr, "quadrature error bound %.3g, largest interpolation shortfall %.3g, largest margin %.3g, "
                    "verification: largest shortfall %.3g (must be <= 0)\n", qerr, maxdef, maxmargin, worst);
    if (worst > 0.0)
        return 1;
    printf("/* BEGIN GENERATED TABLES */\n");
    printf("/* generated by MURK_GGX_GENERATE_TABLES: quadrature error %.2g, largest margin %.2g */\n", qerr,
           maxmargin);
    printf("static const float ggx_m[GGX_TAB_N][GGX_TAB_N] = {\n");
    for (int j = 0; j < GEN_N; j++) {
        printf("    {");
        for (int i = 0; i < GEN_N; i++)
            printf("%s%.8ef", i == 0 ? "" : (i % 6 == 0 ? ",\n     " : ", "), (double)(float)S[j][i]);
        printf("},\n");
    }
    printf("};\nstatic const float ggx_mavg[GGX_TAB_N] = {\n");
    for (int j = 0; j < GEN_N; j++) {
        /* exact integral of M 2 mu dmu = M 4 t^3 dt, M linear in t on each interval */
        double sum = 0.0;
        for (int i = 0; i < GEN_N - 1; i++) {
            double t0 = i / (double)(GEN_N - 1), t1 = (i + 1) / (double)(GEN_N - 1);
            double B = (S[j][i + 1] - S[j][i]) / (t1 - t0), A = S[j][i] - B * t0;
            sum += A * (pow(t1, 4) - pow(t0, 4)) + B * 0.8 * (pow(t1, 5) - pow(t0, 5));
        }
        printf("%s%.8ef,", j % 6 == 0 ? (j ? "\n    " : "    ") : " ", (double)(float)sum);
    }
    printf("\n};\n/* END GENERATED TABLES */\n");
    return 0;
}
#endif
