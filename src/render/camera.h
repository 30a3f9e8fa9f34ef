/*
 * camera.h - the pinhole camera as the renderer uses it: a frame set up once
 * per render, and the one ray of a camera sample (a position on the film,
 * and on the lens for cameras that have one).
 */
#ifndef PK_RENDER_CAMERA_H
#define PK_RENDER_CAMERA_H

#include "../accel/geom.h"

typedef struct camera_frame {
    vec3 origin, u, v, w; /* w points backwards (from the target to the eye) */
    float half_w, half_h;
    float spread;         /* the angle of one pixel (radians, vertically): ray cones for texture filtering */
    int width, height;
} camera_frame;

/* Where a camera sample lies: film_x, film_y in pixels ((0, 0) the top-left
 * corner of the image, pixel (px, py) covers px..px+1, py..py+1), and
 * lens_u, lens_v in [0, 1)^2 on the lens (unused by the pinhole). */
typedef struct camera_sample {
    float film_x, film_y;
    float lens_u, lens_v;
} camera_sample;

/* cam has passed camera_validate. */
static inline PK_HD camera_frame camera_setup(const pk_camera *cam, int width, int height)
{
    camera_frame f;
    vec3 from = v3(cam->look_from[0], cam->look_from[1], cam->look_from[2]);
    vec3 at = v3(cam->look_at[0], cam->look_at[1], cam->look_at[2]);
    vec3 up = v3(cam->up[0], cam->up[1], cam->up[2]);
    f.origin = from;
    f.w = v3_norm_scaled(v3_sub(from, at));
    f.u = v3_norm(v3_cross(v3_norm_scaled(up), f.w));
    f.v = v3_cross(f.w, f.u);
    f.half_h = tanf(0.5f * cam->fov_deg * PK_PI / 180.0f);
    f.half_w = f.half_h * (float)width / (float)height;
    f.spread = 2.0f * f.half_h / (float)height;
    f.width = width;
    f.height = height;
    return f;
}

/* The ray of camera sample cs. */
static inline PK_HD ray camera_ray(const camera_frame *f, const camera_sample *cs)
{
    float sx = (2.0f * cs->film_x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * cs->film_y / (float)f->height) * f->half_h;
    vec3 d = v3_norm(v3_add(v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy)), v3_neg(f->w)));
    ray r = {f->origin, 0.0f, d, INFINITY};
    return r;
}

#endif
