/*
 * test_session.c - render sessions and films through the public header:
 * any tiling of the image into regions, rendered in one call or in many and
 * merged in any order, equals the one-call render byte for byte; films merge
 * exactly; one renderer serves two cameras with one build; the progress
 * callback is monotone, comes from the calling thread, ends with completion
 * and can cancel.
 */
#include "test.h"

#include "paprsek.h"

#include <pthread.h>
#include <stdbool.h>
#include <stdint.h>

static pk_context *ctx;

typedef struct lcg {
    uint64_t s;
} lcg;
static uint32_t next_u32(lcg *g)
{
    g->s = g->s * 6364136223846793005ull + 1442695040888963407ull;
    return (uint32_t)(g->s >> 33);
}
static int rand_int(lcg *g, int n) { return (int)(next_u32(g) % (uint32_t)n); }

/* A random partition of rect by guillotine cuts into out[n..], which ends at
 * out[max - 1]; returns the new n. */
static size_t cut(lcg *g, pk_region rect, pk_region *out, size_t n, size_t max)
{
    if (n + 1 >= max || (rect.width < 2 && rect.height < 2) || rand_int(g, 5) == 0) {
        out[n] = rect;
        return n + 1;
    }
    pk_region a = rect, b = rect;
    bool vertical = rect.height < 2 || (rect.width >= 2 && rand_int(g, 2));
    if (vertical) {
        a.width = 1 + rand_int(g, rect.width - 1);
        b.x = rect.x + a.width;
        b.width = rect.width - a.width;
    } else {
        a.height = 1 + rand_int(g, rect.height - 1);
        b.y = rect.y + a.height;
        b.height = rect.height - a.height;
    }
    n = cut(g, a, out, n, max - 1); /* one slot stays for b */
    return cut(g, b, out, n, max);
}

static bool same_bytes(const void *a, const void *b, size_t n) { return memcmp(a, b, n) == 0; }

static bool same_image(const pk_image *a, const pk_image *b)
{
    return pk_image_width(a) == pk_image_width(b) && pk_image_height(a) == pk_image_height(b) &&
           same_bytes(pk_image_pixels_const(a), pk_image_pixels_const(b),
                      sizeof(float) * 3 * (size_t)pk_image_width(a) * (size_t)pk_image_height(a));
}

static bool same_film(pk_film *a, pk_film *b)
{
    size_t n = (size_t)pk_film_width(a) * (size_t)pk_film_height(a);
    return pk_film_width(a) == pk_film_width(b) && pk_film_height(a) == pk_film_height(b) &&
           same_bytes(pk_film_sums(a), pk_film_sums(b), n * 3 * sizeof(float)) &&
           same_bytes(pk_film_counts(a), pk_film_counts(b), n * sizeof(uint32_t));
}

static pk_image *resolve(pk_film *f)
{
    pk_image *img = NULL;
    REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK);
    return img;
}

static pk_scene *load(const char *what)
{
    pk_scene *s = NULL;
    pk_status st = what ? pk_scene_load_file(ctx, what, &s) : pk_scene_create_cornell_box(ctx, &s);
    REQUIRE(st == PK_OK);
    return s;
}

/* ---- tilings ---------------------------------------------------------------- */

