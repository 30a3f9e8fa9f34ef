/*
 * camera.c - the one camera rule and automatic framing.
 */
#include "camera.h"

#include <string.h>

camera_problem camera_check(const pk_camera *cam)
{
    vec3 from = v3(cam->look_from[0], cam->look_from[1], cam->look_from[2]);
    vec3 at = v3(cam->look_at[0], cam->look_at[1], cam->look_at[2]);
    vec3 up = v3(cam->up[0], cam->up[1], cam->up[2]);
    if (!v3_finite(from) || !v3_finite(at) || !v3_finite(up) || !isfinite(cam->fov_deg) ||
        !isfinite(cam->lens_radius) || !isfinite(cam->focus_distance) || !isfinite(cam->ortho_width))
        return CAMERA_NOT_FINITE;
    if (!(cam->fov_deg > 0.0f && cam->fov_deg < 180.0f)) return CAMERA_FOV;
    vec3 dir = v3_sub(at, from);
    if (!v3_finite(dir)) return CAMERA_TOO_FAR;
    if (dir.x == 0.0f && dir.y == 0.0f && dir.z == 0.0f) return CAMERA_SAME_POINT;
    if (up.x == 0.0f && up.y == 0.0f && up.z == 0.0f) return CAMERA_UP_ZERO;
    /* sine of the angle between view and up: below 1e-4 (0.006 degrees) the
     * camera frame is too ill-conditioned to trust */
    if (!(v3_len(v3_cross(v3_norm_scaled(dir), v3_norm_scaled(up))) > 1e-4f)) return CAMERA_UP_PARALLEL;
    if (cam->lens_radius < 0.0f) return CAMERA_LENS;
    if (cam->focus_distance < 0.0f) return CAMERA_FOCUS;
    if (cam->projection != PK_PROJECTION_PERSPECTIVE && cam->projection != PK_PROJECTION_ORTHOGRAPHIC)
        return CAMERA_PROJECTION;
    if (cam->ortho_width < 0.0f) return CAMERA_ORTHO_WIDTH;
    /* the distance to look_at stands for a focus distance or a width of 0:
     * it must be finite (render/camera.h camera_distance) */
    const bool by_distance = (cam->lens_radius > 0.0f && cam->focus_distance == 0.0f) ||
                             (cam->projection == PK_PROJECTION_ORTHOGRAPHIC && cam->ortho_width == 0.0f);
    if (by_distance) {
        const float m = fmaxf(fabsf(dir.x), fmaxf(fabsf(dir.y), fabsf(dir.z)));
        if (!isfinite(m * v3_len(v3_scale(dir, 1.0f / m)))) return CAMERA_TOO_FAR;
    }
    return CAMERA_OK;
}

pk_status camera_validate(pk_context *ctx, const pk_camera *cam, const char *what)
{
    switch (camera_check(cam)) {
    case CAMERA_OK: return PK_OK;
    case CAMERA_NOT_FINITE:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: camera values must be finite numbers", what);
    case CAMERA_FOV:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: fov %g must be between 0 and 180 degrees (exclusive)",
                         what, (double)cam->fov_deg);
    case CAMERA_TOO_FAR:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: look_from and look_at are too far apart", what);
    case CAMERA_SAME_POINT:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: look_from and look_at are the same point", what);
    case CAMERA_UP_ZERO:
    case CAMERA_UP_PARALLEL:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: up vector is zero or parallel to the view direction",
                         what);
    case CAMERA_LENS:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: lens_radius %g must not be negative (0: a pinhole)", what,
                         (double)cam->lens_radius);
    case CAMERA_FOCUS:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "%s: focus_distance %g must not be negative (0: the distance to look_at)", what,
                         (double)cam->focus_distance);
    case CAMERA_PROJECTION:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "%s: projection %d is not PK_PROJECTION_PERSPECTIVE (0) or PK_PROJECTION_ORTHOGRAPHIC (1)",
                         what, cam->projection);
    case CAMERA_ORTHO_WIDTH:
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "%s: ortho_width %g must not be negative (0: the perspective view's width at look_at)", what,
                         (double)cam->ortho_width);
    }
    return PK_ERR_INVALID_ARGUMENT;
}

void pk_camera_init(pk_camera *cam)
{
    if (!cam) return;
    const pk_camera k = {{0.0f, 0.0f, 0.0f}, {0.0f, 0.0f, -1.0f}, {0.0f, 1.0f, 0.0f}, 45.0f,
                         0.0f, 0.0f, PK_PROJECTION_PERSPECTIVE, 0.0f};
    *cam = k;
}

void scene_camera(const pk_scene *s, pk_camera *cam)
{
    if (s->has_camera) {
        *cam = s->camera;
        return;
    }
    /* Look along -z at the centre of the bounds from just far enough that the
     * front face of the box fills a 40 degree view (with a small margin). */
    aabb b = s->bounds;
    if (!v3_finite(b.lo) || !v3_finite(b.hi)) b.lo = b.hi = v3s(0.0f);
    vec3 c = aabb_center(b), e = aabb_extent(b);
    float fov = 40.0f;
    float half = 0.5f * fmaxf(e.x, e.y) * 1.08f;
    if (!(half > 0.0f)) half = fmaxf(0.5f * e.z, 1.0f);
    float dist = half / tanf(0.5f * fov * PK_PI / 180.0f) + 0.5f * e.z;
    pk_camera_init(cam);
    const float from[3] = {c.x, c.y, c.z + dist}, at[3] = {c.x, c.y, c.z};
    memcpy(cam->look_from, from, sizeof from);
    memcpy(cam->look_at, at, sizeof at);
    cam->fov_deg = fov;
}

void camera_look(pk_camera *cam, vec3 from, vec3 at, vec3 up)
{
    pk_camera_init(cam);
    const float v[3][3] = {{from.x, from.y, from.z}, {at.x, at.y, at.z}, {up.x, up.y, up.z}};
    memcpy(cam->look_from, v[0], sizeof v[0]);
    memcpy(cam->look_at, v[1], sizeof v[1]);
    memcpy(cam->up, v[2], sizeof v[2]);
}

camera_problem scene_set_camera(pk_scene *s, const pk_camera *cam)
{
    const camera_problem why = camera_check(cam);
    if (why != CAMERA_OK) return why;
    s->camera = *cam;
    s->has_camera = true;
    return CAMERA_OK;
}
