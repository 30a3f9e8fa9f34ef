/*
 * pdict.c - the parameter dictionary (pdict.h): storage, marks, the typed
 * getters with their messages, and the cJSON adapter. The messages are the
 * JSON reader's, word for word: its scenes' tests compare them.
 */
#include "pdict.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

void pd_init(pdict *d, pk_context *ctx, const pd_source *src, void *self, const char *what, bool owns)
{
    memset(d, 0, sizeof *d);
    d->ctx = ctx;
    d->src = src;
    d->self = self;
    d->what = what ? what : "parameters";
    d->owns = owns;
}

static void entry_free(const pk_allocator *a, pd_entry *e)
{
    mem_free(a, (void *)e->name);
    mem_free(a, (void *)e->str);
    mem_free(a, (void *)e->nums);
}

void pd_free(pdict *d)
{
    if (!d || !d->ctx) return;
    for (size_t i = 0; i < d->n; i++) {
        if (d->owns) entry_free(&d->ctx->alloc, &d->e[i]);
        else if (d->own_lists) mem_free(&d->ctx->alloc, (void *)d->e[i].nums); /* the adapter's lists */
    }
    mem_free(&d->ctx->alloc, d->e);
    d->e = NULL;
    d->n = d->cap = 0;
}

/* *dst = a copy of *src that the dictionary owns. */
static pk_status entry_copy(pdict *d, pd_entry *dst, const pd_entry *src)
{
    const pk_allocator *a = &d->ctx->alloc;
    *dst = *src;
    dst->name = NULL, dst->str = NULL, dst->nums = NULL;
    dst->name = mem_strdup(a, src->name);
    if (src->str) dst->str = mem_strdup(a, src->str);
    if (src->n) {
        double *v = mem_alloc(a, src->n * sizeof *v);
        if (v) memcpy(v, src->nums, src->n * sizeof *v);
        dst->nums = v;
    }
    if (!dst->name || (src->str && !dst->str) || (src->n && !dst->nums)) {
        entry_free(a, dst);
        return ctx_nomem(d->ctx);
    }
    return PK_OK;
}

pk_status pd_add(pdict *d, const pd_entry *e)
{
    if (d->n == d->cap) {
        size_t cap = d->cap ? 2 * d->cap : 16;
        pd_entry *ne = mem_realloc_array(&d->ctx->alloc, d->e, cap, sizeof *ne);
        if (!ne) return ctx_nomem(d->ctx);
        d->e = ne;
        d->cap = cap;
    }
    if (!d->owns) {
        d->e[d->n++] = *e;
        return PK_OK;
    }
    pk_status st = entry_copy(d, &d->e[d->n], e);
    if (st == PK_OK) d->n++;
    return st;
}

pk_status pd_set(pdict *d, const pd_entry *e)
{
    for (size_t i = 0; i < d->n; i++) {
        if (strcmp(d->e[i].name, e->name) != 0) continue;
        if (!d->owns) {
            if (d->own_lists) mem_free(&d->ctx->alloc, (void *)d->e[i].nums);
            d->e[i] = *e;
            return PK_OK;
        }
        pd_entry c;
        pk_status st = entry_copy(d, &c, e);
        if (st) return st;
        entry_free(&d->ctx->alloc, &d->e[i]);
        d->e[i] = c;
        return PK_OK;
    }
    return pd_add(d, e);
}

void pd_clear_marks(pdict *d)
{
    for (size_t i = 0; i < d->n; i++) d->e[i].used = false;
}

void pd_mark_all(pdict *d)
{
    for (size_t i = 0; i < d->n; i++) d->e[i].used = true;
}

const pd_entry *pd_get(pdict *d, const char *name)
{
    for (size_t i = 0; i < d->n; i++)
        if (strcmp(d->e[i].name, name) == 0) {
            d->e[i].used = true;
            return &d->e[i];
        }
    return NULL;
}

void pd_declare(pdict *d, const char *const *names, size_t n)
{
    for (size_t i = 0; i < d->n; i++)
        for (size_t k = 0; k < n; k++)
            if (strcmp(d->e[i].name, names[k]) == 0) d->e[i].used = true;
}

