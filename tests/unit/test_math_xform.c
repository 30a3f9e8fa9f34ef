/*
 * test_math_xform.c - math/xform.h against hand-computed values: builders,
 * composition order, inversion, points, vectors and normals (the inverse
 * transpose, also under a mirroring transform), look-at.
 */
#include "test.h"

#include "math/xform.h"

#define CHECK_V3(v, X, Y, Z, tol)                                                                               \
    do {                                                                                                         \
        vec3 v_ = (v);                                                                                           \
        CHECK_NEAR(v_.x, (X), (tol));                                                                            \
        CHECK_NEAR(v_.y, (Y), (tol));                                                                            \
        CHECK_NEAR(v_.z, (Z), (tol));                                                                            \
    } while (0)

static void test_builders(void)
{
    xform i = xform_identity();
    for (int k = 0; k < 16; k++) CHECK(i.m[k] == (k % 5 == 0 ? 1.0f : 0.0f));
    CHECK(xform_is_affine(&i) && xform_finite(&i));

    xform t = xform_translate(v3(1, 2, 3));
    CHECK_V3(xform_point(&t, v3(1, 1, 1)), 2, 3, 4, 0);
    CHECK_V3(xform_vector(&t, v3(1, 1, 1)), 1, 1, 1, 0); /* vectors ignore the translation */

    xform s = xform_scale(v3(2, 3, 4));
    CHECK_V3(xform_point(&s, v3(1, 1, 1)), 2, 3, 4, 0);
    CHECK(xform_det3(&s) == 24.0);

    /* 90 degrees about +z: x -> y, y -> -x (right-handed) */
    xform r = xform_rotate(v3(0, 0, 1), 90.0f);
    CHECK_V3(xform_point(&r, v3(1, 0, 0)), 0, 1, 0, 1e-7);
    CHECK_V3(xform_point(&r, v3(0, 1, 0)), -1, 0, 0, 1e-7);
    CHECK_NEAR(xform_det3(&r), 1.0, 1e-6);
    /* 120 degrees about (1,1,1)/sqrt(3) cycles the axes: x -> y -> z -> x */
    float k = 1.0f / sqrtf(3.0f);
    xform c = xform_rotate(v3(k, k, k), 120.0f);
    CHECK_V3(xform_point(&c, v3(1, 0, 0)), 0, 1, 0, 1e-6);
    CHECK_V3(xform_point(&c, v3(0, 0, 1)), 1, 0, 0, 1e-6);
}

static void test_compose_invert(void)
{
    /* xform_mul(a, b) applies b first: translate after scale */
    xform t = xform_translate(v3(1, 0, 0)), s = xform_scale(v3s(2.0f));
    xform ts = xform_mul(&t, &s), st = xform_mul(&s, &t);
    CHECK_V3(xform_point(&ts, v3(1, 1, 1)), 3, 2, 2, 0);
    CHECK_V3(xform_point(&st, v3(1, 1, 1)), 4, 2, 2, 0);
    CHECK(ts.m[3] == 1.0f && st.m[3] == 2.0f);
    CHECK(xform_is_affine(&ts));

    /* M = T(1,2,3) R_z(90) S(2,1,1): inverse by hand = S(1/2,1,1) R_z(-90) T(-1,-2,-3) */
    xform r = xform_rotate(v3(0, 0, 1), 90.0f), s2 = xform_scale(v3(2, 1, 1)), tr = xform_translate(v3(1, 2, 3));
    xform rs = xform_mul(&r, &s2), m = xform_mul(&tr, &rs), inv;
    REQUIRE(xform_invert(&m, &inv));
    /* M (1,0,0) = R (2,0,0) + t = (0,2,0) + (1,2,3) */
    CHECK_V3(xform_point(&m, v3(1, 0, 0)), 1, 4, 3, 1e-6);
    CHECK_V3(xform_point(&inv, v3(1, 4, 3)), 1, 0, 0, 1e-6);
    /* the linear part of the inverse: rows (0, 1/2, 0), (-1, 0, 0), (0, 0, 1) */
    const float want[12] = {0, 0.5f, 0, -1, -1, 0, 0, 1, 0, 0, 1, -3};
    for (int q = 0; q < 12; q++) CHECK_NEAR(inv.m[q], want[q], 1e-6);
    CHECK(inv.m[12] == 0.0f && inv.m[13] == 0.0f && inv.m[14] == 0.0f && inv.m[15] == 1.0f);
    xform id = xform_mul(&m, &inv);
    for (int q = 0; q < 16; q++) CHECK_NEAR(id.m[q], q % 5 == 0 ? 1.0 : 0.0, 1e-6);

    xform flat = xform_scale(v3(1, 0, 1)), untouched = xform_identity();
    CHECK(!xform_invert(&flat, &untouched));
    CHECK(untouched.m[0] == 1.0f && untouched.m[5] == 1.0f);
}

