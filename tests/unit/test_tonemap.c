/*
 * test_tonemap.c - the tone curves of 8-bit outputs (image_tonemap,
 * PK_TONEMAP_*), each against values computed here in double precision from
 * its published definition:
 *   - PBR Neutral (Khronos): the specification's steps; colours with every
 *     component in [0.08, 0.8] come out less 0.04 (its guarantee), and the
 *     curve is continuous where compression starts;
 *   - AgX (Blender's, Eary Chow's definition): Rec.709 -> Rec.2020 (BT.2087)
 *     times AgX's inset matrix multiplied out here, the log2 encoding, and
 *     the sigmoid whose toe and shoulder scales are found here by bisection
 *     from its conditions (through (0, 0), the pivot and (1, 1)) rather
 *     than from their closed form;
 *   - ACES (Hill's fit of RRT + ODT);
 * and for every curve: 0 -> 0, monotonic along the grey axis and along a
 * coloured ray, outputs in [0, 1], names parsed and printed.
 */
#include "test.h"

#include "paprsek.h"
#include "image/image_write.h"

/* ---- the references ------------------------------------------------------ */

static void ref_pbr_neutral(const double in[3], double out[3])
{
    double c[3] = {in[0], in[1], in[2]};
    const double ks = 0.8 - 0.04, kd = 0.15;
    double x = c[0] < c[1] ? c[0] : c[1];
    x = x < c[2] ? x : c[2];
    const double f = x < 0.08 ? x - 6.25 * x * x : 0.04;
    for (int i = 0; i < 3; i++) c[i] -= f;
    double p = c[0] > c[1] ? c[0] : c[1];
    p = p > c[2] ? p : c[2];
    if (p < ks) {
        for (int i = 0; i < 3; i++) out[i] = c[i];
        return;
    }
    const double d = 1.0 - ks, pn = 1.0 - d * d / (p + d - ks), g = 1.0 - 1.0 / (kd * (p - pn) + 1.0);
    for (int i = 0; i < 3; i++) out[i] = c[i] * pn / p * (1.0 - g) + pn * g;
}

/* AgX's sigmoid with scale k on one side: y_p + s (x - x_p) / (1 + |s (x - x_p) / k|^p)^(1/p). */
static double agx_side(double x, double k)
{
    const double xp = 10.0 / 16.5, yp = pow(0.18, 1.0 / 2.4), s = 2.4, p = 1.5;
    const double t = s * (x - xp);
    return yp + t / pow(1.0 + pow(fabs(t) / k, p), 1.0 / p);
}

/* The k for which agx_side(end, k) == target (monotonic in k). */
static double agx_scale(double end, double target)
{
    double lo = 1e-6, hi = 1e3;
    for (int it = 0; it < 200; it++) {
        const double mid = sqrt(lo * hi);
        const double y = agx_side(end, mid);
        /* larger k: closer to the straight line, farther from the pivot */
        if ((end < 0.5 ? y < target : y > target)) hi = mid;
        else lo = mid;
    }
    return sqrt(lo * hi);
}

static void ref_agx(const double in[3], double out[3])
{
    static const double bt2087[3][3] = {
        {0.6274040, 0.3292820, 0.0433136}, {0.0690970, 0.9195400, 0.0113612}, {0.0163916, 0.0880132, 0.8955950}};
    static const double inset[3][3] = {{0.856627153315983, 0.0951212405381588, 0.0482516061458583},
                                       {0.137318972929847, 0.761241990602591, 0.101439036467562},
                                       {0.11189821299995, 0.0767994186031903, 0.811302368396859}};
    static const double outset[3][3] = {{1.9645509602733, -0.8558584511781, -0.1088671082683},
                                        {-0.2993224339091, 1.3264510741502, -0.0270840209839},
                                        {-0.1643683380608, -0.2382246406886, 1.4026653471433}};
    static double k_toe, k_shoulder;
    if (k_toe == 0.0) {
        k_toe = agx_scale(0.0, 0.0);
        k_shoulder = agx_scale(1.0, 1.0);
    }
    double r2020[3], e[3];
    for (int i = 0; i < 3; i++) r2020[i] = bt2087[i][0] * in[0] + bt2087[i][1] * in[1] + bt2087[i][2] * in[2];
    for (int i = 0; i < 3; i++) {
        e[i] = inset[i][0] * r2020[0] + inset[i][1] * r2020[1] + inset[i][2] * r2020[2];
        double x = (log2(e[i] > 1e-10 ? e[i] / 0.18 : 1e-10 / 0.18) + 10.0) / 16.5;
        x = x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x;
        e[i] = pow(agx_side(x, x < 10.0 / 16.5 ? k_toe : k_shoulder), 2.4);
    }
    for (int i = 0; i < 3; i++) out[i] = outset[i][0] * e[0] + outset[i][1] * e[1] + outset[i][2] * e[2];
}

