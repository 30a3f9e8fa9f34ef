/*
 * filter.c - the pixel filter's sampling, built once per renderer
 * (filter.h).
 */
#include "filter.h"

#include <string.h>

/* Sub-samples per cell for the cells' means (Simpson's rule). */
#define FILTER_SUBSTEPS 16

/* The mean of f's profile over [a, b] (Simpson's rule on FILTER_SUBSTEPS intervals). */
static double profile_mean(const pk_filter *f, double r, double a, double b)
{
    const double h = (b - a) / FILTER_SUBSTEPS;
    double s = filter_profile(f, r, a) + filter_profile(f, r, b);
    for (int k = 1; k < FILTER_SUBSTEPS; k++) s += (k & 1 ? 4.0 : 2.0) * filter_profile(f, r, a + h * k);
    return s * h / 3.0 / (b - a);
}

static pk_status build_axis(pk_context *ctx, const pk_filter *f, float radius, const char *axis, filter_axis *a)
{
    memset(a, 0, sizeof *a);
    a->radius = radius;
    a->weight = 1.0f;
    if (f->type == PK_FILTER_BOX) {
        a->kind = radius == 0.5f ? FILTER_PIXEL : FILTER_UNIFORM;
        return PK_OK;
    }
    if (f->type == PK_FILTER_TRIANGLE) {
        a->kind = FILTER_TENT;
        return PK_OK;
    }
    a->kind = FILTER_TABLE;
    const double r = radius;
    double v[FILTER_CELLS], sum = 0.0, sum_abs = 0.0;
    for (int i = 0; i < FILTER_CELLS; i++) {
        const double x0 = -r + 2.0 * r * i / FILTER_CELLS, x1 = -r + 2.0 * r * (i + 1) / FILTER_CELLS;
        v[i] = profile_mean(f, r, x0, x1);
        sum += v[i];
        sum_abs += fabs(v[i]);
        if (v[i] < 0.0) a->negative[i >> 5] |= 1u << (i & 31);
    }
    if (!(sum > 1e-6 * sum_abs) || !isfinite(sum_abs))
        return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT,
                         "filter %s: its %s profile integrates to %g (it must be positive)", pk_filter_name(f->type),
                         axis, sum * 2.0 * r / FILTER_CELLS);
    double c = 0.0;
    a->cdf[0] = 0.0f;
    for (int i = 0; i < FILTER_CELLS; i++) {
        c += fabs(v[i]);
        a->cdf[i + 1] = (float)(c / sum_abs);
    }
    a->cdf[FILTER_CELLS] = 1.0f;
    for (int j = 0, i = 0; j < FILTER_GUIDE; j++) {
        const float u = (float)j / (float)FILTER_GUIDE;
        while (i < FILTER_CELLS - 1 && a->cdf[i + 1] <= u) i++;
        a->guide[j] = (uint8_t)i;
    }
    a->weight = (float)(sum_abs / sum);
    return PK_OK;
}

pk_status filter_build(pk_context *ctx, const pk_filter *f, pixel_filter *out)
{
    pk_status st = build_axis(ctx, f, f->radius_x, "x", &out->x);
    if (st == PK_OK) st = build_axis(ctx, f, f->radius_y, "y", &out->y);
    return st;
}
