/*
 * xform.h - affine transforms: a row-major 4x4 matrix whose last row is
 * 0 0 0 1, applied to column vectors (p' = M p), so that xform_mul(a, b)
 * applies b first, then a. Builders (translate, scale, rotate, look-at),
 * composition, inversion, and the three ways a transform acts: on points
 * (with the translation), on vectors (without) and on normals (by the
 * inverse transpose). Header only, as the rest of math/; the readers (OBJ,
 * JSON, Mitsuba XML and those to come) and the scene's instances share it.
 *
 * The operation order of each function is part of its contract: scenes were
 * rendered with these exact roundings before the readers shared them, and
 * images are compared byte for byte. Compiled with -ffp-contract=off.
 */
#ifndef PK_XFORM_H
#define PK_XFORM_H

#include "vec3.h"

#include <math.h>
#include <stdbool.h>

/* m[4 * row + col]; m[12..15] = 0 0 0 1 for every transform built here. */
typedef struct xform {
    float m[16];
} xform;

static inline xform xform_identity(void)
{
    xform x;
    for (int i = 0; i < 16; i++) x.m[i] = (i % 5 == 0) ? 1.0f : 0.0f;
    return x;
}

static inline xform xform_translate(vec3 d)
{
    xform x = xform_identity();
    x.m[3] = d.x, x.m[7] = d.y, x.m[11] = d.z;
    return x;
}

static inline xform xform_scale(vec3 s)
{
    xform x = xform_identity();
    x.m[0] = s.x, x.m[5] = s.y, x.m[10] = s.z;
    return x;
}

/* Right-handed rotation by deg degrees about axis, which must be of unit
 * length (the callers normalise it: how is theirs to choose). */
static inline xform xform_rotate(vec3 ax, float deg)
{
    xform x = xform_identity();
    float *r = x.m;
    float rad = deg * (PK_PI / 180.0f), c = cosf(rad), sn = sinf(rad), k = 1.0f - c;
    r[0] = k * ax.x * ax.x + c, r[1] = k * ax.x * ax.y - sn * ax.z, r[2] = k * ax.x * ax.z + sn * ax.y;
    r[4] = k * ax.x * ax.y + sn * ax.z, r[5] = k * ax.y * ax.y + c, r[6] = k * ax.y * ax.z - sn * ax.x;
    r[8] = k * ax.x * ax.z - sn * ax.y, r[9] = k * ax.y * ax.z + sn * ax.x, r[10] = k * ax.z * ax.z + c;
    return x;
}

typedef enum xform_lookat_status {
    XFORM_LOOKAT_OK,
    XFORM_LOOKAT_SAME_POINT, /* origin and target coincide (or are not finite) */
    XFORM_LOOKAT_BAD_UP      /* up is zero or parallel to the view direction */
} xform_lookat_status;

/* The camera-to-world transform of a camera at origin looking at target:
 * local +z is the view direction, +y up, +x left (Mitsuba's look-at). When
 * up is not given (has_up false; up should then be +y) and the view runs
 * along it, +z is used instead. *out is written only on XFORM_LOOKAT_OK. */
static inline xform_lookat_status xform_lookat(vec3 o, vec3 target, vec3 up, bool has_up, xform *out)
{
    vec3 dir = v3_sub(target, o);
    if (!(v3_len2(dir) > 0.0f) || !v3_finite(dir)) return XFORM_LOOKAT_SAME_POINT;
    dir = v3_norm_scaled(dir);
    vec3 left = v3_cross(v3_norm_scaled(up), dir);
    if (!(v3_len(left) > 1e-4f)) {
        if (has_up) return XFORM_LOOKAT_BAD_UP;
        left = v3_cross(v3(0.0f, 0.0f, 1.0f), dir); /* looking along y */
    }
    left = v3_norm(left);
    vec3 nup = v3_cross(dir, left);
    xform x = xform_identity();
    float *e = x.m;
    e[0] = left.x, e[4] = left.y, e[8] = left.z;
    e[1] = nup.x, e[5] = nup.y, e[9] = nup.z;
    e[2] = dir.x, e[6] = dir.y, e[10] = dir.z;
    e[3] = o.x, e[7] = o.y, e[11] = o.z;
    *out = x;
    return XFORM_LOOKAT_OK;
}

/* a b (b applied first): each entry summed in double, rounded once. */
static inline xform xform_mul(const xform *a, const xform *b)
{
    double r[16];
    for (int i = 0; i < 4; i++)
        for (int j = 0; j < 4; j++) {
            double sum = 0.0;
            for (int k = 0; k < 4; k++) sum += (double)a->m[i * 4 + k] * (double)b->m[k * 4 + j];
            r[i * 4 + j] = sum;
        }
    xform x;
    for (int i = 0; i < 16; i++) x.m[i] = (float)r[i];
    return x;
}

/* The determinant of the linear (upper left 3x3) part, in double. */
static inline double xform_det3(const xform *x)
{
    const float *m = x->m;
    double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9], i = m[10];
    return a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g);
}

