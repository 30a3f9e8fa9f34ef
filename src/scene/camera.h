/*
 * camera.h - the one camera rule (finite values, fov in (0, 180), distinct
 * eye and target, an up vector that is not parallel to the view, a lens
 * radius, focus distance and orthographic width that are not negative, a
 * known projection) used by the
 * API, JSON scenes and the renderer, and the automatic framing of a scene
 * without a camera.
 */
#ifndef PK_CAMERA_H
#define PK_CAMERA_H

#include "scene.h"

typedef enum camera_problem {
    CAMERA_OK = 0,
    CAMERA_NOT_FINITE,   /* a non-finite value */
    CAMERA_FOV,          /* fov not in (0, 180) */
    CAMERA_TOO_FAR,      /* look_at - look_from overflows */
    CAMERA_SAME_POINT,   /* look_from == look_at */
    CAMERA_UP_ZERO,      /* up is the zero vector */
    CAMERA_UP_PARALLEL,  /* up is parallel to the view direction */
    CAMERA_LENS,         /* lens_radius < 0 */
    CAMERA_FOCUS,        /* focus_distance < 0 */
    CAMERA_PROJECTION,   /* not a pk_projection */
    CAMERA_ORTHO_WIDTH   /* ortho_width < 0 */
} camera_problem;

PK_HIDDEN camera_problem camera_check(const pk_camera *cam);
/* *cam = pk_camera_init's defaults, looking from from toward at with up. */
PK_HIDDEN void camera_look(pk_camera *cam, vec3 from, vec3 at, vec3 up);
/* Makes cam the scene's camera when it passes camera_check; otherwise
 * changes nothing and returns the problem, which the caller reports with
 * its own location. */
PK_HIDDEN camera_problem scene_set_camera(pk_scene *s, const pk_camera *cam);
/* Latches "what: <the problem>" in ctx (ctx may be NULL: nothing is latched). */
PK_HIDDEN pk_status camera_validate(pk_context *ctx, const pk_camera *cam, const char *what);
/* The scene's camera, or one framed on its bounds. */
PK_HIDDEN void scene_camera(const pk_scene *s, pk_camera *cam);

#endif