static void check_tilings(const pk_scene *s, const char *name, int w, int h)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = w;
    o.height = h;
    o.spp = 3;
    o.light_samples = 4;
    o.threads = 2;
    pk_image *whole = NULL;
    pk_stats st;
    REQUIRE(pk_render(ctx, s, &o, &whole, &st) == PK_OK);
    CHECKF(st.accel_builds == 1 && st.pixels == (uint64_t)w * (uint64_t)h, "%s: builds %d pixels %llu", name,
           st.accel_builds, (unsigned long long)st.pixels);
    const float *px = pk_image_pixels_const(whole);
    double sum = 0.0;
    for (size_t i = 0; i < 3 * (size_t)w * (size_t)h; i++) sum += (double)px[i];
    CHECKF(sum > 0.0, "%s: the reference image is black", name);

    lcg g = {0x9e3779b97f4a7c15ull ^ (uint64_t)w};
    enum { MAXR = 64 };
    pk_region reg[MAXR];
    for (int trial = 0; trial < 6; trial++) {
        const size_t n = cut(&g, (pk_region){0, 0, w, h}, reg, 0, MAXR);
        o.threads = 1 + trial % 3;
        pk_renderer *r = NULL;
        REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
        /* (a) all regions in one call */
        pk_film *one = NULL;
        REQUIRE(pk_film_create(ctx, w, h, &one) == PK_OK);
        CHECK(pk_renderer_render(r, reg, n, one) == PK_OK);
        pk_image *img = resolve(one);
        CHECKF(same_image(img, whole), "%s: %zu regions in one call (%d threads) differ from one render", name, n,
               o.threads);
        pk_image_destroy(img);
        /* (b) each region in its own film, merged in a random order and grouping */
        pk_film *films[MAXR];
        for (size_t i = 0; i < n; i++) {
            REQUIRE(pk_film_create(ctx, w, h, &films[i]) == PK_OK);
            CHECK(pk_renderer_render(r, &reg[i], 1, films[i]) == PK_OK);
        }
        size_t live = n;
        while (live > 1) { /* merge two random films until one is left */
            size_t a = (size_t)rand_int(&g, (int)live), b = (size_t)rand_int(&g, (int)live - 1);
            if (b >= a) b++;
            CHECK(pk_film_merge(ctx, films[a], films[b]) == PK_OK);
            pk_film_destroy(films[b]);
            films[b] = films[--live];
        }
        CHECKF(same_film(films[0], one), "%s: %zu films merged differ from one film", name, n);
        img = resolve(films[0]);
        CHECKF(same_image(img, whole), "%s: %zu merged films differ from one render", name, n);
        pk_image_destroy(img);
        pk_film_destroy(films[0]);
        pk_stats rs;
        pk_renderer_get_stats(r, &rs);
        CHECKF(rs.accel_builds == 1 && rs.pixels == 2 * (uint64_t)w * (uint64_t)h,
               "%s: a renderer used twice reports %d builds, %llu pixels", name, rs.accel_builds,
               (unsigned long long)rs.pixels);
        /* (c) the whole image twice into one film: twice the sums and counts, the same mean */
        pk_film *twice = NULL;
        REQUIRE(pk_film_create(ctx, w, h, &twice) == PK_OK);
        CHECK(pk_renderer_render(r, NULL, 0, twice) == PK_OK);
        CHECK(pk_renderer_render(r, NULL, 0, twice) == PK_OK);
        CHECK(pk_film_counts(twice)[0] == 2u * (uint32_t)o.spp);
        img = resolve(twice);
        CHECKF(same_image(img, whole), "%s: two passes differ from one", name);
        pk_image_destroy(img);
        pk_film_destroy(twice);
        pk_film_destroy(one);
        pk_renderer_destroy(r);
    }
    pk_image_destroy(whole);
}