pk_status pd_report_unused(pdict *d)
{
    for (size_t i = 0; i < d->n; i++) {
        const pd_entry *e = &d->e[i];
        if (!e->used) {
            if (d->src && d->src->warn_unused) d->src->warn_unused(d->self, d, e);
            else ctx_warn(d->ctx, "%s: %s: unknown parameter ignored", d->what, e->name);
            continue;
        }
        for (size_t k = 0; k < i && !d->dups; k++)
            if (strcmp(d->e[k].name, e->name) == 0) return pd_fail(d, e, -1, PK_ERR_PARSE, "duplicate key");
    }
    return PK_OK;
}

pk_status pd_fail(const pdict *d, const pd_entry *e, long elem, pk_status st, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    if (d->src && d->src->fail) return d->src->fail(d->self, d, e, elem, st, msg);
    if (!e || elem == PD_AT_ENTRY) return ctx_error(d->ctx, st, "%s: %s", d->what, msg);
    if (elem >= 0) return ctx_error(d->ctx, st, "%s: %s[%ld]: %s", d->what, e->name, elem, msg);
    return ctx_error(d->ctx, st, "%s: %s: %s", d->what, e->name, msg);
}

/* ---- typed getters ---------------------------------------------------------- */

static pk_status number_of(const pdict *d, const pd_entry *e, float *out)
{
    if (e->kind != PD_NUMBER) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a number");
    float f = (float)e->num;
    if (!isfinite(f)) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a finite number");
    *out = f;
    return PK_OK;
}

pk_status pd_float(pdict *d, const char *name, float def, pd_range r, float *out)
{
    const pd_entry *e = pd_get(d, name);
    if (!e) {
        *out = def;
        return PK_OK;
    }
    float f = 0.0f;
    pk_status st = number_of(d, e, &f);
    if (st) return st;
    switch (r) {
    case PD_ANY: break;
    case PD_UNIT:
        if (!(f >= 0.0f && f <= 1.0f)) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be in 0..1");
        break;
    case PD_POSITIVE:
        if (!(f > 0.0f)) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a positive number");
        break;
    case PD_NONNEG:
        if (f < 0.0f) return pd_fail(d, e, -1, PK_ERR_PARSE, "must not be negative");
        break;
    }
    *out = f;
    return PK_OK;
}

static pk_status floats_of(const pdict *d, const pd_entry *e, int n, float *out)
{
    if (e->kind != PD_NUMBERS || e->n != (size_t)n)
        return pd_fail(d, e, -1, PK_ERR_PARSE, "must be an array of %d numbers", n);
    for (size_t i = 0; i < e->n; i++) {
        if (i >= e->first_other) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be an array of %d numbers", n);
        out[i] = (float)e->nums[i];
        if (!isfinite(out[i])) return pd_fail(d, e, (long)i, PK_ERR_PARSE, "numbers must be finite");
    }
    return PK_OK;
}

pk_status pd_floats(pdict *d, const char *name, int n, float *out)
{
    const pd_entry *e = pd_get(d, name);
    return e ? floats_of(d, e, n, out) : PK_OK;
}

pk_status pd_vec3(pdict *d, const char *name, vec3 def, pd_vrange r, vec3 *out)
{
    const pd_entry *e = pd_get(d, name);
    if (!e) {
        *out = def;
        return PK_OK;
    }
    float f[3];
    pk_status st = floats_of(d, e, 3, f);
    if (st) return st;
    const vec3 v = v3(f[0], f[1], f[2]);
    switch (r) {
    case PD_V_ANY: break;
    case PD_V_COLOUR:
        if (v.x < 0.0f || v.y < 0.0f || v.z < 0.0f)
            return pd_fail(d, e, -1, PK_ERR_PARSE, "colour components must not be negative");
        break;
    case PD_V_REFLECTANCE:
        if (!(v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f && v.x <= 1.0f && v.y <= 1.0f && v.z <= 1.0f))
            return pd_fail(d, e, -1, PK_ERR_PARSE, "components must be in 0..1");
        break;
    case PD_V_POSITIVE:
        if (!(v.x > 0.0f && v.y > 0.0f && v.z > 0.0f))
            return pd_fail(d, e, -1, PK_ERR_PARSE, "components must be positive");
        break;
    case PD_V_NONNEG:
        if (!(v.x >= 0.0f && v.y >= 0.0f && v.z >= 0.0f))
            return pd_fail(d, e, -1, PK_ERR_PARSE, "components must not be negative");
        break;
    }
    *out = v;
    return PK_OK;
}

