/*
 * pbrt_param.c - pbrt-v4 parameter lists (pbrt_param.h): reading, the pdict
 * they are offered as, and the typed getters. Messages are the pbrt
 * reader's, word for word; its tests compare them.
 */
#include "pbrt_param.h"

#include "io_util.h"

#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>

static const struct {
    const char *name;
    ptype type;
} ptype_names[] = {{"integer", PT_INT},    {"float", PT_FLOAT},     {"point2", PT_POINT2},   {"vector2", PT_VECTOR2},
                   {"point3", PT_POINT3},  {"point", PT_POINT3},    {"vector3", PT_VECTOR3}, {"vector", PT_VECTOR3},
                   {"normal", PT_NORMAL},  {"normal3", PT_NORMAL},  {"rgb", PT_RGB},         {"color", PT_RGB},
                   {"spectrum", PT_SPECTRUM}, {"blackbody", PT_BLACKBODY}, {"string", PT_STRING},
                   {"texture", PT_TEXTURE}, {"bool", PT_BOOL}};

void pb_param_free(const pk_allocator *a, pparam *q)
{
    mem_free(a, q->num);
    for (size_t k = 0; k < q->nstr; k++) mem_free(a, q->str[k]);
    mem_free(a, q->str);
    q->num = NULL, q->str = NULL, q->nnum = q->nstr = 0;
}

pk_status pb_param_copy(pk_context *ctx, const pparam *q, pparam *out)
{
    const pk_allocator *a = &ctx->alloc;
    *out = *q;
    out->num = NULL, out->str = NULL, out->cap_num = q->nnum, out->cap_str = q->nstr;
    if (q->nnum && !(out->num = mem_calloc(a, q->nnum, sizeof *q->num))) goto nomem;
    if (q->nnum) memcpy(out->num, q->num, q->nnum * sizeof *q->num);
    if (q->nstr && !(out->str = mem_calloc(a, q->nstr, sizeof *q->str))) goto nomem;
    for (size_t k = 0; k < q->nstr; k++)
        if (!(out->str[k] = mem_strdup(a, q->str[k]))) goto nomem;
    return PK_OK;
nomem:
    pb_param_free(a, out);
    return ctx_nomem(ctx);
}

void pb_list_clear(pdict *d, plist *pl)
{
    for (size_t i = 0; i < pl->n; i++) pb_param_free(&d->ctx->alloc, &pl->p[i]);
    pl->n = 0;
    pd_free(d);
}

pk_status pb_fail(pdict *d, size_t line, pk_status st, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    const pd_entry at = {.name = "", .line = line};
    return pd_fail(d, &at, -1, st, "%s", msg);
}

pk_status pd_from_pbrt(pdict *d, const plist *pl)
{
    pd_free(d);
    for (size_t i = 0; i < pl->n; i++) {
        const pparam *q = &pl->p[i];
        pd_entry e = {.name = q->name, .type = q->tname, .line = q->line, .node = q, .used = q->from_attribute};
        if (q->type == PT_BOOL && q->nnum == 1) {
            e.kind = PD_BOOL, e.b = q->num[0] != 0.0;
        } else if (q->nstr) {
            e.kind = q->nstr == 1 ? PD_STRING : PD_OTHER, e.str = q->str[0];
        } else {
            e.kind = q->nnum == 1 ? PD_NUMBER : PD_NUMBERS, e.num = q->nnum ? q->num[0] : 0.0;
            e.nums = q->num, e.n = e.first_other = q->nnum;
        }
        pk_status st = pd_add(d, &e);
        if (st) return st;
    }
    return PK_OK;
}

static bool is_stringish(ptype t) { return t == PT_STRING || t == PT_TEXTURE; }

static pk_status push_num(pdict *d, pparam *q, double v)
{
    if (!mem_grow(&d->ctx->alloc, (void **)&q->num, &q->cap_num, q->nnum + 1, sizeof *q->num)) return ctx_nomem(d->ctx);
    q->num[q->nnum++] = v;
    return PK_OK;
}

static pk_status push_str(pdict *d, pparam *q, const pbrt_token *tk)
{
    if (!mem_grow(&d->ctx->alloc, (void **)&q->str, &q->cap_str, q->nstr + 1, sizeof *q->str)) return ctx_nomem(d->ctx);
    char *s = mem_alloc(&d->ctx->alloc, tk->len + 1);
    if (!s) return ctx_nomem(d->ctx);
    pbrt_tok_string(tk, s, tk->len + 1);
    q->str[q->nstr++] = s;
    return PK_OK;
}