/* (A + B) + C, A + (B + C) and C + A + B are the same bits. */
static void check_merge_order(const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 40;
    o.height = 30;
    o.spp = 2;
    o.light_samples = 2;
    pk_renderer *r = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    const pk_region parts[3][2] = {{{0, 0, 40, 10}, {0, 20, 7, 10}}, {{0, 10, 40, 10}, {7, 20, 20, 10}},
                                   {{27, 20, 13, 10}, {0, 0, 0, 0}}};
    const size_t nparts[3] = {2, 2, 1};
    pk_film *f[3][3]; /* three copies of A, B and C */
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++) {
            REQUIRE(pk_film_create(ctx, 40, 30, &f[c][k]) == PK_OK);
            CHECK(pk_renderer_render(r, parts[k], nparts[k], f[c][k]) == PK_OK);
        }
    /* (A + B) + C */
    CHECK(pk_film_merge(ctx, f[0][0], f[0][1]) == PK_OK);
    CHECK(pk_film_merge(ctx, f[0][0], f[0][2]) == PK_OK);
    /* A + (B + C) */
    CHECK(pk_film_merge(ctx, f[1][1], f[1][2]) == PK_OK);
    CHECK(pk_film_merge(ctx, f[1][0], f[1][1]) == PK_OK);
    /* C + A + B */
    CHECK(pk_film_merge(ctx, f[2][2], f[2][0]) == PK_OK);
    CHECK(pk_film_merge(ctx, f[2][2], f[2][1]) == PK_OK);
    CHECK(same_film(f[0][0], f[1][0]));
    CHECK(same_film(f[0][0], f[2][2]));
    for (size_t i = 0; i < 40 * 30; i++) CHECK(pk_film_counts(f[0][0])[i] == 2u);
    /* merging films of different sizes is refused */
    pk_film *small = NULL;
    REQUIRE(pk_film_create(ctx, 4, 4, &small) == PK_OK);
    CHECK(pk_film_merge(ctx, f[0][0], small) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "cannot merge a 4x4 film into a 40x30 film") != NULL);
    pk_context_clear_error(ctx);
    /* a film of the wrong size, and bad regions, are refused before any work */
    CHECK(pk_renderer_render(r, NULL, 0, small) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    const pk_region bad[] = {{-1, 0, 4, 4}, {38, 0, 4, 4}, {0, 0, 0, 5}, {0, 28, 4, 3}};
    for (size_t i = 0; i < sizeof bad / sizeof bad[0]; i++) {
        CHECK(pk_renderer_render(r, &bad[i], 1, f[0][0]) == PK_ERR_INVALID_ARGUMENT);
        CHECK(strstr(pk_context_error(ctx), "not inside the 40x30 image") != NULL);
        pk_context_clear_error(ctx);
    }
    const pk_region overlap[] = {{0, 0, 10, 10}, {20, 20, 5, 5}, {9, 9, 2, 2}};
    CHECK(pk_renderer_render(r, overlap, 3, f[0][0]) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strcmp(pk_context_error(ctx), "regions 0 and 2 overlap") == 0);
    pk_context_clear_error(ctx);
    pk_film_destroy(small);
    for (int k = 0; k < 3; k++)
        for (int c = 0; c < 3; c++) pk_film_destroy(f[c][k]);
    pk_renderer_destroy(r);
}

/* ---- one build, two cameras --------------------------------------------------- */

static void check_cameras(void)
{
    pk_scene *s = load(NULL), *s2 = load(NULL);
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 48;
    o.height = 40;
    o.light_samples = 4;
    o.collect_stats = 1;
    pk_renderer *r = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    pk_stats st0;
    pk_renderer_get_stats(r, &st0);
    CHECK(st0.accel_builds == 1 && st0.build_us > 0.0 && st0.rays_camera == 0);
    pk_camera c1, c2;
    pk_renderer_get_camera(r, &c1);
    c2 = c1;
    c2.look_from[0] += 0.3f;
    c2.fov_deg = 30.0f;
    pk_film *f1 = NULL, *f2 = NULL;
    REQUIRE(pk_film_create(ctx, 48, 40, &f1) == PK_OK && pk_film_create(ctx, 48, 40, &f2) == PK_OK);
    CHECK(pk_renderer_render(r, NULL, 0, f1) == PK_OK);
    CHECK(pk_renderer_set_camera(r, &c2) == PK_OK);
    CHECK(pk_renderer_render(r, NULL, 0, f2) == PK_OK);
    pk_stats st;
    pk_renderer_get_stats(r, &st);
    CHECKF(st.accel_builds == 1 && st.build_us == st0.build_us, "two cameras: %d builds, build %.1f then %.1f us",
           st.accel_builds, st0.build_us, st.build_us);
    CHECK(st.rays_camera == 2u * 48u * 40u);
    /* each equals a one-call render of a scene with that camera */
    pk_image *a = resolve(f1), *b = resolve(f2), *ref1 = NULL, *ref2 = NULL;
    REQUIRE(pk_render(ctx, s, &o, &ref1, NULL) == PK_OK);
    REQUIRE(pk_scene_set_camera(ctx, s2, &c2) == PK_OK);
    REQUIRE(pk_render(ctx, s2, &o, &ref2, NULL) == PK_OK);
    CHECK(same_image(a, ref1));
    CHECK(same_image(b, ref2));
    CHECK(!same_image(a, b));
    /* a bad camera is refused and the old one kept */
    pk_camera bad = c2;
    bad.fov_deg = 180.0f;
    CHECK(pk_renderer_set_camera(r, &bad) == PK_ERR_INVALID_ARGUMENT);
    pk_context_clear_error(ctx);
    pk_camera now;
    pk_renderer_get_camera(r, &now);
    CHECK(memcmp(&now, &c2, sizeof now) == 0);
    pk_image_destroy(a), pk_image_destroy(b), pk_image_destroy(ref1), pk_image_destroy(ref2);
    pk_film_destroy(f1), pk_film_destroy(f2);
    pk_renderer_destroy(r);
    pk_scene_destroy(s), pk_scene_destroy(s2);
}

