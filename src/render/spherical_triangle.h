/*
 * spherical_triangle.h - directions uniform in the solid angle that a
 * triangle subtends from a point (Arvo 1995, "Stratified sampling of
 * spherical triangles"), the inverse of that map, and the bilinear warp of
 * its unit square that lights.h puts in front of it to follow the cosine at
 * the receiver. Every function is PK_HD (the GPU's path tracer samples
 * lights with them).
 *
 * The map. Seen from p the triangle v0 v1 v2 is the spherical triangle of
 * the unit directions a, b, c, with angle alpha at a and area (solid angle)
 * O. u0 picks the sub-triangle a b c' whose area is u0 O, c' on the arc from
 * a to c; u1 picks the direction on the arc from b to c' with 1 - cos of
 * its angle from b uniform. Every direction of the triangle then has the
 * density 1 / O. Corners of the unit square: (u0, u1) = (0, 0) and (1, 0)
 * go to b, (0, 1) to a, (1, 1) to c.
 *
 * Precision. The textbook formulations lose everything for small
 * triangles: O = alpha + beta + gamma - pi cancels, and Arvo's cos of the
 * arc a c' is 1 - tiny. Here instead:
 *   - O from the Van Oosterom-Strackee formula tan(O / 2) = det(a, b, c) /
 *     (1 + a.b + b.c + c.a), with det(a, b, c) = (v0 - p).(e1 x e2) / (|v0 - p|
 *     |v1 - p| |v2 - p|) taken from the triangle's edges e1 = v1 - v0,
 *     e2 = v2 - v0, not from differences of nearly equal unit vectors;
 *   - alpha from the tangents at a of the arcs toward b and c, which are
 *     the parts of e1 and e2 across a (atan2 of their cross and dot);
 *   - the arc a c' as t = tan(b' / 2): for the triangle of sides c (= arc a
 *     b), b' and the angle alpha between them, tan(A / 2) = t k sin(alpha) /
 *     (1 + t k cos(alpha)) with k = tan(c / 2) (the area from two sides and
 *     the included angle), which solved for t is
 *         t = sin(A / 2) / (k sin(alpha - A / 2)),
 *     every factor well conditioned when the triangle is small (alpha >
 *     O / 2 in any spherical triangle, so the sine stays positive);
 *   - 1 - cos of an arc as |x - y|^2 / 2.
 * The caller (lights.h) still samples small solid angles by area: below
 * SPH_TRI_MIN_SOLID_ANGLE area sampling is cheaper for the noise it leaves
 * (see the definition), and above
 * SPH_TRI_MAX_SOLID_ANGLE (a point almost on the triangle) the map's arcs
 * approach pi.
 */
#ifndef PK_SPHERICAL_TRIANGLE_H
#define PK_SPHERICAL_TRIANGLE_H

#include "../math/vec3.h"

#if !defined(__CUDACC__) && defined(__GNUC__) && (defined(__x86_64__) || defined(__i386__)) && defined(__SSE__)
#include <xmmintrin.h>
#define SPH_SQRT_SSE 1
#endif

/* 0.5 sr, where pbrt-v4 takes 3e-4: measured at equal time, the warped
 * spherical sample's extra cost (+29 % per sample in the Cornell box) buys
 * less than it costs below that. CornellBox-Original 512x512, 3 s, noise
 * from two seeds (bench/noise2.sh), two rounds: 3e-4 sr 8.83/8.91 %, 0.5 sr
 * 8.13/8.05 %, area sampling only 8.29/8.03 %. Near lights (a lamp a few
 * centimetres from a surface), where area sampling leaves fireflies, still
 * take the spherical sample. -D to measure another threshold. */
#ifndef SPH_TRI_MIN_SOLID_ANGLE
#define SPH_TRI_MIN_SOLID_ANGLE 0.5f
#endif
#define SPH_TRI_MAX_SOLID_ANGLE 6.22f