static void test_normals(void)
{
    /* scale (2, 1, -1): inverse transpose diag(1/2, 1, -1); det < 0 so the
     * normal matrix is (up to a positive factor) that, and (1,1,0) maps to
     * (1/2, 1, 0)/|.| */
    xform m = xform_scale(v3(2, 1, -1));
    float nm[9], cf[9];
    REQUIRE(xform_normal_matrix(&m, nm));
    xform_normal_cofactors(&m, cf);
    vec3 a = v3_norm(xform_apply3(nm, v3(1, 1, 0))), b = v3_norm(xform_apply3(cf, v3(1, 1, 0)));
    CHECK_V3(a, 0.5 / sqrt(1.25), 1.0 / sqrt(1.25), 0, 1e-6);
    CHECK_V3(b, 0.5 / sqrt(1.25), 1.0 / sqrt(1.25), 0, 1e-6);
    CHECK_V3(v3_norm(xform_apply3(nm, v3(0, 0, 1))), 0, 0, -1, 1e-7);
    /* the largest entry of xform_normal_matrix is 1 in magnitude */
    float big = 0.0f;
    for (int q = 0; q < 9; q++) big = fmaxf(big, fabsf(nm[q]));
    CHECK(big == 1.0f);

    /* a shear: the normal of the plane y = 0 stays perpendicular to the
     * sheared plane's tangents */
    xform sh = xform_identity();
    sh.m[1] = 1.0f; /* x += y */
    sh.m[4] = 0.5f; /* y += x / 2 */
    REQUIRE(xform_normal_matrix(&sh, nm));
    vec3 n = xform_apply3(nm, v3(0, 1, 0));
    vec3 t1 = xform_vector(&sh, v3(1, 0, 0)), t2 = xform_vector(&sh, v3(0, 0, 1));
    CHECK_NEAR(v3_dot(n, t1), 0.0, 1e-6);
    CHECK_NEAR(v3_dot(n, t2), 0.0, 1e-6);

    /* rotations carry normals as they carry vectors */
    xform r = xform_rotate(v3(0, 0, 1), 90.0f);
    REQUIRE(xform_normal_matrix(&r, nm));
    CHECK_V3(v3_norm(xform_apply3(nm, v3(1, 0, 0))), 0, 1, 0, 1e-6);

    xform flat = xform_scale(v3(1, 1, 0));
    CHECK(!xform_normal_matrix(&flat, nm));
}

static void test_lookat(void)
{
    xform m;
    CHECK(xform_lookat(v3(0, 0, 5), v3(0, 0, 0), v3(0, 1, 0), true, &m) == XFORM_LOOKAT_OK);
    CHECK_V3(xform_point(&m, v3s(0.0f)), 0, 0, 5, 0);
    CHECK_V3(xform_vector(&m, v3(0, 0, 1)), 0, 0, -1, 1e-7); /* +z: the view direction */
    CHECK_V3(xform_vector(&m, v3(0, 1, 0)), 0, 1, 0, 1e-7);  /* +y: up */
    CHECK_V3(xform_vector(&m, v3(1, 0, 0)), -1, 0, 0, 1e-7); /* +x: left, seen looking along -z */
    CHECK(xform_lookat(v3s(1.0f), v3s(1.0f), v3(0, 1, 0), true, &m) == XFORM_LOOKAT_SAME_POINT);
    CHECK(xform_lookat(v3s(0.0f), v3(0, 2, 0), v3(0, 1, 0), true, &m) == XFORM_LOOKAT_BAD_UP);
    /* without an explicit up, looking along y falls back to +z as up */
    CHECK(xform_lookat(v3s(0.0f), v3(0, 2, 0), v3(0, 1, 0), false, &m) == XFORM_LOOKAT_OK);
    CHECK_V3(xform_vector(&m, v3(0, 0, 1)), 0, 1, 0, 1e-7);
}

int main(void)
{
    test_builders();
    test_compose_invert();
    test_normals();
    test_lookat();
    return test_done("test_math_xform");
}