/* ---- progress ------------------------------------------------------------------------- */

typedef struct progress_log {
    pthread_t caller;
    int calls, bad_thread, not_monotone;
    uint64_t last_done, total;
    double last_elapsed;
    int cancel_at_call; /* return 1 at this call (0: never) */
    int cancel_when_done; /* return 1 at the first call with done > 0 */
} progress_log;

static int on_progress(void *user, uint64_t done, uint64_t total, double elapsed)
{
    progress_log *p = user;
    p->calls++;
    if (!pthread_equal(pthread_self(), p->caller)) p->bad_thread++;
    if (p->calls > 1 && (done < p->last_done || total != p->total || elapsed < p->last_elapsed)) p->not_monotone++;
    if (done > total) p->not_monotone++;
    p->last_done = done;
    p->total = total;
    p->last_elapsed = elapsed;
    if (p->cancel_at_call && p->calls == p->cancel_at_call) return 1;
    if (p->cancel_when_done && done > 0) return 1;
    return 0;
}

static void check_progress(const pk_scene *s)
{
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 160;
    o.height = 120;
    o.spp = 4;
    o.light_samples = 16;
    o.threads = 2;
    o.progress = on_progress;
    progress_log log = {pthread_self(), 0, 0, 0, 0, 0, 0.0, 0, 0};
    o.progress_user = &log;
    pk_image *img = NULL, *ref = NULL;
    pk_stats st;
    REQUIRE(pk_render(ctx, s, &o, &img, &st) == PK_OK);
    const uint64_t tiles = (uint64_t)((160 + 15) / 16) * (uint64_t)((120 + 15) / 16);
    CHECKF(log.calls >= 2 && log.total == tiles && log.last_done == tiles, "%d calls, last %llu of %llu", log.calls,
           (unsigned long long)log.last_done, (unsigned long long)log.total);
    CHECK(log.bad_thread == 0 && log.not_monotone == 0);
    /* a few times a second: the start, one every 0.25 s at most, the end */
    CHECKF(log.calls <= 2 + (int)(st.render_s / 0.25) + 1, "%d calls in %.2f s", log.calls, st.render_s);
    o.progress = NULL;
    REQUIRE(pk_render(ctx, s, &o, &ref, NULL) == PK_OK);
    CHECK(same_image(img, ref)); /* a callback changes nothing */
    pk_image_destroy(img), pk_image_destroy(ref);

    /* cancelled at the first report: nothing rendered, status CANCELLED, black image */
    o.progress = on_progress;
    log = (progress_log){pthread_self(), 0, 0, 0, 0, 0, 0.0, 1, 0};
    CHECK(pk_render(ctx, s, &o, &img, NULL) == PK_ERR_CANCELLED);
    CHECK(strcmp(pk_context_error(ctx), "render cancelled") == 0);
    pk_context_clear_error(ctx);
    REQUIRE(img);
    const float *px = pk_image_pixels_const(img);
    double sum = 0.0;
    for (size_t i = 0; i < 3u * 160u * 120u; i++) sum += (double)px[i];
    CHECK(sum == 0.0);
    CHECK(log.last_done == 0 && log.calls == 2);
    pk_image_destroy(img);

    /* cancelled at the first report of finished work, in a render long enough
     * to report (1 thread, many samples): some tiles and not all */
    o.threads = 1;
    o.spp = 64;
    o.width = 320;
    o.height = 240;
    log = (progress_log){pthread_self(), 0, 0, 0, 0, 0, 0.0, 0, 1};
    pk_renderer *r = NULL;
    pk_film *film = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create(ctx, 320, 240, &film) == PK_OK);
    pk_status rs = pk_renderer_render(r, NULL, 0, film);
    size_t with = 0;
    for (size_t i = 0; i < 320u * 240u; i++) with += pk_film_counts(film)[i] != 0;
    if (log.calls > 2 || rs == PK_ERR_CANCELLED) {
        CHECKF(rs == PK_ERR_CANCELLED && with > 0 && with < 320u * 240u && with % 256 == 0,
               "cancelled mid-render: status %d, %zu pixels with samples", (int)rs, with);
    } else {
        printf("note: the render finished before its first report; mid-render cancel not exercised\n");
    }
    pk_context_clear_error(ctx);
    pk_film_destroy(film);
    pk_renderer_destroy(r);
}

