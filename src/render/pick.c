/*
 * pick.c - the surface under a point of the image (pk_renderer_pick), for a
 * viewer that focuses where the user clicks: one ray from the centre of the
 * lens, traced through the renderer's accelerator (read only) past holes.
 */
#include "render.h"

#include "../scene/camera.h"
#include "camera.h"
#include "surface.h"

#include <math.h>
#include <string.h>

pk_status renderer_pick(const pk_renderer *r, const pk_camera *cam_in, double x, double y, pk_pick *out)
{
    memset(out, 0, sizeof *out);
    out->material = "";
    const pk_render_options *o = renderer_options(r);
    if (!(x >= 0.0 && x <= (double)o->width && y >= 0.0 && y <= (double)o->height)) return PK_ERR_INVALID_ARGUMENT;
    pk_camera cam = cam_in ? *cam_in : *renderer_camera(r);
    if (camera_check(&cam) != CAMERA_OK) return PK_ERR_INVALID_ARGUMENT;
    cam.lens_radius = 0.0f; /* the ray through the lens's centre: the one every lens sample focuses on */
    const camera_frame cf = camera_setup(&cam, o->width, o->height);
    const camera_sample cs = {(float)x, (float)y, 0.5f, 0.5f, 1.0f};
    ray ry = camera_ray(&cf, &cs);
    const frame *fr = renderer_frame(r);
    hit h;
    bool found = accel_intersect(fr->a, &ry, &h, NULL);
    if (found && fr->v.has_cutout) found = trace_past_holes(fr->a, &fr->v, &ry, &h, NULL);
    if (!found || !isfinite(h.t)) return PK_OK;
    const surface sf = surface_at(&fr->v, &ry, &h);
    out->hit = 1;
    out->t = h.t;
    /* along the view direction (-w): the plane in focus is measured so */
    const float along = -v3_dot(ry.d, cf.w);
    out->distance = cf.ortho ? h.t : h.t * along;
    out->position[0] = sf.p.x, out->position[1] = sf.p.y, out->position[2] = sf.p.z;
    out->normal[0] = sf.ns.x, out->normal[1] = sf.ns.y, out->normal[2] = sf.ns.z;
    out->prim = h.prim;
    if (sf.m && sf.m->name) out->material = sf.m->name;
    return PK_OK;
}
