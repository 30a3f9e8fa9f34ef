/*
 * cornell.c - the built-in Cornell box, from the measurements published by the
 * Cornell University Program of Computer Graphics ("Cornell Box data"),
 * converted from millimetres to metres. Every quad is listed in the published
 * vertex order, which makes walls face into the box, the boxes face out and
 * the light face down; each quad becomes the triangles (0,1,2) and (0,2,3).
 */
#include "scene.h"

#define CB_MM 0.001f /* the data is in millimetres; the scene is in metres */

/* The light sits this far below the ceiling (published: in the ceiling plane). */
#define CB_LIGHT_DROP_MM 0.5f

/* Reflectances; the light's Ke is the usual (17, 12, 4) scaled so that a
 * direct-lighting-only (Whitted) render is well exposed: the floor below the
 * light reaches about 0.5 in red. */
#define CB_LIGHT_SCALE 3.0f

typedef struct cb_quad {
    float v[4][3]; /* mm */
    int material;  /* CB_* below */
} cb_quad;

enum { CB_WHITE, CB_RED, CB_GREEN, CB_LIGHT, CB_NMAT };

static const cb_quad cb_quads[] = {
    /* floor */
    {{{552.8f, 0.0f, 0.0f}, {0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, 559.2f}, {549.6f, 0.0f, 559.2f}}, CB_WHITE},
    /* ceiling */
    {{{556.0f, 548.8f, 0.0f}, {556.0f, 548.8f, 559.2f}, {0.0f, 548.8f, 559.2f}, {0.0f, 548.8f, 0.0f}}, CB_WHITE},
    /* back wall */
    {{{549.6f, 0.0f, 559.2f}, {0.0f, 0.0f, 559.2f}, {0.0f, 548.8f, 559.2f}, {556.0f, 548.8f, 559.2f}}, CB_WHITE},
    /* right wall (x = 0; on the right as seen from the camera) */
    {{{0.0f, 0.0f, 559.2f}, {0.0f, 0.0f, 0.0f}, {0.0f, 548.8f, 0.0f}, {0.0f, 548.8f, 559.2f}}, CB_GREEN},
    /* left wall */
    {{{552.8f, 0.0f, 0.0f}, {549.6f, 0.0f, 559.2f}, {556.0f, 548.8f, 559.2f}, {556.0f, 548.8f, 0.0f}}, CB_RED},
    /* light (y lowered by CB_LIGHT_DROP_MM when built) */
    {{{343.0f, 548.8f, 227.0f}, {343.0f, 548.8f, 332.0f}, {213.0f, 548.8f, 332.0f}, {213.0f, 548.8f, 227.0f}},
     CB_LIGHT},
    /* short block */
    {{{130.0f, 165.0f, 65.0f}, {82.0f, 165.0f, 225.0f}, {240.0f, 165.0f, 272.0f}, {290.0f, 165.0f, 114.0f}}, CB_WHITE},
    {{{290.0f, 0.0f, 114.0f}, {290.0f, 165.0f, 114.0f}, {240.0f, 165.0f, 272.0f}, {240.0f, 0.0f, 272.0f}}, CB_WHITE},
    {{{130.0f, 0.0f, 65.0f}, {130.0f, 165.0f, 65.0f}, {290.0f, 165.0f, 114.0f}, {290.0f, 0.0f, 114.0f}}, CB_WHITE},
    {{{82.0f, 0.0f, 225.0f}, {82.0f, 165.0f, 225.0f}, {130.0f, 165.0f, 65.0f}, {130.0f, 0.0f, 65.0f}}, CB_WHITE},
    {{{240.0f, 0.0f, 272.0f}, {240.0f, 165.0f, 272.0f}, {82.0f, 165.0f, 225.0f}, {82.0f, 0.0f, 225.0f}}, CB_WHITE},
    /* tall block */
    {{{423.0f, 330.0f, 247.0f}, {265.0f, 330.0f, 296.0f}, {314.0f, 330.0f, 456.0f}, {472.0f, 330.0f, 406.0f}}, CB_WHITE},
    {{{423.0f, 0.0f, 247.0f}, {423.0f, 330.0f, 247.0f}, {472.0f, 330.0f, 406.0f}, {472.0f, 0.0f, 406.0f}}, CB_WHITE},
    {{{472.0f, 0.0f, 406.0f}, {472.0f, 330.0f, 406.0f}, {314.0f, 330.0f, 456.0f}, {314.0f, 0.0f, 456.0f}}, CB_WHITE},
    {{{314.0f, 0.0f, 456.0f}, {314.0f, 330.0f, 456.0f}, {265.0f, 330.0f, 296.0f}, {265.0f, 0.0f, 296.0f}}, CB_WHITE},
    {{{265.0f, 0.0f, 296.0f}, {265.0f, 330.0f, 296.0f}, {423.0f, 330.0f, 247.0f}, {423.0f, 0.0f, 247.0f}}, CB_WHITE},
};

static pk_status add_quad(pk_context *ctx, pk_scene *s, const cb_quad *q, uint32_t mat)
{
    uint32_t base = (uint32_t)s->npositions;
    pk_status st;
    for (int i = 0; i < 4; i++) {
        float y = q->v[i][1];
        if (q->material == CB_LIGHT) y -= CB_LIGHT_DROP_MM;
        if ((st = scene_add_position(ctx, s, v3(q->v[i][0] * CB_MM, y * CB_MM, q->v[i][2] * CB_MM)))) return st;
    }
    triangle t = {{base, base + 1, base + 2}, {-1, -1, -1}, {-1, -1, -1}, mat};
    if ((st = scene_add_triangle(ctx, s, &t))) return st;
    t.v[1] = base + 2;
    t.v[2] = base + 3;
    return scene_add_triangle(ctx, s, &t);
}

pk_status scene_build_cornell(pk_context *ctx, pk_scene *s)
{
    static const char *const names[CB_NMAT] = {"white", "red", "green", "light"};
    uint32_t mat[CB_NMAT];
    pk_status st;
    for (int i = 0; i < CB_NMAT; i++)
        if ((st = scene_add_material(ctx, s, names[i], &mat[i]))) return st;
    s->materials[mat[CB_WHITE]].kd = v3(0.73f, 0.73f, 0.73f);
    s->materials[mat[CB_RED]].kd = v3(0.63f, 0.065f, 0.05f);
    s->materials[mat[CB_GREEN]].kd = v3(0.14f, 0.45f, 0.09f);
    s->materials[mat[CB_LIGHT]].kd = v3(0.78f, 0.78f, 0.78f);
    s->materials[mat[CB_LIGHT]].ke = v3_scale(v3(17.0f, 12.0f, 4.0f), CB_LIGHT_SCALE);
    for (size_t i = 0; i < sizeof cb_quads / sizeof cb_quads[0]; i++)
        if ((st = add_quad(ctx, s, &cb_quads[i], mat[cb_quads[i].material]))) return st;

    /* The published camera: at (278, 273, -800) mm looking along +z, focal
     * length 35 mm on a 25 mm film: fov = 2 atan(12.5 / 35) = 39.3077 deg. */
    const pk_camera cam = {{0.278f, 0.273f, -0.800f}, {0.278f, 0.273f, 0.0f}, {0.0f, 1.0f, 0.0f}, 39.3077f,
                           0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    s->camera = cam;
    s->has_camera = true;
    return PK_OK;
}