static void ref_aces(const double in[3], double out[3])
{
    static const double mi[3][3] = {{0.59719, 0.35458, 0.04823}, {0.07600, 0.90834, 0.01566}, {0.02840, 0.13383, 0.83777}};
    static const double mo[3][3] = {
        {1.60475, -0.53108, -0.07367}, {-0.10208, 1.10813, -0.00605}, {-0.00327, -0.07276, 1.07602}};
    double v[3];
    for (int i = 0; i < 3; i++) {
        const double x = mi[i][0] * in[0] + mi[i][1] * in[1] + mi[i][2] * in[2];
        v[i] = (x * (x + 0.0245786) - 0.000090537) / (x * (0.983729 * x + 0.4329510) + 0.238081);
    }
    for (int i = 0; i < 3; i++) out[i] = mo[i][0] * v[0] + mo[i][1] * v[1] + mo[i][2] * v[2];
}

static double clamp01(double x) { return x < 0.0 ? 0.0 : x > 1.0 ? 1.0 : x; }

/* ---- the checks ---------------------------------------------------------- */

static void check_against(int curve, void (*ref)(const double *, double *), double tol)
{
    /* greys over 14 stops, colours, saturated primaries, highlights */
    static const double cols[][3] = {{0.18, 0.18, 0.18}, {0.5, 0.2, 0.05}, {0.05, 0.3, 0.9}, {1.0, 0.0, 0.0},
                                     {0.0, 1.0, 0.0},    {0.0, 0.0, 1.0},  {3.0, 2.0, 0.5},  {10.0, 10.0, 10.0},
                                     {0.01, 0.02, 0.005}, {0.7, 0.7, 0.1}, {40.0, 5.0, 1.0}, {0.001, 0.001, 0.001}};
    double worst = 0.0;
    for (size_t n = 0; n < sizeof cols / sizeof cols[0]; n++) {
        float in[3] = {(float)cols[n][0], (float)cols[n][1], (float)cols[n][2]}, out[3];
        const double din[3] = {in[0], in[1], in[2]};
        double want[3];
        ref(din, want);
        image_tonemap(curve, in, out);
        for (int i = 0; i < 3; i++) {
            const double d = fabs((double)out[i] - clamp01(want[i]));
            worst = d > worst ? d : worst;
            CHECKF(d <= tol, "%s (%g, %g, %g) channel %d: %.7f vs %.7f", pk_tonemap_name(curve), din[0], din[1],
                   din[2], i, (double)out[i], clamp01(want[i]));
        }
    }
    printf("%-12s largest difference from the reference: %.2e (tolerance %.0e)\n", pk_tonemap_name(curve), worst, tol);
}

static void check_shape(int curve)
{
    const float zero[3] = {0.0f, 0.0f, 0.0f};
    float out[3];
    image_tonemap(curve, zero, out);
    for (int i = 0; i < 3; i++) CHECKF(out[i] == 0.0f, "%s: 0 -> %g", pk_tonemap_name(curve), (double)out[i]);
    /* monotonic: grey from 2^-14 to 2^14, and a colour scaled the same way
     * (its luminance), in steps of 1/16 stop */
    float prev_g = 0.0f, prev_l = 0.0f;
    int bad_g = 0, bad_l = 0;
    for (int s = -14 * 16; s <= 14 * 16; s++) {
        const float v = exp2f((float)s / 16.0f);
        const float grey[3] = {v, v, v}, col[3] = {0.8f * v, 0.3f * v, 0.1f * v};
        image_tonemap(curve, grey, out);
        /* grey stays grey up to the matrices' rounding (ACES's output rows sum to 1 within 1e-5,
         * AgX's within 1e-4) */
        bad_g += out[1] < prev_g || fabsf(out[0] - out[1]) > 2e-4f || fabsf(out[2] - out[1]) > 2e-4f;
        prev_g = out[1];
        for (int i = 0; i < 3; i++) bad_g += !(out[i] >= 0.0f && out[i] <= 1.0f);
        image_tonemap(curve, col, out);
        const float l = 0.2126f * out[0] + 0.7152f * out[1] + 0.0722f * out[2];
        bad_l += l < prev_l - 1e-7f;
        prev_l = l;
    }
    CHECKF(bad_g == 0, "%s: grey ramp not monotonic and grey (%d)", pk_tonemap_name(curve), bad_g);
    CHECKF(bad_l == 0, "%s: colour ramp's luminance not monotonic (%d)", pk_tonemap_name(curve), bad_l);
    const float nan3[3] = {NAN, -1.0f, INFINITY};
    image_tonemap(curve, nan3, out);
    for (int i = 0; i < 3; i++) CHECKF(out[i] >= 0.0f && out[i] <= 1.0f, "%s: NaN, -1, inf -> %g", pk_tonemap_name(curve), (double)out[i]);
}