/* sqrtf(x): the same correctly rounded value, as the SSE instruction on
 * x86. Without -fno-math-errno GCC leaves sqrtf a call into the C library
 * in blocks it estimates cold, and the branches before a light sample make
 * these such blocks in the path tracer's inlined step (measured: with this
 * and sph_atan2 the Cornell box renders some 5 % faster). */
static inline PK_HD float sph_sqrt(float x)
{
#ifdef SPH_SQRT_SSE
    return _mm_cvtss_f32(_mm_sqrt_ss(_mm_set_ss(x)));
#else
    return sqrtf(x);
#endif
}

/* atan2(y, x) (not both 0) to within 2e-7 relative, without the C
 * library's call: atan(t) / t on [0, 1] as a polynomial
 * in t^2 (Abramowitz and Stegun 4.4.49, error 2e-8 relative; its constant
 * term is 1, so small angles keep their relative precision), then the
 * octant. Sampling and pdf use this same function, so its error is only a
 * (tiny) error in the map, never a disagreement between them. */
static inline PK_HD float sph_atan2(float y, float x)
{
    const float ay = fabsf(y), ax = fabsf(x), mx = ay > ax ? ay : ax, mn = ay > ax ? ax : ay;
    if (!(mx > 0.0f)) return 0.0f;
    const float t = mn / mx, s = t * t;
    float r = 0.0028662257f;
    r = r * s - 0.0161657367f;
    r = r * s + 0.0429096138f;
    r = r * s - 0.0752896400f;
    r = r * s + 0.1065626393f;
    r = r * s - 0.1420889944f;
    r = r * s + 0.1999355085f;
    r = r * s - 0.3333314528f;
    r = t + t * (r * s);
    if (ay > ax) r = 0.5f * PK_PI - r;
    if (x < 0.0f) r = PK_PI - r;
    return y < 0.0f ? -r : r;
}

/* A triangle as seen from a point. */
typedef struct sph_tri {
    vec3 a, b, c;                /* unit directions toward v0, v1, v2 */
    vec3 tc;                     /* unit tangent at a of the arc from a toward c */
    float area;                  /* the solid angle, in (0, 2 pi) */
    float sin_alpha, cos_alpha;  /* the angle at a */
    float k;                     /* tan of half the arc from a to b */
} sph_tri;

/* The triangle v0 v1 v2 seen from p, and whether its solid angle lies in
 * [min_area, max_area]; false also for a degenerate view (p on the
 * triangle's plane, a vertex at p, a sliver whose angles round to nothing,
 * lengths that overflow or vanish in float). *t is only complete when true. */
static inline PK_HD bool sph_tri_setup(sph_tri *t, vec3 p, vec3 v0, vec3 v1, vec3 v2, float min_area, float max_area)
{
    const vec3 A = v3_sub(v0, p), B = v3_sub(v1, p), C = v3_sub(v2, p);
    /* 1 / length; a length that vanishes or overflows gives 0 or inf here */
    const float ia = 1.0f / sph_sqrt(v3_len2(A)), ib = 1.0f / sph_sqrt(v3_len2(B)), ic = 1.0f / sph_sqrt(v3_len2(C));
    if (!(ia > 0.0f && ib > 0.0f && ic > 0.0f) || !isfinite(ia * ib * ic)) return false;
    t->a = v3_scale(A, ia), t->b = v3_scale(B, ib), t->c = v3_scale(C, ic);
    const vec3 e1 = v3_sub(v1, v0), e2 = v3_sub(v2, v0);
    const float an = v3_dot(t->a, v3_cross(e1, e2)); /* |e1 x e2| times the sine of a's elevation */
    const float det = an * (ib * ic);
    const float ab = v3_dot(t->a, t->b), bc = v3_dot(t->b, t->c), ca = v3_dot(t->c, t->a);
    t->area = 2.0f * sph_atan2(fabsf(det), 1.0f + ab + bc + ca);
    if (!(t->area >= min_area && t->area <= max_area)) return false; /* NaN too */
    /* the angle at a: between the tangents tb, tc of the arcs toward b and
     * c; tb x tc is along a, of length |an| */
    const vec3 tb = v3_sub(e1, v3_scale(t->a, v3_dot(t->a, e1)));
    const vec3 tc = v3_sub(e2, v3_scale(t->a, v3_dot(t->a, e2)));
    const float itb = 1.0f / sph_sqrt(v3_len2(tb)), itc = 1.0f / sph_sqrt(v3_len2(tc)), ir = itb * itc;
    if (!(ir > 0.0f) || !isfinite(ir) || !isfinite(an)) return false;
    t->sin_alpha = fabsf(an) * ir, t->cos_alpha = v3_dot(tb, tc) * ir;
    t->tc = v3_scale(tc, itc);
    /* tan(c / 2) = |a x b| / (1 + a.b), with a x b = a x e1 / |v1 - p| */
    t->k = sph_sqrt(v3_len2(v3_cross(t->a, e1))) * ib / (1.0f + ab);
    return t->sin_alpha > 0.0f && t->k > 0.0f && isfinite(t->k);
}

