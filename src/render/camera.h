/*
 * camera.h - the camera as the renderer uses it: a frame set up once per
 * render, and the one ray of a camera sample (a position on the film, and on
 * the lens for a camera that has one). The projection is perspective (rays
 * from the eye) or orthographic (parallel rays from the plane of the eye);
 * either may have a thin lens, which blurs what lies off the plane in focus.
 * PK_HD: the GPU's path tracer runs the same code.
 */
#ifndef PK_RENDER_CAMERA_H
#define PK_RENDER_CAMERA_H

#include "../accel/geom.h"
#include "sampling.h"

typedef struct camera_frame {
    vec3 origin, u, v, w; /* w points backwards (from the target to the eye) */
    /* perspective: the tangents of the half angles of the view; orthographic:
     * half the view's width and height in scene units */
    float half_w, half_h;
    float spread;         /* the angle of one pixel (radians, vertically): ray cones for texture filtering
                           * (0 for the orthographic projection, whose rays do not diverge) */
    int width, height;
    float cone0;          /* the ray cone's width where the camera ray starts: a pixel's width for the
                           * orthographic projection, 0 for the perspective one */
    float lens_radius;    /* 0: a pinhole */
    float focus;          /* distance along -w to the plane in focus (used with a lens) */
    int ortho;            /* the orthographic projection */
} camera_frame;

/* Where a camera sample lies: film_x, film_y in pixels ((0, 0) the top-left
 * corner of the image, pixel (px, py) covers px..px+1, py..py+1; with a
 * pixel filter wider than the pixel a sample may lie outside it), and
 * lens_u, lens_v in [0, 1)^2 on the lens (unused without one); weight: what
 * its radiance is multiplied by in its pixel's sum (the pixel filter's,
 * filter.h: 1 but for filters with negative lobes). */
typedef struct camera_sample {
    float film_x, film_y;
    float lens_u, lens_v;
    float weight;
} camera_sample;

/* Whether the camera of f has a lens: its camera samples then use the
 * sampler's lens dimensions (sampler.h SAMPLER_DIM_LENS). */
static inline PK_HD bool camera_has_lens(const camera_frame *f) { return f->lens_radius > 0.0f; }

/* |b - a| for any finite a, b whose difference is finite, however large or
 * small (scaled by its largest component first, like v3_norm_scaled). */
static inline PK_HD float camera_distance(vec3 a, vec3 b)
{
    const vec3 d = v3_sub(b, a);
    const float m = fmaxf(fabsf(d.x), fmaxf(fabsf(d.y), fabsf(d.z)));
    if (!(m > 0.0f) || !isfinite(m)) return v3_len(d);
    return m * v3_len(v3_scale(d, 1.0f / m));
}

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
    f.cone0 = 0.0f;
    const float dist = camera_distance(from, at);
    f.lens_radius = cam->lens_radius;
    f.focus = cam->focus_distance > 0.0f ? cam->focus_distance : dist;
    f.ortho = cam->projection == PK_PROJECTION_ORTHOGRAPHIC;
    if (f.ortho) {
        /* the width given, or the perspective view's at look_at */
        const float hw = cam->ortho_width > 0.0f ? 0.5f * cam->ortho_width : f.half_w * dist;
        f.half_w = hw;
        f.half_h = hw * (float)height / (float)width;
        f.cone0 = 2.0f * hw / (float)width;
        f.spread = 0.0f;
    }
    return f;
}

/* Whether camera_ray is camera_ray_pinhole for f (no lens, perspective). */
static inline PK_HD bool camera_is_pinhole(const camera_frame *f) { return !f->ortho && !camera_has_lens(f); }

/* The pinhole's ray of camera sample cs: from the eye through the point
 * (sx, sy) of the image plane at distance 1. */
static inline PK_HD ray camera_ray_pinhole(const camera_frame *f, const camera_sample *cs)
{
    float sx = (2.0f * cs->film_x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * cs->film_y / (float)f->height) * f->half_h;
    vec3 d = v3_norm(v3_add(v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy)), v3_neg(f->w)));
    ray r = {f->origin, 0.0f, d, INFINITY};
    return r;
}

/* The ray of camera sample cs. Perspective: from the eye through the point
 * (sx, sy) of the image plane at distance 1; orthographic: from the point
 * (sx, sy) of the plane of the eye along the view direction. With a lens the
 * ray starts at the lens point of (lens_u, lens_v) (a concentric map onto
 * the disk of lens_radius about that start) and passes where the lens-less
 * ray meets the plane in focus, so that points there stay sharp. */
static inline PK_HD ray camera_ray(const camera_frame *f, const camera_sample *cs)
{
    if (camera_is_pinhole(f)) return camera_ray_pinhole(f, cs);
    float sx = (2.0f * cs->film_x / (float)f->width - 1.0f) * f->half_w;
    float sy = (1.0f - 2.0f * cs->film_y / (float)f->height) * f->half_h;
    const vec3 film = v3_add(v3_scale(f->u, sx), v3_scale(f->v, sy));
    vec3 o = f->origin, d;
    if (f->ortho) {
        o = v3_add(o, film);
        d = v3_neg(f->w);
    } else {
        d = v3_add(film, v3_neg(f->w));
    }
    if (camera_has_lens(f)) {
        float lx, ly;
        sample_disk_concentric(cs->lens_u, cs->lens_v, &lx, &ly);
        const vec3 off = v3_add(v3_scale(f->u, f->lens_radius * lx), v3_scale(f->v, f->lens_radius * ly));
        o = v3_add(o, off);
        d = v3_sub(v3_scale(d, f->focus), off); /* (d reaches the plane in focus at f->focus times its length) */
    }
    ray r = {o, 0.0f, v3_norm(d), INFINITY};
    return r;
}

#endif