pk_status pd_int(pdict *d, const char *name, int def, int lo, int hi, int *out)
{
    const pd_entry *e = pd_get(d, name);
    if (!e) {
        *out = def;
        return PK_OK;
    }
    if (e->kind != PD_NUMBER || e->num != floor(e->num)) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be an integer");
    const double v = e->num;
    if (v < (double)lo || v > (double)hi)
        return pd_fail(d, e, -1, v > (double)hi ? PK_ERR_LIMIT : PK_ERR_PARSE, "must be an integer in %d..%d", lo, hi);
    *out = (int)v;
    return PK_OK;
}

pk_status pd_bool(pdict *d, const char *name, bool def, bool *out)
{
    const pd_entry *e = pd_get(d, name);
    if (!e) {
        *out = def;
        return PK_OK;
    }
    if (e->kind != PD_BOOL) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be true or false");
    *out = e->b;
    return PK_OK;
}

pk_status pd_string(pdict *d, const char *name, const char *def, const char **out)
{
    const pd_entry *e = pd_get(d, name);
    if (!e) {
        *out = def;
        return PK_OK;
    }
    if (e->kind != PD_STRING || !e->str[0]) return pd_fail(d, e, -1, PK_ERR_PARSE, "must be a non-empty string");
    *out = e->str;
    return PK_OK;
}

pk_status pd_texture(pdict *d, const pd_entry *e, bool colour, tex_ref *ref, bool *loaded)
{
    if (!d->src || !d->src->texture) return pd_fail(d, e, -1, PK_ERR_UNSUPPORTED, "textures are not supported here");
    return d->src->texture(d->self, d, e, colour, ref, loaded);
}

pk_status pd_nested(pdict *d, const pd_entry *e, pdict *sub)
{
    pd_init(sub, d->ctx, d->src, d->self, d->what, d->owns);
    if (!d->src || !d->src->nested)
        return pd_fail(d, e, -1, PK_ERR_UNSUPPORTED, "nested objects are not supported here");
    return d->src->nested(d->self, d, e, sub);
}

/* ---- the cJSON adapter ---------------------------------------------------------- */

pk_status pd_from_cjson(pdict *d, const cJSON *obj, const char *path)
{
    snprintf(d->path, sizeof d->path, "%s", path);
    d->node = obj;
    d->own_lists = !d->owns;
    const pk_allocator *a = &d->ctx->alloc;
    for (const cJSON *m = obj ? obj->child : NULL; m; m = m->next) {
        pd_entry e = {.name = m->string ? m->string : "", .node = m, .kind = PD_OTHER};
        double *nums = NULL;
        if (cJSON_IsNumber(m)) {
            e.kind = PD_NUMBER;
            e.num = m->valuedouble;
        } else if (cJSON_IsBool(m)) {
            e.kind = PD_BOOL;
            e.b = cJSON_IsTrue(m);
        } else if (cJSON_IsString(m)) {
            e.kind = PD_STRING;
            e.str = m->valuestring;
        } else if (cJSON_IsNull(m)) {
            e.kind = PD_NULL;
        } else if (cJSON_IsObject(m)) {
            e.kind = PD_OBJECT;
        } else if (cJSON_IsArray(m)) {
            e.kind = PD_NUMBERS;
            e.n = (size_t)cJSON_GetArraySize(m);
            e.first_other = e.n;
            if (e.n) {
                nums = mem_alloc(a, e.n * sizeof *nums);
                if (!nums) return ctx_nomem(d->ctx);
                size_t i = 0;
                for (const cJSON *c = m->child; c; c = c->next, i++) {
                    nums[i] = cJSON_IsNumber(c) ? c->valuedouble : 0.0;
                    if (!cJSON_IsNumber(c) && e.first_other == e.n) e.first_other = i;
                }
            }
            e.nums = nums;
        }
        /* a borrowing dictionary still owns the lists made here: pd_free frees them */
        pk_status st = pd_add(d, &e);
        if (st || d->owns) mem_free(a, nums); /* an owning dictionary copied it */
        if (st) return st;
    }
    return PK_OK;
}