static void test_agx_grey(void)
{
    float prev = 0.0f, out[3];
    int bad = 0;
    for (int s = -14 * 16; s <= 14 * 16; s++) {
        const float v = exp2f((float)s / 16.0f), g[3] = {v, v, v};
        image_tonemap(PK_TONEMAP_AGX, g, out);
        bad += out[1] < prev || fabsf(out[0] - out[1]) > 2e-4f || fabsf(out[2] - out[1]) > 2e-4f;
        prev = out[1];
    }
    CHECKF(bad == 0, "agx: grey ramp not monotonic and grey (%d)", bad);
    /* middle grey lands on the pivot: 0.18^(1/2.4) encoded, so 0.18 linear */
    const float mid[3] = {0.18f, 0.18f, 0.18f};
    image_tonemap(PK_TONEMAP_AGX, mid, out);
    CHECK_NEAR(out[1], 0.18, 2e-3);
}

static void test_pbr_neutral_identity(void)
{
    /* every component in [0.08, 0.8]: out = in - 0.04 exactly (in float) */
    int bad = 0;
    for (int r = 0; r <= 8; r++)
        for (int g = 0; g <= 8; g++)
            for (int b = 0; b <= 8; b++) {
                const float in[3] = {0.08f + 0.09f * (float)r, 0.08f + 0.09f * (float)g, 0.08f + 0.09f * (float)b};
                float out[3];
                image_tonemap(PK_TONEMAP_PBR_NEUTRAL, in, out);
                for (int i = 0; i < 3; i++) bad += fabsf(out[i] - (in[i] - 0.04f)) > 1e-6f;
            }
    CHECKF(bad == 0, "pbr-neutral: %d components of colours in [0.08, 0.8] are not the input less 0.04", bad);
    /* continuous where compression starts (peak 0.76 after the offset) */
    const float a[3] = {0.7999f, 0.5f, 0.3f}, b[3] = {0.8001f, 0.5f, 0.3f};
    float oa[3], ob[3];
    image_tonemap(PK_TONEMAP_PBR_NEUTRAL, a, oa);
    image_tonemap(PK_TONEMAP_PBR_NEUTRAL, b, ob);
    for (int i = 0; i < 3; i++) CHECK_NEAR(oa[i], ob[i], 1e-3);
    /* the darks: below 0.08 the offset x - 6.25 x^2 takes 0 to 0, 0.04 at 0.08 */
    const float d[3] = {0.04f, 0.04f, 0.04f};
    image_tonemap(PK_TONEMAP_PBR_NEUTRAL, d, oa);
    CHECK_NEAR(oa[0], 0.04 - (0.04 - 6.25 * 0.04 * 0.04), 1e-7);
}

static void test_names(void)
{
    CHECK(pk_tonemap_parse("clamp") == PK_TONEMAP_CLAMP);
    CHECK(pk_tonemap_parse("agx") == PK_TONEMAP_AGX);
    CHECK(pk_tonemap_parse("pbr-neutral") == PK_TONEMAP_PBR_NEUTRAL);
    CHECK(pk_tonemap_parse("aces") == PK_TONEMAP_ACES);
    CHECK(pk_tonemap_parse("filmic") == -1 && pk_tonemap_parse(NULL) == -1);
    for (int k = 0; k < PK_TONEMAP_COUNT; k++) CHECK(pk_tonemap_parse(pk_tonemap_name(k)) == k);
    CHECK(strcmp(pk_tonemap_name(99), "unknown") == 0);
    /* clamp is the identity clipped to [0, 1] */
    const float in[3] = {0.25f, 1.5f, -0.5f};
    float out[3];
    image_tonemap(PK_TONEMAP_CLAMP, in, out);
    CHECK(out[0] == 0.25f && out[1] == 1.0f && out[2] == 0.0f);
}

int main(void)
{
    test_names();
    /* tolerances: float evaluation of a double reference, 1e-5; AgX 5e-4,
     * since its matrix product is taken here from the two published
     * matrices, whose entries differ from the stored product by up to 1e-4) */
    check_against(PK_TONEMAP_PBR_NEUTRAL, ref_pbr_neutral, 1e-5);
    check_against(PK_TONEMAP_ACES, ref_aces, 1e-5);
    check_against(PK_TONEMAP_AGX, ref_agx, 5e-4);
    for (int k = 0; k < PK_TONEMAP_COUNT; k++) check_shape(k);
    test_agx_grey();
    test_pbr_neutral_identity();
    return test_done("test_tonemap");
}