/* The pixel angle (how far texture lookups are filtered) follows the camera:
 * a renderer whose camera narrows its field of view renders a finely
 * textured scene as a renderer built with that camera does. And
 * pk_camera_init's camera is the documented one and a valid one. */
static void check_camera_textures(void)
{
    pk_camera d;
    memset(&d, 0x7f, sizeof d);
    pk_camera_init(&d);
    CHECK(d.look_from[0] == 0.0f && d.look_from[1] == 0.0f && d.look_from[2] == 0.0f);
    CHECK(d.look_at[0] == 0.0f && d.look_at[1] == 0.0f && d.look_at[2] == -1.0f);
    CHECK(d.up[0] == 0.0f && d.up[1] == 1.0f && d.up[2] == 0.0f && d.fov_deg == 45.0f);

    pk_scene *s = load(PK_TEST_DATA "/tex_json.json"), *s2 = load(PK_TEST_DATA "/tex_json.json");
    pk_render_options o;
    pk_render_options_init(&o);
    o.width = 40;
    o.height = 30;
    o.spp = 2;
    o.threads = 2;
    pk_renderer *r = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    pk_camera c;
    pk_renderer_get_camera(r, &c);
    c.fov_deg = 8.0f; /* a pixel a fifth as wide: sharper lookups of the fine checker */
    REQUIRE(pk_renderer_set_camera(r, &c) == PK_OK);
    pk_film *f = NULL;
    REQUIRE(pk_film_create(ctx, 40, 30, &f) == PK_OK);
    CHECK(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    pk_image *a = resolve(f), *ref = NULL;
    REQUIRE(pk_scene_set_camera(ctx, s2, &c) == PK_OK);
    REQUIRE(pk_render(ctx, s2, &o, &ref, NULL) == PK_OK);
    CHECKF(same_image(a, ref), "a renderer given a narrower camera differs from one built with it");
    pk_image_destroy(a), pk_image_destroy(ref);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
    pk_scene_destroy(s), pk_scene_destroy(s2);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    pk_scene *cornell = load(NULL);
    check_tilings(cornell, "cornell", 61, 47);
    check_merge_order(cornell);
    check_cameras();
    check_camera_textures();
    check_progress(cornell);
    pk_scene *json = load(PK_TEST_DATA "/json_example.json");
    check_tilings(json, "json_example", 33, 70);
    pk_scene_destroy(json);
    pk_scene_destroy(cornell);
    pk_context_destroy(ctx);
    return test_done("test_session");
}