static inline bool xform_finite(const xform *x)
{
    for (int i = 0; i < 16; i++)
        if (!isfinite(x->m[i])) return false;
    return true;
}

/* The last row is 0 0 0 1 (not projective). */
static inline bool xform_is_affine(const xform *x)
{
    return x->m[12] == 0.0f && x->m[13] == 0.0f && x->m[14] == 0.0f && x->m[15] == 1.0f;
}

/* The inverse of an affine transform, computed in double (adjugate over the
 * determinant) and rounded once. False, *out untouched, when the linear part
 * is singular or the result is not finite. */
static inline bool xform_invert(const xform *x, xform *out)
{
    const float *m = x->m;
    double a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9], i = m[10];
    double det = xform_det3(x);
    if (!(det != 0.0) || !isfinite(det)) return false;
    double inv[9] = {(e * i - f * h) / det, (c * h - b * i) / det, (b * f - c * e) / det,
                     (f * g - d * i) / det, (a * i - c * g) / det, (c * d - a * f) / det,
                     (d * h - e * g) / det, (b * g - a * h) / det, (a * e - b * d) / det};
    double t[3] = {m[3], m[7], m[11]};
    xform r = xform_identity();
    for (int row = 0; row < 3; row++) {
        for (int col = 0; col < 3; col++) r.m[4 * row + col] = (float)inv[3 * row + col];
        r.m[4 * row + 3] = (float)-(inv[3 * row] * t[0] + inv[3 * row + 1] * t[1] + inv[3 * row + 2] * t[2]);
    }
    if (!xform_finite(&r)) return false;
    *out = r;
    return true;
}

/* M p (with the translation), in float, left to right. */
static inline PK_HD vec3 xform_point(const xform *x, vec3 p)
{
    const float *m = x->m;
    return v3(m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
              m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]);
}

/* M v without the translation (directions, tangents). */
static inline PK_HD vec3 xform_vector(const xform *x, vec3 d)
{
    const float *m = x->m;
    return v3(m[0] * d.x + m[1] * d.y + m[2] * d.z, m[4] * d.x + m[5] * d.y + m[6] * d.z,
              m[8] * d.x + m[9] * d.y + m[10] * d.z);
}

/* ---- normals: the inverse transpose of the linear part, up to a positive
 * scale (normals are renormalised after), so that a mirroring transform
 * turns them as it turns the surface. Two roundings of the same matrix
 * exist because scenes were rendered with both: ---- */

/* Cofactors computed in double, divided by the largest one (in float
 * range for any finite transform), the sign of the determinant applied
 * (the OBJ loader's). False when the transform is singular. */
static inline bool xform_normal_matrix(const xform *x, float nm[9])
{
    const float *m = x->m;
    double a = (double)m[0], b = (double)m[1], c = (double)m[2];
    double d = (double)m[4], e = (double)m[5], f = (double)m[6];
    double g = (double)m[8], h = (double)m[9], i = (double)m[10];
    double cof[9] = {e * i - f * h, f * g - d * i, d * h - e * g, c * h - b * i, a * i - c * g,
                     b * g - a * h, b * f - c * e, c * d - a * f, a * e - b * d};
    double det = a * cof[0] + b * cof[1] + c * cof[2];
    if (!(fabs(det) > 0.0) || !isfinite(det)) return false;
    double big = 0.0;
    for (int k = 0; k < 9; k++) big = fmax(big, fabs(cof[k]));
    double scale = (det < 0.0 ? -1.0 : 1.0) / big;
    for (int k = 0; k < 9; k++) nm[k] = (float)(cof[k] * scale);
    return true;
}

/* Cofactors computed in float, the sign of the determinant applied (the
 * Mitsuba XML reader's; its meshes' normals are rounded this way). */
static inline void xform_normal_cofactors(const xform *x, float nm[9])
{
    const float *m = x->m;
    const float a = m[0], b = m[1], c = m[2], d = m[4], e = m[5], f = m[6], g = m[8], h = m[9], i = m[10];
    const float cf[9] = {e * i - f * h, f * g - d * i, d * h - e * g, c * h - b * i, a * i - c * g,
                         b * g - a * h, b * f - c * e, c * d - a * f, a * e - b * d};
    float sign = xform_det3(x) < 0.0 ? -1.0f : 1.0f;
    for (int k = 0; k < 9; k++) nm[k] = sign * cf[k];
}

/* nm n: a normal through a matrix from xform_normal_matrix or
 * xform_normal_cofactors (not normalised). */
static inline PK_HD vec3 xform_apply3(const float nm[9], vec3 n)
{
    return v3(nm[0] * n.x + nm[1] * n.y + nm[2] * n.z, nm[3] * n.x + nm[4] * n.y + nm[5] * n.z,
              nm[6] * n.x + nm[7] * n.y + nm[8] * n.z);
}

#endif
