/*
 * test_scene_write_json.c - pk_scene_write_json (paprsek convert) reads back
 * bit for bit:
 *  - a scene whose positions, normals and uvs are replaced by floats of every
 *    kind (tiny, huge, subnormal, -0, random bit patterns) and whose lights
 *    and materials hold awkward values comes back from its JSON with the same
 *    bits in every world triangle corner, material record field and light;
 *  - scenes of every format (tests/data/convert, the fog scene) come back
 *    with the same render settings and their has_ flags, ambient light,
 *    environment (map pixels included), media and grids;
 *  - what the format cannot hold (a changed default material, a number that
 *    is not finite) is refused with a message naming it, and leaves no file;
 *  - an unwritable place fails before anything is written.
 */
#include "test.h"
#include "test_rng.h"

#include "io/scene_record.h"
#include "scene/scene.h"

#include <dirent.h>
#include <float.h>
#include <stdint.h>
#include <string.h>

static pk_context *ctx;

/* A finite float of any kind: random bits (not inf/NaN), or a special one. */
static float any_float(rng *r)
{
    static const float special[] = {0.0f, -0.0f, FLT_MIN, -FLT_MIN, 1e-45f, 3e-39f, FLT_MAX / 4, 0.1f, 1.0f / 3.0f,
                                    16777217.0f, 0.7f, -123456.789f, 1e-20f, 8388607.5f};
    uint32_t u = rng_u32(r);
    if (u % 4 == 0) return special[(u >> 8) % (sizeof special / sizeof special[0])];
    for (;;) {
        uint32_t bits = rng_u32(r);
        float f;
        memcpy(&f, &bits, sizeof f);
        /* moderate exponents keep the scene's bounds and areas finite */
        if (isfinite(f) && fabsf(f) < 1e15f) return f;
    }
}

/* (memcmp may not be given NULL, which empty arrays are, even for 0 bytes) */
static bool same_bits(const void *a, const void *b, size_t n) { return n == 0 || memcmp(a, b, n) == 0; }

static size_t files_in(const char *dir)
{
    size_t n = 0;
    DIR *d = opendir(dir);
    if (!d) return 0;
    for (struct dirent *e; (e = readdir(d));)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    closedir(d);
    return n;
}

static size_t rec_size(rec_type t)
{
    switch (t) {
    case REC_VEC3: return sizeof(vec3);
    case REC_BOOL: return sizeof(bool);
    case REC_U8: return 1;
    case REC_F2: return 2 * sizeof(float);
    case REC_F9: return 9 * sizeof(float);
    case REC_F16: return 16 * sizeof(float);
    default: return sizeof(float);
    }
}

static void compare(const pk_scene *a, const pk_scene *b)
{
    REQUIRE(a->ntris == b->ntris);
    for (size_t k = 0; k < a->ntris; k++) {
        const triangle *ta = &a->tris[k], *tb = &b->tris[k];
        CHECKF(ta->material == tb->material, "triangle %zu: material %u vs %u", k, ta->material, tb->material);
        for (int j = 0; j < 3; j++) {
            CHECKF(same_bits(&a->positions[ta->v[j]], &b->positions[tb->v[j]], sizeof(vec3)), "triangle %zu corner %d", k, j);
            const bool hn = ta->n[0] >= 0 && ta->n[1] >= 0 && ta->n[2] >= 0;
            const bool ht = ta->t[0] >= 0 && ta->t[1] >= 0 && ta->t[2] >= 0;
            CHECK(hn == (tb->n[j] >= 0));
            CHECK(ht == (tb->t[j] >= 0));
            if (hn && tb->n[j] >= 0) CHECK(same_bits(&a->normals[ta->n[j]], &b->normals[tb->n[j]], sizeof(vec3)));
            if (ht && tb->t[j] >= 0) CHECK(same_bits(&a->uvs[ta->t[j]], &b->uvs[tb->t[j]], sizeof(uv2)));
        }
    }
    REQUIRE(a->nmaterials == b->nmaterials);
    for (size_t i = 0; i < a->nmaterials; i++)
        for (size_t f = 0; f < rec_nmaterial; f++)
            CHECKF(same_bits((const char *)&a->materials[i] + rec_material[f].offset,
                             (const char *)&b->materials[i] + rec_material[f].offset, rec_size(rec_material[f].type)),
                   "material %zu field %s", i, rec_material[f].name);
    REQUIRE(a->nlights == b->nlights);
    for (size_t i = 0; i < a->nlights; i++)
        for (size_t f = 0; f < rec_nlight; f++)
            CHECKF(same_bits((const char *)&a->lights[i] + rec_light[f].offset,
                             (const char *)&b->lights[i] + rec_light[f].offset, rec_size(rec_light[f].type)),
                   "light %zu field %s", i, rec_light[f].name);
    REQUIRE(a->nspheres == b->nspheres);
    CHECK(same_bits(a->spheres, b->spheres, a->nspheres * sizeof *a->spheres));
    CHECK(a->has_camera == b->has_camera && same_bits(&a->camera, &b->camera, sizeof a->camera));
}

