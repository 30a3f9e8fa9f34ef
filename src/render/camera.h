/*
 * camera.h - the pinhole camera as the renderer uses it: a frame set up once
 * per render and a ray through any image position.
 */
#ifndef PK_RENDER_CAMERA_H
#define PK_RENDER_CAMERA_H

#include "../accel/geom.h"

typedef struct camera_frame {
    vec3 origin, u, v, w; /* w points backwards (from the target to the eye) */
    float half_w, half_h;
    int width, height;
} camera_frame;

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
    f.width = width;
    f.height = height;
    return f;
}

/* Ray through image position (x, y) in pixels, (0,0) the top-left corner. */
static inline PK_HD ray camera_ray(const camera_frame *f, float x, float y)
{
    float sx = (2.0f * x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * y / (float)f->height) * f->half_h;
    vec3 d = v3_norm(v3_add(v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy)), v3_neg(f->w)));
    ray r = {f->origin, 0.0f, d, INFINITY};
    return r;
}

#endif
