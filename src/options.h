/*
 * options.h - render-option defaults and the one range table (options.c).
 * The lowest module after the context: scene, io and api.c use it.
 */
#ifndef PK_OPTIONS_H
#define PK_OPTIONS_H

#include "paprsek_internal.h"

/* The int field of opt that table entry o describes. */
PK_HIDDEN int *options_int_field(pk_render_options *opt, const pk_int_option *o);
/* Ranges of the table, the pixel budget, a known accelerator kind (whether it
 * is built in is api.c's check). Latches "name v is out of range (lo..hi)". */
PK_HIDDEN pk_status options_check(pk_context *ctx, const pk_render_options *opt);
/* Whether f is a filter the renderer can use: a known type, radii in
 * (0, PK_FILTER_MAX_RADIUS], its parameters in range. Latches "filter ...". */
PK_HIDDEN pk_status options_check_filter(pk_context *ctx, const pk_filter *f);
#define PK_FILTER_MAX_RADIUS 16.0f
/* Makes device and accel agree: device PK_DEVICE_CUDA renders on the GPU's
 * structure (accel becomes PK_ACCEL_CUDA); accel PK_ACCEL_CUDA alone is the
 * older spelling of device PK_DEVICE_CUDA. */
PK_HIDDEN void options_resolve_device(pk_render_options *opt);

#endif