static pk_status tok_error(pdict *d, const pbrt_tokenizer *t, const pbrt_token *tk)
{
    return pb_fail(d, tk->line, PK_ERR_PARSE, "%s", t->why);
}

/* One value token of parameter q. */
static pk_status param_value(pdict *d, const pbrt_tokenizer *t, pparam *q, const pbrt_token *tk)
{
    if (tk->kind == PBRT_TOK_ERROR) return tok_error(d, t, tk);
    if (q->type == PT_BOOL) {
        if (pbrt_tok_is(tk, "true")) return push_num(d, q, 1.0);
        if (pbrt_tok_is(tk, "false")) return push_num(d, q, 0.0);
        return pb_fail(d, tk->line, PK_ERR_PARSE, "'bool %s' takes true or false, not '%.*s'", q->name,
                       io_tok_len(tk->text, tk->text + tk->len), tk->text);
    }
    if (tk->kind == PBRT_TOK_NUMBER && !is_stringish(q->type)) {
        if (q->type == PT_INT && !tk->integer)
            return pb_fail(d, tk->line, PK_ERR_PARSE, "'integer %s' takes integers, not '%.*s'", q->name,
                           io_tok_len(tk->text, tk->text + tk->len), tk->text);
        if (!isfinite(tk->number))
            return pb_fail(d, tk->line, PK_ERR_PARSE, "'%s %s': number '%.*s' is not finite", q->tname, q->name,
                           io_tok_len(tk->text, tk->text + tk->len), tk->text);
        return push_num(d, q, tk->number);
    }
    if (tk->kind == PBRT_TOK_STRING && (is_stringish(q->type) || q->type == PT_SPECTRUM)) return push_str(d, q, tk);
    const char *want = is_stringish(q->type) ? "strings" : q->type == PT_SPECTRUM ? "numbers or a name" : "numbers";
    return pb_fail(d, tk->line, PK_ERR_PARSE, "'%s %s' takes %s, not '%.*s'", q->tname, q->name, want,
                   io_tok_len(tk->text, tk->text + tk->len), tk->text);
}

/* The parameter list that follows a directive's arguments: "type name"
 * followed by one value or a bracketed list of values. */
pk_status pb_read_params(pdict *d, plist *pl, pbrt_tokenizer *t)
{
    pk_status st;
    pb_list_clear(d, pl);
    for (;;) {
        pbrt_token tk = pbrt_tok_peek(t);
        if (tk.kind != PBRT_TOK_STRING) return tk.kind == PBRT_TOK_ERROR ? tok_error(d, t, &tk) : pd_from_pbrt(d, pl);
        pbrt_tok_next(t);
        char decl[160];
        pbrt_tok_string(&tk, decl, sizeof decl);
        char tn[32] = "", nm[96] = "", extra[8] = "";
        int got = sscanf(decl, "%31s %95s %7s", tn, nm, extra);
        if (got != 2)
            return pb_fail(d, tk.line, PK_ERR_PARSE, "expected a parameter \"type name\", found \"%.*s\"",
                           io_tok_len(tk.text, tk.text + tk.len), tk.text);
        int type = -1;
        for (size_t i = 0; i < sizeof ptype_names / sizeof ptype_names[0]; i++)
            if (strcmp(tn, ptype_names[i].name) == 0) type = (int)ptype_names[i].type;
        if (type < 0) return pb_fail(d, tk.line, PK_ERR_PARSE, "unknown parameter type '%s' (in \"%s\")", tn, decl);
        if (strlen(nm) >= sizeof pl->p[0].name)
            return pb_fail(d, tk.line, PK_ERR_PARSE, "parameter name '%.40s...' is too long", nm);
        for (size_t i = 0; i < pl->n; i++)
            if (strcmp(pl->p[i].name, nm) == 0)
                return pb_fail(d, tk.line, PK_ERR_PARSE, "parameter '%s' is given twice", nm);
        if (!mem_grow(&d->ctx->alloc, (void **)&pl->p, &pl->cap, pl->n + 1, sizeof *pl->p)) return ctx_nomem(d->ctx);
        pparam *q = &pl->p[pl->n++];
        memset(q, 0, sizeof *q);
        q->type = (ptype)type;
        snprintf(q->tname, sizeof q->tname, "%s", tn);
        snprintf(q->name, sizeof q->name, "%s", nm);
        q->line = tk.line;
        pbrt_token v = pbrt_tok_next(t);
        if (v.kind == PBRT_TOK_LBRACK) {
            for (;;) {
                v = pbrt_tok_next(t);
                if (v.kind == PBRT_TOK_RBRACK) break;
                if (v.kind == PBRT_TOK_END)
                    return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s': the list has no closing ']'", tn, nm);
                if ((st = param_value(d, t, q, &v))) return st;
            }
        } else if (v.kind == PBRT_TOK_END) {
            return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' has no value", tn, nm);
        } else if ((st = param_value(d, t, q, &v))) {
            return st;
        }
        /* counts */
        size_t n = q->nnum + q->nstr, per = 1;
        if (q->type == PT_POINT2 || q->type == PT_VECTOR2) per = 2;
        if (q->type == PT_POINT3 || q->type == PT_VECTOR3 || q->type == PT_NORMAL || q->type == PT_RGB) per = 3;
        if (n == 0) return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' has no value", tn, nm);
        if (n % per)
            return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' has %zu values, not a multiple of %zu", tn, nm, n, per);
        if (q->type == PT_SPECTRUM && q->nnum && (q->nstr || q->nnum % 2))
            return pb_fail(d, q->line, PK_ERR_PARSE,
                           "'spectrum %s' takes (wavelength, value) pairs or one name, not %zu values", nm, n);
        if (q->type == PT_SPECTRUM && q->nstr > 1)
            return pb_fail(d, q->line, PK_ERR_PARSE, "'spectrum %s' takes one name", nm);
    }
}