/* The rest of the scene: render settings, ambient, environment, media. */
static void compare_rest(const pk_scene *a, const pk_scene *b)
{
    const scene_render_settings *ra = &a->render, *rb = &b->render;
    CHECK(ra->has_width == rb->has_width && ra->has_height == rb->has_height && ra->has_spp == rb->has_spp &&
          ra->has_light_samples == rb->has_light_samples && ra->has_max_depth == rb->has_max_depth &&
          ra->has_threads == rb->has_threads && ra->has_accel == rb->has_accel && ra->has_fresnel == rb->has_fresnel &&
          ra->has_seed == rb->has_seed && ra->has_integrator == rb->has_integrator &&
          ra->has_regularize == rb->has_regularize && ra->has_light_tree == rb->has_light_tree &&
          ra->has_clamp_indirect == rb->has_clamp_indirect &&
          ra->has_energy_compensation == rb->has_energy_compensation);
    const pk_render_options *oa = &ra->opt, *ob = &rb->opt;
    CHECK(oa->width == ob->width && oa->height == ob->height && oa->spp == ob->spp &&
          oa->light_samples == ob->light_samples && oa->max_depth == ob->max_depth && oa->threads == ob->threads &&
          oa->accel == ob->accel && oa->fresnel == ob->fresnel && oa->seed == ob->seed &&
          oa->integrator == ob->integrator && oa->regularize == ob->regularize && oa->light_tree == ob->light_tree &&
          same_bits(&oa->clamp_indirect, &ob->clamp_indirect, sizeof(float)) &&
          oa->energy_compensation == ob->energy_compensation);
    CHECK(same_bits(&a->ambient, &b->ambient, sizeof(vec3)));
    for (size_t f = 0; f < rec_nenv; f++)
        CHECKF(same_bits((const char *)&a->env + rec_env[f].offset, (const char *)&b->env + rec_env[f].offset,
                         rec_size(rec_env[f].type)),
               "environment field %s", rec_env[f].name);
    CHECK(a->env.map_w == b->env.map_w && a->env.map_h == b->env.map_h);
    if (a->env.map_rgb && b->env.map_rgb)
        CHECK(same_bits(a->env.map_rgb, b->env.map_rgb, 3 * sizeof(float) * (size_t)a->env.map_w * (size_t)a->env.map_h));
    CHECK(a->camera_medium == b->camera_medium);
    REQUIRE(a->nmedia == b->nmedia);
    for (size_t i = 0; i < a->nmedia; i++) {
        for (size_t f = 0; f < rec_nmedium; f++)
            CHECKF(same_bits((const char *)&a->media[i] + rec_medium[f].offset,
                             (const char *)&b->media[i] + rec_medium[f].offset, rec_size(rec_medium[f].type)),
                   "medium %zu field %s", i, rec_medium[f].name);
        const medium_grid *ga[3] = {&a->media[i].density, &a->media[i].albedo_grid, &a->media[i].emission_grid};
        const medium_grid *gb[3] = {&b->media[i].density, &b->media[i].albedo_grid, &b->media[i].emission_grid};
        for (int g = 0; g < 3; g++) {
            CHECK(!ga[g]->data == !gb[g]->data);
            if (!ga[g]->data || !gb[g]->data) continue;
            CHECK(ga[g]->nx == gb[g]->nx && ga[g]->ny == gb[g]->ny && ga[g]->nz == gb[g]->nz &&
                  ga[g]->channels == gb[g]->channels);
            CHECK(same_bits(ga[g]->data, gb[g]->data,
                            sizeof(float) * (size_t)ga[g]->nx * (size_t)ga[g]->ny * (size_t)ga[g]->nz *
                                (size_t)ga[g]->channels));
        }
    }
}

