/*
 * test_render.c - renders the built-in Cornell box small and checks what
 * must hold: the left wall is red and the right wall green, the light is the
 * brightest region, no NaN or infinite pixels, the same image for 1 and 2
 * threads and for every accelerator, and the statistics add up.
 */
#include "test.h"

#include "paprsek.h"

static pk_context *ctx;

static pk_image *render(const pk_scene *s, int threads, pk_accel_kind accel, int size, pk_stats *st)
{
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = o.height = size;
    o.threads = threads;
    o.accel = accel;
    o.light_samples = 8;
    o.collect_stats = st != NULL;
    pk_image *img = NULL;
    pk_status rc = pk_render(ctx, s, &o, &img, st);
    CHECKF(rc == PK_OK, "%s", pk_context_error(ctx));
    REQUIRE(img);
    return img;
}

/* Mean colour of the rectangle [x0,x1) x [y0,y1) given in fractions of the image. */
static void region_mean(const pk_image *img, float x0, float y0, float x1, float y1, double m[3])
{
    int w = pk_image_width(img), h = pk_image_height(img);
    const float *p = pk_image_pixels_const(img);
    m[0] = m[1] = m[2] = 0;
    int n = 0;
    for (int y = (int)(y0 * (float)h); y < (int)(y1 * (float)h); y++)
        for (int x = (int)(x0 * (float)w); x < (int)(x1 * (float)w); x++, n++)
            for (int c = 0; c < 3; c++) m[c] += (double)p[3 * ((size_t)y * (size_t)w + (size_t)x) + c];
    for (int c = 0; c < 3; c++) m[c] /= n ? n : 1;
}

static int same_image(const pk_image *a, const pk_image *b)
{
    size_t n = (size_t)pk_image_width(a) * (size_t)pk_image_height(a) * 3;
    return pk_image_width(a) == pk_image_width(b) && pk_image_height(a) == pk_image_height(b) &&
           memcmp(pk_image_pixels_const(a), pk_image_pixels_const(b), n * sizeof(float)) == 0;
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_create_cornell_box(ctx, &s) == PK_OK);
    const int size = 64;
    pk_stats st;
    pk_image *img = render(s, 2, PK_ACCEL_DEFAULT, size, &st);

    /* finite, non-negative, not black */
    const float *p = pk_image_pixels_const(img);
    size_t n = (size_t)size * size * 3, bad = 0;
    double sum = 0;
    for (size_t i = 0; i < n; i++) {
        if (!isfinite(p[i]) || p[i] < 0.0f) bad++;
        sum += (double)p[i];
    }
    CHECKF(bad == 0, "%zu NaN, infinite or negative values", bad);
    CHECK(sum / (double)n > 0.02);

    /* walls: red on the left, green on the right (middle height, outer strips) */
    double left[3], right[3], top[3], floor_[3];
    region_mean(img, 0.02f, 0.35f, 0.10f, 0.65f, left);
    region_mean(img, 0.90f, 0.35f, 0.98f, 0.65f, right);
    CHECKF(left[0] > 2 * left[1] && left[0] > 2 * left[2], "left wall not red: %g %g %g", left[0], left[1], left[2]);
    CHECKF(right[1] > 1.5 * right[0] && right[1] > 1.5 * right[2], "right wall not green: %g %g %g", right[0],
           right[1], right[2]);

    /* the light: the brightest pixel is in the top part of the image, near the middle */
    int w = pk_image_width(img), best = 0;
    float bestv = -1;
    for (int i = 0; i < size * size; i++) {
        float v = p[3 * i] + p[3 * i + 1] + p[3 * i + 2];
        if (v > bestv) {
            bestv = v;
            best = i;
        }
    }
    int bx = best % w, by = best / w;
    CHECKF(by < size / 4 && bx > size / 4 && bx < 3 * size / 4, "brightest pixel at %d,%d", bx, by);
    region_mean(img, 0.3f, 0.0f, 0.7f, 0.1f, top);
    region_mean(img, 0.3f, 0.9f, 0.7f, 1.0f, floor_);
    CHECK(top[0] + top[1] + top[2] > 0.0);
    CHECK(floor_[0] + floor_[1] + floor_[2] > 0.0); /* the floor is lit */

    /* statistics add up */
    CHECK(st.rays_camera == (uint64_t)size * size);
    CHECK(st.rays_shadow > st.rays_camera);
    CHECK(st.intersection_tests > 0 && st.nodes_visited > 0);
    CHECK(st.render_s > 0.0 && st.build_us >= 0.0 && st.threads == 2);

    /* bit-identical for 1 and 2 threads, and for every accelerator */
    pk_image *one = render(s, 1, PK_ACCEL_DEFAULT, size, NULL);
    CHECK(same_image(img, one));
    pk_accel_kind kinds[] = {PK_ACCEL_NONE, PK_ACCEL_MIDPOINT, PK_ACCEL_BVH};
    for (size_t k = 0; k < sizeof kinds / sizeof kinds[0]; k++) {
        pk_image *other = render(s, 2, kinds[k], size, NULL);
        CHECKF(same_image(img, other), "--accel %s gives a different image", pk_accel_kind_name(kinds[k]));
        pk_image_destroy(other);
    }
    /* statistics off changes nothing in the image */
    pk_image_destroy(one);
    pk_image_destroy(img);
    pk_scene_destroy(s);
    pk_context_destroy(ctx);
    return test_done("test_render");
}
