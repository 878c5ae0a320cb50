/* blackbody.c — blackbody emission for temperature fields (density.h): Planck's law integrated against the
 * CIE 1931 colour-matching functions, to XYZ, then to linear sRGB.
 *
 * Normalisation, as pbrt-v4 (BlackbodySpectrum): the spectrum is divided by its own peak,
 * B(lambda, T) / B(lambda_max(T), T) with Wien's lambda_max = 2.897771955e-3 m K / T, so that a medium's
 * `emission` scale means the same in murk as pbrt-v4's Lescale on the same explosion; its luminance still
 * rises steeply with T through the flame range (Y = 0.0034 at 1500 K, 0.048 at 2000 K, 0.83 at 4000 K).
 *     XYZ = sum_lambda Bn(lambda, T) cmf(lambda) / sum_lambda ybar(lambda)   (360..830 nm, 5 nm steps)
 * then linear sRGB with the IEC 61966-2-1 matrix (D65 white); channels that fall below 0 (the Planckian
 * locus leaves the sRGB gamut below about 1900 K) are set to 0.
 *
 * The colour-matching functions: the CIE 1931 2-degree standard colorimetric observer, 5 nm from 360 to
 * 830 nm (CIE 015:2018, Table 1), with the digits of the table as Debian's colord-data 1.4.6 ships it
 * (/usr/share/colord/cmf/CIE1931-2deg-XYZ.cmf). */
#include "media/density.h"
#include "util/util.h"

#include <math.h>
#include <stdlib.h>

static const double cie1931_5nm[95][3] = {
    {0.0001299, 0.000003917, 0.0006061}, {0.0002321, 0.000006965, 0.001086}, {0.0004149, 0.00001239, 0.001946},
    {0.0007416, 0.00002202, 0.003486}, {0.001368, 0.000039, 0.006450001}, {0.002236, 0.000064, 0.01054999},
    {0.004243, 0.00012, 0.02005001}, {0.00765, 0.000217, 0.03621}, {0.01431, 0.000396, 0.06785001},
    {0.02319, 0.00064, 0.1102}, {0.04351, 0.00121, 0.2074}, {0.07763, 0.00218, 0.3713},
    {0.13438, 0.004, 0.6456}, {0.21477, 0.0073, 1.0390501}, {0.2839, 0.0116, 1.3856},
    {0.3285, 0.01684, 1.62296}, {0.34828, 0.023, 1.74706}, {0.34806, 0.0298, 1.7826},
    {0.3362, 0.038, 1.77211}, {0.3187, 0.048, 1.7441}, {0.2908, 0.06, 1.6692},
    {0.2511, 0.0739, 1.5281}, {0.19536, 0.09098, 1.28764}, {0.1421, 0.1126, 1.0419},
    {0.09564, 0.13902, 0.8129501}, {0.05795001, 0.1693, 0.6162}, {0.03201, 0.20802, 0.46518},
    {0.0147, 0.2586, 0.3533}, {0.0049, 0.323, 0.272}, {0.0024, 0.4073, 0.2123},
    {0.0093, 0.503, 0.1582}, {0.0291, 0.6082, 0.1117}, {0.06327, 0.71, 0.07824999},
    {0.1096, 0.7932, 0.05725001}, {0.1655, 0.862, 0.04216}, {0.2257499, 0.9148501, 0.02984},
    {0.2904, 0.954, 0.0203}, {0.3597, 0.9803, 0.0134}, {0.4334499, 0.9949501, 0.008749999},
    {0.5120501, 1.0, 0.005749999}, {0.5945, 0.995, 0.0039}, {0.6784, 0.9786, 0.002749999},
    {0.7621, 0.952, 0.0021}, {0.8425, 0.9154, 0.0018}, {0.9163, 0.87, 0.001650001},
    {0.9786, 0.8163, 0.0014}, {1.0263, 0.757, 0.0011}, {1.0567, 0.6949, 0.001},
    {1.0622, 0.631, 0.0008}, {1.0456, 0.5668, 0.0006}, {1.0026, 0.503, 0.00034},
    {0.9384, 0.4412, 0.00024}, {0.8544499, 0.381, 0.00019}, {0.7514, 0.321, 0.0001},
    {0.6424, 0.265, 0.00004999999}, {0.5419, 0.217, 0.00003}, {0.4479, 0.175, 0.00002},
    {0.3608, 0.1382, 0.00001}, {0.2835, 0.107, 0.0}, {0.2187, 0.0816, 0.0},
    {0.1649, 0.061, 0.0}, {0.1212, 0.04458, 0.0}, {0.0874, 0.032, 0.0},
    {0.0636, 0.0232, 0.0}, {0.04677, 0.017, 0.0}, {0.0329, 0.01192, 0.0},
    {0.0227, 0.00821, 0.0}, {0.01584, 0.005723, 0.0}, {0.01135916, 0.004102, 0.0},
    {0.008110916, 0.002929, 0.0}, {0.005790346, 0.002091, 0.0}, {0.004109457, 0.001484, 0.0},
    {0.002899327, 0.001047, 0.0}, {0.00204919, 0.00074, 0.0}, {0.001439971, 0.00052, 0.0},
    {0.0009999493, 0.0003611, 0.0}, {0.0006900786, 0.0002492, 0.0}, {0.0004760213, 0.0001719, 0.0},
    {0.0003323011, 0.00012, 0.0}, {0.0002348261, 0.0000848, 0.0}, {0.0001661505, 0.00006, 0.0},
    {0.000117413, 0.0000424, 0.0}, {0.00008307527, 0.00003, 0.0}, {0.00005870652, 0.0000212, 0.0},
    {0.00004150994, 0.00001499, 0.0}, {0.00002935326, 0.0000106, 0.0}, {0.00002067383, 0.0000074657, 0.0},
    {0.00001455977, 0.0000052578, 0.0}, {0.00001025398, 0.0000037029, 0.0}, {0.000007221456, 0.0000026078, 0.0},
    {0.000005085868, 0.0000018366, 0.0}, {0.000003581652, 0.0000012934, 0.0}, {0.000002522525, 0.00000091093, 0.0},
    {0.000001776509, 0.00000064153, 0.0}, {0.000001251141, 0.00000045181, 0.0},
};

