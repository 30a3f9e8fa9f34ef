/*
 * test_pick.c - pk_renderer_pick and pk_camera_check through the public
 * header: the surface under a point of the Cornell box, the distance a
 * focus wants, a pick from another thread while the renderer renders, and
 * the refusals.
 */
#include "paprsek.h"
#include "test.h"

#include <pthread.h>

typedef struct job {
    pk_renderer *r;
    pk_film *film;
    pk_status st;
} job;

static void *render_job(void *arg)
{
    job *j = arg;
    for (uint32_t p = 0; p < 4 && j->st == PK_OK; p++) {
        pk_renderer_set_pass(j->r, p);
        j->st = pk_renderer_render(j->r, NULL, 0, j->film);
    }
    return NULL;
}

int main(void)
{
    pk_context *ctx = NULL;
    pk_scene *scene = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    REQUIRE(pk_scene_create_cornell_box(ctx, &scene) == PK_OK);
    pk_render_options ro;
    pk_scene_get_render_options(scene, &ro);
    ro.width = 64;
    ro.height = 48;
    ro.spp = 1;
    ro.threads = 2;
    pk_renderer *r = NULL;
    REQUIRE(pk_renderer_create(ctx, scene, &ro, &r) == PK_OK);
    pk_camera cam;
    pk_scene_get_camera(scene, &cam); /* from (0.278, 0.273, -0.8) along +z */

    /* the centre of the image: the front face of the tall block, from
     * (0.265, 0.296) to (0.423, 0.247) in x, z: z = 0.296 - 0.013 * 49 / 158 */
    pk_pick pk;
    CHECK(pk_renderer_pick(r, NULL, 32.0, 24.0, &pk) == PK_OK);
    CHECK(pk.hit == 1);
    const double z = 0.296 - 0.013 * 49.0 / 158.0;
    CHECK_NEAR(pk.distance, z + 0.8, 1e-5);
    CHECK_NEAR(pk.t, z + 0.8, 1e-5); /* on the axis: along the ray is along the view */
    CHECK_NEAR(pk.position[0], 0.278, 1e-5);
    CHECK_NEAR(pk.position[1], 0.273, 1e-5);
    CHECK_NEAR(pk.position[2], z, 1e-5);
    /* the face's normal, toward the camera (-z side): (-49, 0, -158) normalised */
    const double nl = sqrt(49.0 * 49.0 + 158.0 * 158.0);
    CHECK_NEAR(pk.normal[0], -49.0 / nl, 1e-5);
    CHECK_NEAR(pk.normal[1], 0.0, 1e-6);
    CHECK_NEAR(pk.normal[2], -158.0 / nl, 1e-5);
    CHECK(strcmp(pk.material, "white") == 0);

    /* the back wall seen off axis: the distance along the view stays 0.5592 + 0.8, t grows */
    CHECK(pk_renderer_pick(r, &cam, 30.0, 15.0, &pk) == PK_OK);
    CHECK(pk.hit == 1);
    CHECK_NEAR(pk.distance, 1.3592, 1e-5);
    CHECK(pk.t > pk.distance);
    CHECK_NEAR(pk.normal[2], -1.0, 1e-6);

    /* a lens does not move the pick: the ray goes through its centre */
    pk_camera lens = cam;
    lens.lens_radius = 0.05f;
    lens.focus_distance = 0.5f;
    pk_pick pl;
    CHECK(pk_renderer_pick(r, &lens, 32.0, 24.0, &pl) == PK_OK);
    CHECK(pk_renderer_pick(r, NULL, 32.0, 24.0, &pk) == PK_OK);
    CHECK(pl.hit && pk.hit && pl.distance == pk.distance && pl.prim == pk.prim);

    /* looking out of the open front of the box: nothing */
    pk_camera out = cam;
    out.look_at[2] = -2.0f;
    CHECK(pk_renderer_pick(r, &out, 32.0, 24.0, &pk) == PK_OK);
    CHECK(pk.hit == 0);

    /* refusals: outside the image, a bad camera, NULLs; nothing latched */
    CHECK(pk_renderer_pick(r, NULL, -0.5, 3.0, &pk) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_renderer_pick(r, NULL, 3.0, 48.5, &pk) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_renderer_pick(r, NULL, NAN, 3.0, &pk) == PK_ERR_INVALID_ARGUMENT);
    pk_camera bad = cam;
    bad.fov_deg = 180.0f;
    CHECK(pk_renderer_pick(r, &bad, 3.0, 3.0, &pk) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_renderer_pick(NULL, NULL, 3.0, 3.0, &pk) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_renderer_pick(r, NULL, 3.0, 3.0, NULL) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_context_status(ctx) == PK_OK);

    /* pk_camera_check: the library's rule, with its message */
    CHECK(pk_camera_check(ctx, &cam) == PK_OK);
    CHECK(pk_camera_check(NULL, &bad) == PK_ERR_INVALID_ARGUMENT);
    CHECK(pk_camera_check(ctx, &bad) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "fov") != NULL);
    pk_context_clear_error(ctx);
    pk_camera same = cam;
    memcpy(same.look_at, same.look_from, sizeof same.look_at);
    CHECK(pk_camera_check(ctx, &same) == PK_ERR_INVALID_ARGUMENT);
    CHECK(strstr(pk_context_error(ctx), "same point") != NULL);
    pk_context_clear_error(ctx);

    /* picks from this thread while another renders with the same renderer */
    job j = {r, NULL, PK_OK};
    REQUIRE(pk_film_create(ctx, ro.width, ro.height, &j.film) == PK_OK);
    pthread_t th;
    REQUIRE(pthread_create(&th, NULL, render_job, &j) == 0);
    int same_answer = 1;
    for (int i = 0; i < 2000; i++) {
        pk_pick q;
        same_answer &= pk_renderer_pick(r, NULL, 32.0, 24.0, &q) == PK_OK && q.hit &&
                       fabs((double)q.distance - (z + 0.8)) < 1e-5;
    }
    pthread_join(th, NULL);
    CHECK(same_answer);
    CHECK(j.st == PK_OK);
    pk_film_destroy(j.film);

    pk_renderer_destroy(r);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return test_done("test_pick");
}
