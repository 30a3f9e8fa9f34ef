/*
 * render.h - render sessions, the renderer's interface to api.c: a frame
 * built once (accelerator, lights), a camera that may change, and renders of
 * any set of regions into a film, in parallel over 16x16 tiles.
 */
#ifndef PK_RENDER_H
#define PK_RENDER_H

#include "../image/image.h"
#include "frame.h"

/* opt has passed pk_render_options_check and cam camera_validate. */
PK_HIDDEN pk_status renderer_create(pk_context *ctx, const pk_scene *s, const pk_render_options *opt,
                                    const pk_camera *cam, pk_renderer **out);
PK_HIDDEN void renderer_destroy(pk_renderer *r);
PK_HIDDEN pk_context *renderer_context(const pk_renderer *r);
PK_HIDDEN const pk_render_options *renderer_options(const pk_renderer *r);
/* cam has passed camera_validate. */
PK_HIDDEN void renderer_set_camera(pk_renderer *r, const pk_camera *cam);
PK_HIDDEN const pk_camera *renderer_camera(const pk_renderer *r);
/* regions NULL: the whole image; film has the renderer's size. Regions are
 * checked here (inside the image, not empty, not overlapping). */
PK_HIDDEN pk_status renderer_render(pk_renderer *r, const pk_region *regions, size_t n, pk_film *film);
PK_HIDDEN void renderer_stats(const pk_renderer *r, pk_stats *stats);
PK_HIDDEN void renderer_set_pass(pk_renderer *r, uint32_t pass);
PK_HIDDEN uint32_t renderer_pass(const pk_renderer *r);
/* What the renderer built once (read only; pick.c). */
PK_HIDDEN const frame *renderer_frame(const pk_renderer *r);
/* pk_renderer_pick (pick.c); r and out are not NULL. */
PK_HIDDEN pk_status renderer_pick(const pk_renderer *r, const pk_camera *cam, double x, double y, pk_pick *out);
/* Tests: the path tracer's direct-light strategy (PATH_* of path.h). */
PK_HIDDEN void renderer_set_path_strategy(pk_renderer *r, int strategy);

#endif