pparam *pb_param(pdict *d, const char *name)
{
    const pd_entry *e = pd_get(d, name);
    return e ? (pparam *)e->node : NULL;
}

pk_status pb_typed(pdict *d, const char *name, unsigned types, const char *want, pparam **out)
{
    pparam *q = pb_param(d, name);
    *out = NULL;
    if (!q) return PK_OK;
    if (!(types & (1u << q->type)))
        return pb_fail(d, q->line, PK_ERR_PARSE, "parameter '%s %s' should be %s", q->tname, q->name, want);
    *out = q;
    return PK_OK;
}

pk_status pb_float(pdict *d, const char *name, float *v)
{
    pparam *q;
    pk_status st = pb_typed(d, name, TB(PT_FLOAT) | TB(PT_INT), "a float", &q);
    if (st || !q) return st;
    if (q->nnum != 1)
        return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' takes one value, not %zu", q->tname, name, q->nnum);
    *v = (float)q->num[0];
    if (!isfinite(*v)) return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' is not a finite float", q->tname, name);
    return PK_OK;
}

pk_status pb_int(pdict *d, const char *name, int64_t lo, int64_t hi, int64_t *v)
{
    pparam *q;
    pk_status st = pb_typed(d, name, TB(PT_INT), "an integer", &q);
    if (st || !q) return st;
    if (q->nnum != 1) return pb_fail(d, q->line, PK_ERR_PARSE, "'integer %s' takes one value, not %zu", name, q->nnum);
    if (q->num[0] < (double)lo || q->num[0] > (double)hi)
        return pb_fail(d, q->line, PK_ERR_PARSE, "'integer %s' %.0f is outside %lld..%lld", name, q->num[0],
                       (long long)lo, (long long)hi);
    *v = (int64_t)q->num[0];
    return PK_OK;
}

pk_status pb_bool(pdict *d, const char *name, bool *v)
{
    pparam *q;
    pk_status st = pb_typed(d, name, TB(PT_BOOL), "a bool", &q);
    if (st || !q) return st;
    if (q->nnum != 1) return pb_fail(d, q->line, PK_ERR_PARSE, "'bool %s' takes one value, not %zu", name, q->nnum);
    *v = q->num[0] != 0.0;
    return PK_OK;
}

pk_status pb_string(pdict *d, const char *name, const char **v)
{
    pparam *q;
    pk_status st = pb_typed(d, name, TB(PT_STRING), "a string", &q);
    if (st || !q) return st;
    if (q->nstr != 1) return pb_fail(d, q->line, PK_ERR_PARSE, "'string %s' takes one value, not %zu", name, q->nstr);
    *v = q->str[0];
    return PK_OK;
}

pk_status pb_vec3(pdict *d, const char *name, vec3 *v)
{
    pparam *q;
    pk_status st = pb_typed(d, name, TB(PT_POINT3) | TB(PT_VECTOR3) | TB(PT_NORMAL) | TB(PT_RGB), "3 numbers", &q);
    if (st || !q) return st;
    if (q->nnum != 3)
        return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' takes 3 values, not %zu", q->tname, name, q->nnum);
    *v = v3((float)q->num[0], (float)q->num[1], (float)q->num[2]);
    if (!v3_finite(*v)) return pb_fail(d, q->line, PK_ERR_PARSE, "'%s %s' is not finite in float", q->tname, name);
    return PK_OK;
}