/* Loads path, writes it into dir, loads that and compares every part. */
static void round_trip(const char *path, const char *dir)
{
    char out[256];
    snprintf(out, sizeof out, "%s/trip.json", dir);
    pk_scene *a = NULL, *b = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &a) == PK_OK);
    REQUIRE(pk_scene_write_json(ctx, a, out) == PK_OK);
    if (pk_scene_load_file(ctx, out, &b) != PK_OK) {
        fprintf(stderr, "%s: reloading: %s\n", path, pk_context_error(ctx));
        REQUIRE(0);
    }
    compare(a, b);
    compare_rest(a, b);
    pk_scene_destroy(a);
    pk_scene_destroy(b);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    char dir[] = "/tmp/pk_write_json_XXXXXX";
    REQUIRE(mkdtemp(dir));
    char out[256], again[256];
    snprintf(out, sizeof out, "%s/scene.json", dir);

    /* ---- bit for bit ---- */
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, PK_TEST_DATA "/json_example.json", &s) == PK_OK);
    rng r = {0x5eed};
    for (size_t i = 0; i < s->npositions; i++) s->positions[i] = v3(any_float(&r), any_float(&r), any_float(&r));
    for (size_t i = 0; i < s->nnormals; i++) s->normals[i] = v3(any_float(&r), any_float(&r), any_float(&r));
    for (size_t i = 0; i < s->nuvs; i++) s->uvs[i] = (uv2){any_float(&r), any_float(&r)};
    for (size_t i = 1; i < s->nmaterials; i++) {
        s->materials[i].ni = any_float(&r);
        s->materials[i].alpha = any_float(&r);
        s->materials[i].eta = v3(any_float(&r), any_float(&r), any_float(&r));
    }
    for (size_t i = 0; i < s->nlights; i++) s->lights[i].position = v3(any_float(&r), any_float(&r), any_float(&r));
    s->camera.fov_deg = 1.0f / 3.0f;
    REQUIRE(pk_scene_write_json(ctx, s, out) == PK_OK);
    pk_scene *b = NULL;
    if (pk_scene_load_file(ctx, out, &b) != PK_OK) {
        fprintf(stderr, "reloading: %s\n", pk_context_error(ctx));
        REQUIRE(0);
    }
    compare(s, b);
    /* written again from the reloaded scene: the same scene once more */
    snprintf(again, sizeof again, "%s/again.json", dir);
    REQUIRE(pk_scene_write_json(ctx, b, again) == PK_OK);
    pk_scene *c = NULL;
    REQUIRE(pk_scene_load_file(ctx, again, &c) == PK_OK);
    compare(s, c);
    pk_scene_destroy(b);
    pk_scene_destroy(c);

    /* ---- every part of scenes in each format ---- */
    static const char *const scenes[] = {"convert/lights.json", "convert/lights.xml", "convert/lights.pbrt",
                                         "convert/spot.gltf",   "media/fog.json",     "media/fog.xml",
                                         "media/fog.pbrt",      "tex_json.json"};
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", PK_TEST_DATA, scenes[i]);
        round_trip(path, dir);
    }
    /* energy compensation: a glTF asset asks for it, the others do not say */
    for (size_t i = 0; i < sizeof scenes / sizeof scenes[0]; i++) {
        char path[512];
        snprintf(path, sizeof path, "%s/%s", PK_TEST_DATA, scenes[i]);
        pk_scene *g = NULL;
        REQUIRE(pk_scene_load_file(ctx, path, &g) == PK_OK);
        const bool gltf = strstr(scenes[i], ".gltf") != NULL;
        CHECKF(g->render.has_energy_compensation == gltf && g->render.opt.energy_compensation == (gltf ? 1 : 0), "%s",
               scenes[i]);
        pk_render_options ro;
        pk_scene_get_render_options(g, &ro);
        CHECKF(ro.energy_compensation == (gltf ? 1 : 0), "%s: render options", scenes[i]);
        pk_scene_destroy(g);
    }

    /* ---- refused, nothing written ---- */
    char empty[] = "/tmp/pk_write_json_e_XXXXXX";
    REQUIRE(mkdtemp(empty));
    snprintf(out, sizeof out, "%s/x.json", empty);
    const vec3 kd0 = s->materials[0].kd;
    s->materials[0].kd = v3s(0.25f);
    pk_context_clear_error(ctx);
    CHECK(pk_scene_write_json(ctx, s, out) == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(pk_context_error(ctx), "default material") != NULL, "%s", pk_context_error(ctx));
    CHECK(files_in(empty) == 0);
    s->materials[0].kd = kd0;
    s->lights[0].intensity.y = INFINITY;
    pk_context_clear_error(ctx);
    CHECK(pk_scene_write_json(ctx, s, out) == PK_ERR_UNSUPPORTED);
    CHECKF(strstr(pk_context_error(ctx), "lights.intensity is not finite") != NULL, "%s", pk_context_error(ctx));
    CHECKF(files_in(empty) == 0, "%zu files left", files_in(empty));
    s->lights[0].intensity.y = 1.0f;
    pk_context_clear_error(ctx);
    snprintf(out, sizeof out, "%s/no/such/folder/x.json", empty);
    CHECK(pk_scene_write_json(ctx, s, out) == PK_ERR_IO);
    CHECK(files_in(empty) == 0);

    pk_scene_destroy(s);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s' '%s'", dir, empty);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", dir);
    pk_context_destroy(ctx);
    return test_done("test_scene_write_json");
}
