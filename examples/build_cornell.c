/*
 * build_cornell.c - the Cornell box built through Paprsek's scene-building
 * API alone (docs/scene-api.md) and rendered to a file.
 *
 * usage: build_cornell OUT [--builtin]
 *   OUT        the image (.png, .pfm or .exr)
 *   --builtin  render the library's own box (pk_scene_create_cornell_box)
 *              with the same options instead: the two files are the same
 *              byte for byte (tests/api/build_cornell.sh checks it)
 *
 * The geometry is the Cornell University Program of Computer Graphics'
 * published box in millimetres, scaled to metres; the materials are MTL
 * records (JSON materials without a "type"): a diffuse colour "kd" and, for
 * the light, an emitted radiance "ke".
 */
#include "paprsek.h"

#include <stdio.h>
#include <string.h>

/* Quads in the published vertex order: walls face into the box, the blocks
 * out, the light down. Each quad is the triangles (0,1,2) and (0,2,3). */
typedef struct quad {
    float v[4][3]; /* millimetres */
} quad;

static const quad floor_ceiling_back[] = {
    {{{552.8f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 559.2f}, {549.6f, 0.0f, 559.2f}}},             /* floor */
    {{{556.0f, 548.8f, 0.0f}, {556.0f, 548.8f, 559.2f}, {0.0f, 548.8f, 559.2f}, {0.0f, 548.8f, 0.0f}}},     /* ceiling */
    {{{549.6f, 0.0f, 559.2f}, {0.0f, 0.0f, 559.2f}, {0.0f, 548.8f, 559.2f}, {556.0f, 548.8f, 559.2f}}},     /* back */
};
static const quad right_wall[] = {
    {{{0.0f, 0.0f, 559.2f}, {0.0f, 0.0f, 0.0f}, {0.0f, 548.8f, 0.0f}, {0.0f, 548.8f, 559.2f}}},
};
static const quad left_wall[] = {
    {{{552.8f, 0.0f, 0.0f}, {549.6f, 0.0f, 559.2f}, {556.0f, 548.8f, 559.2f}, {556.0f, 548.8f, 0.0f}}},
};
/* the light, 0.5 mm below the ceiling */
static const quad light[] = {
    {{{343.0f, 548.8f - 0.5f, 227.0f}, {343.0f, 548.8f - 0.5f, 332.0f}, {213.0f, 548.8f - 0.5f, 332.0f},
      {213.0f, 548.8f - 0.5f, 227.0f}}},
};
static const quad blocks[] = {
    /* short block */
    {{{130.0f, 165.0f, 65.0f}, {82.0f, 165.0f, 225.0f}, {240.0f, 165.0f, 272.0f}, {290.0f, 165.0f, 114.0f}}},
    {{{290.0f, 0.0f, 114.0f}, {290.0f, 165.0f, 114.0f}, {240.0f, 165.0f, 272.0f}, {240.0f, 0.0f, 272.0f}}},
    {{{130.0f, 0.0f, 65.0f}, {130.0f, 165.0f, 65.0f}, {290.0f, 165.0f, 114.0f}, {290.0f, 0.0f, 114.0f}}},
    {{{82.0f, 0.0f, 225.0f}, {82.0f, 165.0f, 225.0f}, {130.0f, 165.0f, 65.0f}, {130.0f, 0.0f, 65.0f}}},
    {{{240.0f, 0.0f, 272.0f}, {240.0f, 165.0f, 272.0f}, {82.0f, 165.0f, 225.0f}, {82.0f, 0.0f, 225.0f}}},
    /* tall block */
    {{{423.0f, 330.0f, 247.0f}, {265.0f, 330.0f, 296.0f}, {314.0f, 330.0f, 456.0f}, {472.0f, 330.0f, 406.0f}}},
    {{{423.0f, 0.0f, 247.0f}, {423.0f, 330.0f, 247.0f}, {472.0f, 330.0f, 406.0f}, {472.0f, 0.0f, 406.0f}}},
    {{{472.0f, 0.0f, 406.0f}, {472.0f, 330.0f, 406.0f}, {314.0f, 330.0f, 456.0f}, {314.0f, 0.0f, 456.0f}}},
    {{{314.0f, 0.0f, 456.0f}, {314.0f, 330.0f, 456.0f}, {265.0f, 330.0f, 296.0f}, {265.0f, 0.0f, 296.0f}}},
    {{{265.0f, 0.0f, 296.0f}, {265.0f, 330.0f, 296.0f}, {423.0f, 330.0f, 247.0f}, {423.0f, 0.0f, 247.0f}}},
};

#define MAX_QUADS 10