/* The point c' of the arc from a toward c at angle (cos, sin) = (cb, sb)
 * from a. */
static inline PK_HD vec3 sph_tri_on_ac(const sph_tri *t, float cb, float sb)
{
    return v3_add(v3_scale(t->a, cb), v3_scale(t->tc, sb));
}

/* The unit direction of (u0, u1) in [0, 1]^2. */
static inline PK_HD vec3 sph_tri_sample(const sph_tri *t, float u0, float u1)
{
    /* c': tan(b' / 2) = num / den for the sub-triangle of area u0 O */
    const float h = 0.5f * u0 * t->area, sh = sinf(h), ch = cosf(h);
    float num = sh, den = t->k * (t->sin_alpha * ch - t->cos_alpha * sh);
    vec3 cp;
    const float m = num > fabsf(den) ? num : fabsf(den);
    if (!(m > 0.0f)) {
        cp = t->a;
    } else {
        const float im = 1.0f / m;
        num *= im, den *= im;
        const float iq = 1.0f / (num * num + den * den);
        const float cb = (den * den - num * num) * iq, sb = 2.0f * num * den * iq;
        /* (rounding may carry c' a few ulps past c when u0 is near 1; the
         * caller clamps the point to the triangle) */
        cp = den < 0.0f ? t->c : sph_tri_on_ac(t, cb, sb);
    }
    /* along the arc from b to c': 1 - cos theta = u1 (1 - b.c') */
    const vec3 d = v3_sub(cp, t->b);
    const float z = u1 * 0.5f * v3_len2(d);
    const float zz = z * (2.0f - z), cos_t = 1.0f - z, sin_t = sph_sqrt(zz > 0.0f ? zz : 0.0f);
    const vec3 perp = v3_sub(d, v3_scale(t->b, v3_dot(d, t->b))); /* c' - (c'.b) b, without the cancellation */
    const float lp = sph_sqrt(v3_len2(perp));
    if (!(lp > 0.0f)) return t->b;
    return v3_add(v3_scale(t->b, cos_t), v3_scale(perp, sin_t / lp));
}

/* The (u0, u1) that sph_tri_sample maps to the unit direction w (of the
 * spherical triangle), clamped to [0, 1]^2. */