MURK_API void murk_cie1931(int i, double cmf[3])
{
    for (int j = 0; j < 3; j++)
        cmf[j] = i >= 0 && i < 95 ? cie1931_5nm[i][j] : 0.0;
}

MURK_API void murk_blackbody_xyz(double T, double xyz[3])
{
    xyz[0] = xyz[1] = xyz[2] = 0.0;
    if (!(T > 0.0) || !isfinite(T))
        return;
    const double h = 6.62607015e-34, c = 299792458.0, k = 1.380649e-23; /* SI 2019, exact */
    double c2 = h * c / k, lmax = 2.897771955e-3 / T;
    double peak = 1.0 / (pow(lmax, 5.0) * expm1(c2 / (lmax * T))), ysum = 0.0;
    for (int i = 0; i < 95; i++) {
        double l = (360.0 + 5.0 * i) * 1e-9, b = 1.0 / (pow(l, 5.0) * expm1(c2 / (l * T))) / peak;
        for (int j = 0; j < 3; j++)
            xyz[j] += b * cie1931_5nm[i][j];
        ysum += cie1931_5nm[i][1];
    }
    for (int j = 0; j < 3; j++)
        xyz[j] /= ysum;
}

MURK_API murk_rgb murk_blackbody_rgb(double T)
{
    double x[3];
    murk_blackbody_xyz(T, x);
    double r = 3.2404542 * x[0] - 1.5371385 * x[1] - 0.4985314 * x[2];
    double g = -0.9692660 * x[0] + 1.8760108 * x[1] + 0.0415560 * x[2];
    double b = 0.0556434 * x[0] - 0.2040259 * x[1] + 1.0572252 * x[2];
    return murk_rgb3((float)fmax(r, 0.0), (float)fmax(g, 0.0), (float)fmax(b, 0.0));
}

MURK_API int murk_blackbody_table_build(murk_blackbody_table *t, double tmax)
{
    t->n = 0;
    t->rgb = NULL;
    if (!(tmax > 0.0) || !isfinite(tmax))
        tmax = 1.0;
    int n = (int)fmin(ceil(tmax), (double)MURK_BLACKBODY_TABLE_MAX) + 1;
    t->step = (float)(tmax / (n - 1));
    t->inv_step = 1.0f / t->step;
    t->rgb = malloc((size_t)(n + 1) * sizeof *t->rgb);
    if (!t->rgb)
        return -1;
    for (int i = 0; i < n; i++)
        t->rgb[i] = murk_blackbody_rgb((double)t->step * i);
    t->rgb[n] = t->rgb[n - 1]; /* the interpolation's right neighbour at the last entry */
    t->n = n;
    return 0;
}

MURK_API void murk_blackbody_table_free(murk_blackbody_table *t)
{
    free(t->rgb);
    t->rgb = NULL;
    t->n = 0;
}