/* Adds n quads as one mesh of material mat, in metres. */
static pk_status add_quads(pk_context *ctx, pk_scene *scene, const quad *q, size_t n, uint32_t mat)
{
    float pos[MAX_QUADS * 4 * 3];
    uint32_t idx[MAX_QUADS * 6];
    for (size_t i = 0; i < n; i++) {
        for (int k = 0; k < 4; k++)
            for (int c = 0; c < 3; c++) pos[(4 * i + (size_t)k) * 3 + (size_t)c] = q[i].v[k][c] * 0.001f;
        const uint32_t b = (uint32_t)(4 * i), tri[6] = {b, b + 1, b + 2, b, b + 2, b + 3};
        memcpy(&idx[6 * i], tri, sizeof tri);
    }
    pk_mesh_desc mesh = {0};
    mesh.positions = pos;
    mesh.npositions = 4 * n;
    mesh.indices = idx;
    mesh.ntriangles = 2 * n;
    mesh.material = mat; /* no normals, no uvs, no transform */
    return pk_scene_add_mesh(ctx, scene, &mesh);
}

/* A material of the OBJ/MTL kind: diffuse colour kd, emitted radiance ke. */
static pk_status add_mtl(pk_context *ctx, pk_scene *scene, pk_params *p, const char *name, const float kd[3],
                         const float ke[3], uint32_t *index)
{
    pk_params_clear(p);
    pk_status st = pk_params_set_rgb(p, "kd", kd[0], kd[1], kd[2]);
    if (st == PK_OK && ke) st = pk_params_set_rgb(p, "ke", ke[0], ke[1], ke[2]);
    if (st == PK_OK) st = pk_scene_add_material(ctx, scene, name, NULL, p, index);
    return st;
}

static pk_status build(pk_context *ctx, pk_scene **out)
{
    pk_scene *scene = NULL;
    pk_params *p = NULL;
    pk_status st = pk_scene_create(ctx, "cornell-box (API)", &scene);
    if (st == PK_OK) st = pk_params_create(ctx, &p);
    uint32_t white = 0, red = 0, green = 0, lamp = 0;
    static const float kd_white[3] = {0.73f, 0.73f, 0.73f}, kd_red[3] = {0.63f, 0.065f, 0.05f},
                       kd_green[3] = {0.14f, 0.45f, 0.09f}, kd_lamp[3] = {0.78f, 0.78f, 0.78f};
    /* the usual (17, 12, 4), three times brighter so that direct light alone exposes well */
    static const float ke_lamp[3] = {17.0f * 3.0f, 12.0f * 3.0f, 4.0f * 3.0f};
    if (st == PK_OK) st = add_mtl(ctx, scene, p, "white", kd_white, NULL, &white);
    if (st == PK_OK) st = add_mtl(ctx, scene, p, "red", kd_red, NULL, &red);
    if (st == PK_OK) st = add_mtl(ctx, scene, p, "green", kd_green, NULL, &green);
    if (st == PK_OK) st = add_mtl(ctx, scene, p, "light", kd_lamp, ke_lamp, &lamp);
    if (st == PK_OK) st = add_quads(ctx, scene, floor_ceiling_back, 3, white);
    if (st == PK_OK) st = add_quads(ctx, scene, right_wall, 1, green);
    if (st == PK_OK) st = add_quads(ctx, scene, left_wall, 1, red);
    if (st == PK_OK) st = add_quads(ctx, scene, light, 1, lamp);
    if (st == PK_OK) st = add_quads(ctx, scene, blocks, 10, white);
    /* the published camera: 35 mm lens on 25 mm film, fov = 2 atan(12.5 / 35) */
    pk_camera cam = {{0.278f, 0.273f, -0.800f}, {0.278f, 0.273f, 0.0f}, {0.0f, 1.0f, 0.0f}, 39.3077f,
                     0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    if (st == PK_OK) st = pk_scene_set_camera(ctx, scene, &cam);
    if (st == PK_OK) st = pk_scene_commit(ctx, scene);
    pk_params_destroy(p);
    if (st != PK_OK) {
        pk_scene_destroy(scene);
        return st;
    }
    *out = scene;
    return PK_OK;
}

static void warn(void *user, const char *message)
{
    (void)user;
    fprintf(stderr, "build_cornell: warning: %s\n", message);
}

int main(int argc, char **argv)
{
    if (argc < 2 || argc > 3 || (argc == 3 && strcmp(argv[2], "--builtin") != 0)) {
        fprintf(stderr, "usage: build_cornell OUT [--builtin]\n");
        return 2;
    }
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 1;
    pk_context_set_warning_handler(ctx, warn, NULL);
    pk_scene *scene = NULL;
    pk_image *img = NULL;
    pk_status st = argc == 3 ? pk_scene_create_cornell_box(ctx, &scene) : build(ctx, &scene);
    if (st == PK_OK) {
        pk_render_options opt;
        pk_render_options_init(&opt);
        opt.width = 128;
        opt.height = 128;
        opt.spp = 4;
        opt.threads = 2;
        st = pk_render(ctx, scene, &opt, &img, NULL);
    }
    if (st == PK_OK) st = pk_image_write(ctx, img, argv[1]);
    if (st != PK_OK) fprintf(stderr, "build_cornell: %s\n", pk_context_error(ctx));
    pk_image_destroy(img);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return st == PK_OK ? 0 : 1;
}