static inline PK_HD void sph_tri_invert(const sph_tri *t, vec3 w, float *u0, float *u1)
{
    /* c' = cos b' a + sin b' tc lies on the great circle through b and w:
     * normal m = b x w, so (cos b', sin b') is along (m.tc, -m.a) */
    const vec3 m = v3_cross(t->b, w);
    float x = v3_dot(m, t->tc), y = -v3_dot(m, t->a);
    /* of the two antipodal points, the one on the arc (shorter than pi):
     * the one on the side of the arc's midpoint a + c = (1 + a.c) a +
     * (c.tc) tc (not the sign of y alone, which rounding decides when c' is
     * a) */
    if (x * (1.0f + v3_dot(t->a, t->c)) + y * v3_dot(t->c, t->tc) < 0.0f) x = -x, y = -y;
    const float r = sph_sqrt(x * x + y * y); /* x, y: at most 1 */
    if (!(r > 0.0f) || !isfinite(r)) { /* w is b: any u0 */
        *u0 = 0.5f, *u1 = 0.0f;
        return;
    }
    const float cb = x / r, sb = y / r;
    /* the area of a b c': tan(A / 2) = tan(b' / 2) k sin(alpha) / (1 + tan(b' / 2) k cos(alpha)),
     * tan(b' / 2) = sb / (1 + cb) */
    const float ap = 2.0f * sph_atan2(sb * t->k * t->sin_alpha, (1.0f + cb) + sb * t->k * t->cos_alpha);
    float v0 = ap / t->area;
    const vec3 cp = sph_tri_on_ac(t, cb, sb);
    const float dc = v3_len2(v3_sub(cp, t->b));
    float v1 = dc > 0.0f ? v3_len2(v3_sub(w, t->b)) / dc : 0.0f;
    *u0 = v0 > 0.0f ? (v0 < 1.0f ? v0 : 1.0f) : 0.0f;
    *u1 = v1 > 0.0f ? (v1 < 1.0f ? v1 : 1.0f) : 0.0f;
}

/* ---- the bilinear warp ------------------------------------------------------ */

/* x in [0, 1) of density proportional to (1 - x) a + x b (a, b >= 0, not
 * both 0), from u in [0, 1). The CDF's quadratic (b - a) x^2 / 2 + a x =
 * u (a + b) / 2 solved in the form that never divides by b - a:
 * x = u (a + b) / (a + sqrt((1 - u) a^2 + u b^2)). */
static inline PK_HD float sample_linear(float u, float a, float b)
{
    const float den = a + sph_sqrt((1.0f - u) * a * a + u * b * b);
    if (!(den > 0.0f)) return u;
    const float x = u * (a + b) / den;
    return x < 0x1.fffffep-1f ? x : 0x1.fffffep-1f;
}

/* Density on [0, 1]^2 of the bilinear patch of the corner weights w (w[0]
 * at (0, 0), w[1] at (1, 0), w[2] at (0, 1), w[3] at (1, 1); >= 0, not all 0). */
static inline PK_HD float bilinear_pdf(float x, float y, const float w[4])
{
    const float sum = w[0] + w[1] + w[2] + w[3];
    if (!(sum > 0.0f)) return 1.0f;
    return 4.0f * ((1.0f - x) * (1.0f - y) * w[0] + x * (1.0f - y) * w[1] + (1.0f - x) * y * w[2] + x * y * w[3]) / sum;
}

/* A point of density bilinear_pdf from (u0, u1): x from the marginal
 * (linear from w[0] + w[2] to w[1] + w[3]), then y given x. */
static inline PK_HD void sample_bilinear(float u0, float u1, const float w[4], float *x, float *y)
{
    *x = sample_linear(u0, w[0] + w[2], w[1] + w[3]);
    *y = sample_linear(u1, (1.0f - *x) * w[0] + *x * w[1], (1.0f - *x) * w[2] + *x * w[3]);
}

/* The warp's corner weights for a receiver of normal n (unit, or zero for
 * none): |cos| toward each corner direction of the map, at least 0.01 so
 * that no direction of the triangle gets density 0. */
static inline PK_HD void sph_tri_cos_weights(const sph_tri *t, vec3 n, float w[4])
{
    const float fa = fabsf(v3_dot(n, t->a)), fb = fabsf(v3_dot(n, t->b)), fc = fabsf(v3_dot(n, t->c));
    w[2] = fa > 0.01f ? fa : 0.01f;
    w[0] = w[1] = fb > 0.01f ? fb : 0.01f;
    w[3] = fc > 0.01f ? fc : 0.01f;
}

#endif
