/*
 * create_light.c - point, spot and distant lights from a pdict
 * (create_light.h), with the JSON reader's rules and messages, added by the
 * scene's light constructors.
 */
#include "create_light.h"

#include <math.h>
#include <string.h>

pk_status create_light(pdict *d, pk_scene *s)
{
    point_light light, *l = &light;
    static const char *const keys[] = {"type",      "position",    "intensity",  "color",
                                       "direction", "outer_angle", "inner_angle"};
    pd_declare(d, keys, sizeof keys / sizeof keys[0]);
    pk_status st = pd_report_unused(d);
    if (st) return st;
    memset(l, 0, sizeof *l);
    int kind = 0; /* 0 point, 1 spot, 2 distant */
    const pd_entry *e = pd_get(d, "type");
    if (e) {
        const char *t = e->kind == PD_STRING ? e->str : "";
        if (strcmp(t, "point") == 0) kind = 0;
        else if (strcmp(t, "spot") == 0) kind = 1;
        else if (strcmp(t, "distant") == 0) kind = 2;
        else return pd_fail(d, e, -1, PK_ERR_PARSE, "must be \"point\", \"spot\" or \"distant\"");
    }
    const pd_entry *pos = pd_get(d, "position"), *dir = pd_get(d, "direction"), *outer_e = pd_get(d, "outer_angle"),
                   *inner_e = pd_get(d, "inner_angle");
    if (kind != 2) {
        if (!pos) return pd_fail(d, NULL, -1, PK_ERR_PARSE, "missing \"position\"");
        if ((st = pd_vec3(d, "position", l->position, PD_V_ANY, &l->position))) return st;
    } else if (pos) {
        return pd_fail(d, pos, PD_AT_ENTRY, PK_ERR_PARSE, "a distant light has no \"position\"");
    }
    if (kind == 0 && (dir || outer_e || inner_e))
        return pd_fail(d, NULL, -1, PK_ERR_PARSE,
                       "a point light has no \"direction\" or cone angles (\"type\": \"spot\")");
    if (kind != 0) {
        if (!dir) return pd_fail(d, NULL, -1, PK_ERR_PARSE, "missing \"direction\"");
        vec3 v;
        if ((st = pd_vec3(d, "direction", v3s(0.0f), PD_V_ANY, &v))) return st;
        const float len = v3_len(v);
        if (!(len > 0.0f) || !isfinite(len)) return pd_fail(d, dir, -1, PK_ERR_PARSE, "must be a non-zero vector");
        v = v3_scale(v, 1.0f / len);
        if (kind == 2) {
            l->distant = true;
            l->position = v3_neg(v); /* toward the light */
        } else {
            float outer = 30.0f, inner = -1.0f;
            if (outer_e) {
                if ((st = pd_float(d, "outer_angle", outer, PD_ANY, &outer))) return st;
                if (!(outer > 0.0f && outer <= 180.0f))
                    return pd_fail(d, outer_e, -1, PK_ERR_PARSE, "must be in (0, 180] degrees");
            }
            if (inner_e) {
                if ((st = pd_float(d, "inner_angle", inner, PD_ANY, &inner))) return st;
                if (!(inner >= 0.0f && inner <= outer))
                    return pd_fail(d, inner_e, -1, PK_ERR_PARSE, "must be in [0, outer_angle] degrees");
            } else {
                inner = 0.8f * outer;
            }
            l->spot_dir = v;
            l->cos_outer = cosf(outer * PK_PI / 180.0f);
            l->cos_inner = cosf(inner * PK_PI / 180.0f);
            l->spot_falloff = SPOT_FALLOFF_SMOOTHSTEP;
        }
    } else if (outer_e || inner_e) {
        return pd_fail(d, NULL, -1, PK_ERR_PARSE, "cone angles belong to a spot light");
    }
    vec3 intensity = v3s(1.0f), color = v3s(1.0f);
    if ((e = pd_get(d, "intensity"))) {
        if (e->kind == PD_NUMBER) {
            if ((st = pd_float(d, "intensity", 1.0f, PD_ANY, &intensity.x))) return st;
            intensity.y = intensity.z = intensity.x;
        } else if (e->kind != PD_NUMBERS) {
            return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a number or an array of 3 numbers");
        } else if ((st = pd_vec3(d, "intensity", intensity, PD_V_ANY, &intensity))) {
            return st;
        }
        if (intensity.x < 0.0f || intensity.y < 0.0f || intensity.z < 0.0f)
            return pd_fail(d, e, -1, PK_ERR_PARSE, "must not be negative");
    }
    if ((st = pd_vec3(d, "color", color, PD_V_COLOUR, &color))) return st;
    l->intensity = v3_mul(intensity, color);
    if (!v3_finite(l->intensity)) return pd_fail(d, NULL, -1, PK_ERR_PARSE, "intensity * color is not finite");
    pk_context *ctx = d->ctx;
    if (kind == 2) return scene_light_distant(ctx, s, l->position, l->intensity);
    if (kind == 1)
        return scene_light_spot(ctx, s, l->position, l->spot_dir, l->cos_inner, l->cos_outer, l->spot_falloff,
                                l->intensity);
    return scene_light_point(ctx, s, l->position, l->intensity);
}
