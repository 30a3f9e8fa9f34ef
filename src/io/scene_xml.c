/*
 * scene_xml.c - Mitsuba XML scenes (versions 0.4-0.6 with camelCase names,
 * 2.x/3.x with snake_case names) read with expat into a small tree, then
 * mapped onto a pk_scene: shapes (obj, ply, rectangle, cube, disk, sphere),
 * BSDFs onto the material types, emitters (area, point, environment),
 * the perspective, thinlens and orthographic sensors, film, sampler and
 * integrator settings (docs/scene-format.md, "Mitsuba XML"), participating
 * media (homogeneous and heterogeneous, phase functions, grid volumes,
 * shapes' interior and exterior, the sensor's medium: docs/media.md). Errors and
 * warnings read "file:line: what"; what is not supported is warned about
 * and skipped.
 *
 * expat allocates with the C library's malloc (its memory hooks take no user
 * pointer, so they cannot reach a context); everything else goes through the
 * context's allocator.
 */
#include "grid_io.h"
#include "io_util.h"
#include "pdict.h"
#include "readers.h"
#include "scene_build.h"
#include "../math/xform.h"
#include "../options.h"
#include "../scene/camera.h"
#include "../scene/scene.h"
#include "../scene/spectra.h"
#include "../scene/texture.h"

#include <expat.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define XML_MAX_NODES (1u << 20)      /* elements in a scene and its includes */
#define XML_MAX_DEPTH 64              /* nesting of elements */
#define XML_MAX_INCLUDE_DEPTH 8       /* <include> inside <include> ... */
#define XML_MAX_FILES 256             /* files read through <include> */
#define XML_MAX_BSDF_DEPTH 16         /* nested bsdfs and references */
#define XML_MAX_VALUE 4096            /* bytes of an attribute after $ substitution */
#define XML_MAX_PARAMS 256            /* <default> parameters */
#define XML_MAX_WARN_KINDS 64         /* distinct "not supported" warnings remembered */
#define XML_SPHERE_RINGS 32
#define XML_SPHERE_SEGMENTS 64
#define XML_DISK_SEGMENTS 64
#define XML_DEFAULT_FOV 45.0f         /* Mitsuba's perspective default (fov_axis x) */
#define XML_DEFAULT_WIDTH 768         /* Mitsuba's film default */
#define XML_DEFAULT_HEIGHT 576

/* ---- the tree --------------------------------------------------------------- */

typedef struct xml_file {
    const char *shown;   /* name in messages */
    const char *dir;     /* relative file names are resolved against it */
} xml_file;

typedef struct xattr {
    const char *name, *value;
} xattr;

/* One element. Attribute values are kept as written; $name substitution
 * happens when they are read (attr()). */
typedef struct xnode {
    const char *tag;
    xattr *attrs;
    int nattrs;
    struct xnode *parent, *child, *last, *next;
    const xml_file *file;
    unsigned long line;
    int64_t mat;         /* material made of this bsdf, -1 before */
    int64_t mesh;        /* mesh made of this shapegroup, -1 before */
    int64_t medium;      /* scene medium made of this medium, -1 before */
    bool busy;           /* a bsdf being converted (reference cycles) */
} xnode;

typedef struct arena_block {
    struct arena_block *next;
    size_t used, cap;
    _Alignas(16) unsigned char data[];
} arena_block;

typedef struct id_entry {
    const char *id;
    xnode *node;
} id_entry;

typedef struct xml_param {
    const char *name, *value;
} xml_param;

/* One load. */
typedef struct xp {
    pk_context *ctx;
    pk_scene *s;
    arena_block *arena;
    /* id -> element, open addressing (a power of two of slots, > 2 * nids) */
    id_entry *ids;
    size_t nids, id_slots;
    xml_param params[XML_MAX_PARAMS];
    int nparams;
    int nfiles;
    size_t nodes;         /* elements read, included files too */
    int bsdf_depth;
    /* warnings said once per kind */
    char warned[XML_MAX_WARN_KINDS][64];
    int nwarned;
    /* the sensor's fov needs the film's aspect: kept until the end */
    const xnode *sensor;
    float fov;
    char fov_axis[16];
    bool has_fov;
    int film_w, film_h;
    /* where the colour property being read may put a texture (the diffuse
     * reflectances); NULL: textures stand in as constants */
    tex_ref *want_tex;
    /* the scene's version: 0 for Mitsuba 0.x, 3 for Mitsuba 2/3 (spectra
     * are reduced to RGB by that version's rules) */
    int version_major;
    /* attr_st fails without a message (xml_props: a property's name that
     * cannot be substituted is reported where a search by name meets it) */
    bool quiet_attr;
    scene_builder sb;     /* every shape's triangles go in through it */
} xp;

/* expat's side of building one tree */
typedef struct builder {
    xp *p;
    XML_Parser parser;
    const xml_file *file;
    xnode *root, *cur;
    int depth;
    pk_status st;
} builder;

static void *arena_alloc(xp *p, size_t n)
{
    n = (n + 15u) & ~(size_t)15u;
    arena_block *b = p->arena;
    if (!b || b->cap - b->used < n) {
        size_t cap = n > 65536 ? n : 65536;
        b = mem_alloc(&p->ctx->alloc, sizeof *b + cap);
        if (!b) return NULL;
        b->next = p->arena;
        b->used = 0;
        b->cap = cap;
        p->arena = b;
    }
    void *r = b->data + b->used;
    b->used += n;
    return r;
}

static char *arena_strndup(xp *p, const char *s, size_t n)
{
    char *d = arena_alloc(p, n + 1);
    if (!d) return NULL;
    memcpy(d, s, n);
    d[n] = '\0';
    return d;
}

static char *arena_strdup(xp *p, const char *s) { return arena_strndup(p, s, strlen(s)); }

static void arena_free(xp *p)
{
    for (arena_block *b = p->arena, *n; b; b = n) {
        n = b->next;
        mem_free(&p->ctx->alloc, b);
    }
    p->arena = NULL;
}

/* ---- messages ------------------------------------------------------------------ */

/* Copies in to out (n bytes) with control characters as '?', cut at n - 1. */
static void shown(char *out, size_t n, const char *in)
{
    size_t i = 0;
    for (; in && in[i] && i + 1 < n; i++) out[i] = ((unsigned char)in[i] < 32 || in[i] == 127) ? '?' : in[i];
    out[i] = '\0';
}

static pk_status xfail(xp *p, pk_status st, const xnode *n, const char *fmt, ...) PK_PRINTF(4, 5);
static pk_status xfail(xp *p, pk_status st, const xnode *n, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    return ctx_error(p->ctx, st, "%s:%lu: %s", n->file->shown, n->line, msg);
}

static void xwarn(xp *p, const xnode *n, const char *fmt, ...) PK_PRINTF(3, 4);
static void xwarn(xp *p, const xnode *n, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    ctx_warn(p->ctx, "%s:%lu: %s", n->file->shown, n->line, msg);
}

/* True the first time kind is seen (kinds beyond the table count as seen). */
static bool first_time(xp *p, const char *kind)
{
    char k[64];
    shown(k, sizeof k, kind);
    for (int i = 0; i < p->nwarned; i++)
        if (strcmp(p->warned[i], k) == 0) return false;
    if (p->nwarned == XML_MAX_WARN_KINDS) return false;
    memcpy(p->warned[p->nwarned++], k, sizeof k);
    return true;
}

/* ---- reading the XML (expat) ------------------------------------------------------ */

static void stop(builder *b, pk_status st)
{
    if (b->st == PK_OK) b->st = st;
    XML_StopParser(b->parser, XML_FALSE);
}

static void XMLCALL on_start(void *user, const XML_Char *name, const XML_Char **atts)
{
    builder *b = user;
    xp *p = b->p;
    unsigned long line = (unsigned long)XML_GetCurrentLineNumber(b->parser);
    if (b->st != PK_OK) return;
    if (b->depth >= XML_MAX_DEPTH) {
        ctx_error(p->ctx, PK_ERR_LIMIT, "%s:%lu: elements nested more than %d deep", b->file->shown, line,
                  XML_MAX_DEPTH);
        stop(b, PK_ERR_LIMIT);
        return;
    }
    if (p->nodes >= XML_MAX_NODES) {
        ctx_error(p->ctx, PK_ERR_LIMIT, "%s:%lu: more than %u elements in the scene and its includes",
                  b->file->shown, line, XML_MAX_NODES);
        stop(b, PK_ERR_LIMIT);
        return;
    }
    if (!b->cur && b->root) { /* expat refuses a second root itself; never reached */
        ctx_error(p->ctx, PK_ERR_PARSE, "%s:%lu: a second document element", b->file->shown, line);
        stop(b, PK_ERR_PARSE);
        return;
    }
    xnode *n = arena_alloc(p, sizeof *n);
    int na = 0;
    while (atts[2 * na]) na++;
    xattr *a = na ? arena_alloc(p, (size_t)na * sizeof *a) : NULL;
    if (!n || (na && !a)) goto nomem;
    memset(n, 0, sizeof *n);
    n->tag = arena_strdup(p, name);
    if (!n->tag) goto nomem;
    for (int i = 0; i < na; i++) {
        a[i].name = arena_strdup(p, atts[2 * i]);
        a[i].value = arena_strdup(p, atts[2 * i + 1]);
        if (!a[i].name || !a[i].value) goto nomem;
    }
    n->attrs = a;
    n->nattrs = na;
    n->file = b->file;
    n->line = line;
    n->mat = -1;
    n->mesh = -1;
    n->medium = -1;
    n->parent = b->cur;
    if (b->cur) {
        if (b->cur->last) b->cur->last->next = n;
        else b->cur->child = n;
        b->cur->last = n;
    } else {
        b->root = n;
    }
    b->cur = n;
    b->depth++;
    p->nodes++;
    return;
nomem:
    ctx_nomem(p->ctx);
    stop(b, PK_ERR_NOMEM);
}

static void XMLCALL on_end(void *user, const XML_Char *name)
{
    (void)name;
    builder *b = user;
    if (b->st != PK_OK || !b->cur) return;
    b->cur = b->cur->parent;
    b->depth--;
}

/* Document type declarations (and with them entities) are refused: Mitsuba
 * scenes have none, and entity expansion is how XML files blow up. */
static void XMLCALL on_doctype(void *user, const XML_Char *name, const XML_Char *sysid, const XML_Char *pubid,
                               int has_internal)
{
    (void)name, (void)sysid, (void)pubid, (void)has_internal;
    builder *b = user;
    if (b->st != PK_OK) return;
    ctx_error(b->p->ctx, PK_ERR_PARSE, "%s:%lu: document type declarations (<!DOCTYPE ...>) are not supported",
              b->file->shown, (unsigned long)XML_GetCurrentLineNumber(b->parser));
    stop(b, PK_ERR_PARSE);
}

/* Parses text into a tree whose root is <scene>. */
static pk_status parse_tree(xp *p, const char *data, size_t size, const xml_file *file, xnode **root)
{
    *root = NULL;
    if (size > PK_MAX_XML_BYTES || size > (size_t)INT32_MAX)
        return ctx_error(p->ctx, PK_ERR_LIMIT, "%s: an XML scene may hold at most %zu bytes", file->shown,
                         (size_t)PK_MAX_XML_BYTES);
    builder b = {.p = p, .file = file, .st = PK_OK};
    b.parser = XML_ParserCreate(NULL);
    if (!b.parser) return ctx_nomem(p->ctx);
    XML_SetUserData(b.parser, &b);
    XML_SetElementHandler(b.parser, on_start, on_end);
    XML_SetStartDoctypeDeclHandler(b.parser, on_doctype);
    enum XML_Status xs = XML_Parse(b.parser, data, (int)size, XML_TRUE);
    pk_status st = b.st;
    if (st == PK_OK && xs != XML_STATUS_OK) {
        enum XML_Error e = XML_GetErrorCode(b.parser);
        st = ctx_error(p->ctx, e == XML_ERROR_NO_MEMORY ? PK_ERR_NOMEM : PK_ERR_PARSE, "%s:%lu: malformed XML: %s",
                       file->shown, (unsigned long)XML_GetCurrentLineNumber(b.parser), XML_ErrorString(e));
    }
    XML_ParserFree(b.parser);
    if (st != PK_OK) return p->ctx->status ? p->ctx->status : st;
    if (!b.root) return ctx_error(p->ctx, PK_ERR_PARSE, "%s:1: empty document (expected <scene>)", file->shown);
    if (strcmp(b.root->tag, "scene") != 0)
        return xfail(p, PK_ERR_PARSE, b.root, "the document element is <%.40s>, expected <scene>", b.root->tag);
    *root = b.root;
    return PK_OK;
}

/* ---- attributes, parameters, ids ------------------------------------------------------ */

static bool is_ident(char c)
{
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_';
}

static const char *param_find(const xp *p, const char *name, size_t n)
{
    for (int i = 0; i < p->nparams; i++)
        if (strlen(p->params[i].name) == n && memcmp(p->params[i].name, name, n) == 0) return p->params[i].value;
    return NULL;
}

/* Attribute name of n after $name substitution; NULL when absent or on an
 * error (latched: *st says which). */
static const char *attr_st(xp *p, const xnode *n, const char *name, pk_status *st)
{
    *st = PK_OK;
    const char *v = NULL;
    for (int i = 0; i < n->nattrs; i++)
        if (strcmp(n->attrs[i].name, name) == 0) v = n->attrs[i].value;
    if (!v || !strchr(v, '$')) return v;
    char buf[XML_MAX_VALUE];
    size_t o = 0;
    for (const char *c = v; *c;) {
        if (*c == '$' && is_ident(c[1])) {
            const char *s = c + 1, *e = s;
            while (is_ident(*e)) e++;
            const char *val = param_find(p, s, (size_t)(e - s));
            if (!val) {
                char nm[48];
                shown(nm, sizeof nm, s);
                nm[e - s < 47 ? e - s : 47] = '\0';
                *st = p->quiet_attr ? PK_ERR_PARSE : xfail(p, PK_ERR_PARSE, n, "%s=\"...$%s...\": no <default name=\"%s\"> defines $%s", name, nm,
                            nm, nm);
                return NULL;
            }
            size_t l = strlen(val);
            if (o + l >= sizeof buf) goto too_long;
            memcpy(buf + o, val, l);
            o += l;
            c = e;
            continue;
        }
        if (o + 1 >= sizeof buf) goto too_long;
        buf[o++] = *c++;
    }
    buf[o] = '\0';
    char *r = arena_strndup(p, buf, o);
    if (!r) *st = ctx_nomem(p->ctx);
    return r;
too_long:
    *st = p->quiet_attr ? PK_ERR_LIMIT : xfail(p, PK_ERR_LIMIT, n, "attribute %s is longer than %d bytes after $ substitution", name, XML_MAX_VALUE);
    return NULL;
}

static uint64_t hash_str(const char *s)
{
    uint64_t h = 1469598103934665603ull;
    for (; *s; s++) h = (h ^ (unsigned char)*s) * 1099511628211ull;
    return h;
}

static xnode *id_find(const xp *p, const char *id)
{
    if (!p->id_slots) return NULL;
    size_t mask = p->id_slots - 1;
    for (size_t i = (size_t)hash_str(id) & mask;; i = (i + 1) & mask) {
        if (!p->ids[i].id) return NULL;
        if (strcmp(p->ids[i].id, id) == 0) return p->ids[i].node;
    }
}

/* Registers id for n; a later element with the same id replaces the earlier. */
static pk_status id_add(xp *p, const char *id, xnode *n)
{
    if (2 * (p->nids + 1) >= p->id_slots) {
        size_t slots = p->id_slots ? 2 * p->id_slots : 64;
        id_entry *t = mem_calloc(&p->ctx->alloc, slots, sizeof *t);
        if (!t) return ctx_nomem(p->ctx);
        for (size_t i = 0; i < p->id_slots; i++) {
            if (!p->ids[i].id) continue;
            size_t j = (size_t)hash_str(p->ids[i].id) & (slots - 1);
            while (t[j].id) j = (j + 1) & (slots - 1);
            t[j] = p->ids[i];
        }
        mem_free(&p->ctx->alloc, p->ids);
        p->ids = t;
        p->id_slots = slots;
    }
    size_t mask = p->id_slots - 1;
    for (size_t i = (size_t)hash_str(id) & mask;; i = (i + 1) & mask) {
        if (!p->ids[i].id) {
            p->ids[i].id = id;
            p->ids[i].node = n;
            p->nids++;
            return PK_OK;
        }
        if (strcmp(p->ids[i].id, id) == 0) {
            p->ids[i].node = n;
            return PK_OK;
        }
    }
}

/* Mitsuba 0.x names properties in camelCase (toWorld, intIOR), 2.x and 3.x
 * in snake_case (to_world, int_ior): both are compared in snake_case. */
static void snake(char *out, size_t n, const char *in)
{
    size_t o = 0;
    for (size_t i = 0; in[i] && o + 2 < n; i++) {
        char c = in[i];
        if (c >= 'A' && c <= 'Z') {
            if (i > 0 && ((in[i - 1] >= 'a' && in[i - 1] <= 'z') || (in[i - 1] >= '0' && in[i - 1] <= '9')))
                out[o++] = '_';
            c = (char)(c - 'A' + 'a');
        }
        out[o++] = c;
    }
    out[o] = '\0';
}

/* ---- a plugin's properties as a pdict ------------------------------------------------------ */

static void xml_warn_unused(void *self, const pdict *d, const pd_entry *e);
static const pd_source xml_source = {.warn_unused = xml_warn_unused};

/* Fills *d with the named children of plugin, in order: each entry's name
 * is the property's in snake_case ($ substituted; "" where that fails), its
 * node the element and its type the element's tag. Values stay in the
 * elements, read by the getters below when a plugin asks for them, so that
 * a property nobody reads is never checked. A name may come twice: the
 * first is read. Invariant: the entries live in the load's arena (cap is
 * the number of children, so pd_add never grows them): d is never
 * pd_free'd. */
static pk_status xml_props(xp *p, xnode *plugin, pdict *d)
{
    pd_init(d, p->ctx, &xml_source, p, NULL, false);
    d->node = plugin;
    d->dups = true;
    size_t n = 0;
    for (xnode *c = plugin->child; c; c = c->next) n++;
    if (n && !(d->e = arena_alloc(p, n * sizeof *d->e))) return ctx_nomem(p->ctx);
    d->cap = n;
    for (xnode *c = plugin->child; c; c = c->next) {
        pk_status st;
        p->quiet_attr = true;
        const char *nm = attr_st(p, c, "name", &st);
        p->quiet_attr = false;
        if (st == PK_ERR_NOMEM) return st;
        if (!nm && !st) continue;
        char sn[64] = "";
        if (nm) snake(sn, sizeof sn, nm);
        const pd_entry e = {.name = arena_strdup(p, sn), .kind = PD_OTHER, .node = c, .type = c->tag};
        if (!e.name) return ctx_nomem(p->ctx);
        pd_add(d, &e);
    }
    return PK_OK;
}

/* The element holding property name (snake_case), marked read. A name
 * before it that could not be substituted is an error (latched). */
static xnode *prop(pdict *d, const char *name)
{
    const pd_entry *e = pd_get(d, name);
    for (size_t i = 0; i < d->n && &d->e[i] != e; i++)
        if (!d->e[i].name[0]) attr_st(d->self, d->e[i].node, "name", &(pk_status){0});
    return e ? (xnode *)e->node : NULL;
}

/* Every property marked read: a plugin that is not translated, or whose
 * options are another part's (textures), warns about none of them. */
static void props_all_read(pdict *d)
{
    for (size_t i = 0; i < d->n; i++) d->e[i].used = true;
}

/* ---- values ------------------------------------------------------------------------- */

/* Reads up to max numbers separated by blanks and/or commas. */
static pk_status numbers(xp *p, const xnode *n, const char *what, const char *v, float *out, int max, int *count)
{
    int k = 0;
    const char *c = v, *e = v + strlen(v);
    for (;;) {
        while (c < e && (io_is_blank(*c) || *c == ',' || *c == '\n')) c++;
        if (c == e) break;
        const char *te = c;
        while (te < e && !io_is_blank(*te) && *te != ',' && *te != '\n') te++;
        float f;
        const char *end = io_parse_float(c, te, &f);
        if (!end || end != te || k == max) {
            char sv[48];
            shown(sv, sizeof sv, v);
            if (k == max && end == te)
                return xfail(p, PK_ERR_PARSE, n, "%s: \"%s\" holds more than %d numbers", what, sv, max);
            return xfail(p, PK_ERR_PARSE, n, "%s: bad number in \"%s\"", what, sv);
        }
        if (!isfinite(f)) return xfail(p, PK_ERR_PARSE, n, "%s: numbers must be finite", what);
        out[k++] = f;
        c = te;
    }
    *count = k;
    return PK_OK;
}

static pk_status value_attr(xp *p, const xnode *n, const char **v)
{
    pk_status st;
    *v = attr_st(p, n, "value", &st);
    if (st) return st;
    if (!*v) return xfail(p, PK_ERR_PARSE, n, "<%.32s> needs a value attribute", n->tag);
    return PK_OK;
}

static pk_status node_float(xp *p, const xnode *n, float *out)
{
    const char *v;
    pk_status st = value_attr(p, n, &v);
    if (st) return st;
    int k;
    float f[2];
    if ((st = numbers(p, n, n->tag, v, f, 1, &k))) return st;
    if (k != 1) return xfail(p, PK_ERR_PARSE, n, "<%.32s> needs one number", n->tag);
    *out = f[0];
    return PK_OK;
}

/* A float (or integer) property; absent leaves *out. */
static pk_status get_float(xp *p, pdict *d, const char *name, float *out)
{
    xnode *c = prop(d, name);
    if (!c) return PK_OK;
    if (strcmp(c->tag, "float") != 0 && strcmp(c->tag, "integer") != 0)
        return xfail(p, PK_ERR_PARSE, c, "%s must be a <float>, found <%.32s>", name, c->tag);
    return node_float(p, c, out);
}

static pk_status get_int(xp *p, pdict *d, const char *name, int64_t *out, bool *found)
{
    xnode *c = prop(d, name);
    if (found) *found = c != NULL;
    if (!c) return PK_OK;
    const char *v;
    pk_status st = value_attr(p, c, &v);
    if (st) return st;
    const char *s = v, *e = v + strlen(v);
    while (s < e && io_is_blank(*s)) s++;
    while (e > s && io_is_blank(e[-1])) e--;
    const char *end = io_parse_int(s, e, out);
    if (!end || end != e || s == e) {
        char sv[48];
        shown(sv, sizeof sv, v);
        return xfail(p, PK_ERR_PARSE, c, "%s: \"%s\" is not an integer", name, sv);
    }
    return PK_OK;
}

static pk_status get_bool(xp *p, pdict *d, const char *name, bool *out)
{
    xnode *c = prop(d, name);
    if (!c) return PK_OK;
    const char *v;
    pk_status st = value_attr(p, c, &v);
    if (st) return st;
    if (strcmp(v, "true") == 0) *out = true;
    else if (strcmp(v, "false") == 0) *out = false;
    else {
        char sv[48];
        shown(sv, sizeof sv, v);
        return xfail(p, PK_ERR_PARSE, c, "%s: \"%s\" is not true or false", name, sv);
    }
    return PK_OK;
}

static pk_status get_string(xp *p, pdict *d, const char *name, const char **out, xnode **at)
{
    xnode *c = prop(d, name);
    if (at) *at = c;
    if (!c) return PK_OK;
    return value_attr(p, c, out);
}

/* x, y, z attributes each defaulting to def, or value (1 or 3 numbers). */
static pk_status attr_xyz(xp *p, const xnode *n, float def, vec3 *out)
{
    pk_status st;
    const char *v = attr_st(p, n, "value", &st);
    if (st) return st;
    if (v) {
        float f[3];
        int k;
        if ((st = numbers(p, n, "value", v, f, 3, &k))) return st;
        if (k == 1) *out = v3s(f[0]);
        else if (k == 3) *out = v3(f[0], f[1], f[2]);
        else return xfail(p, PK_ERR_PARSE, n, "<%.32s value> needs 1 or 3 numbers", n->tag);
        return PK_OK;
    }
    float f[3] = {def, def, def};
    static const char *const xyz[3] = {"x", "y", "z"};
    for (int i = 0; i < 3; i++) {
        const char *a = attr_st(p, n, xyz[i], &st);
        if (st) return st;
        if (!a) continue;
        int k;
        if ((st = numbers(p, n, xyz[i], a, &f[i], 1, &k))) return st;
        if (k != 1) return xfail(p, PK_ERR_PARSE, n, "%s needs one number", xyz[i]);
    }
    *out = v3(f[0], f[1], f[2]);
    return PK_OK;
}

/* A <point> or <vector>: x, y, z attributes (0 when absent) or value. */
static pk_status node_vec(xp *p, const xnode *n, vec3 *out) { return attr_xyz(p, n, 0.0f, out); }

static pk_status get_vec(xp *p, pdict *d, const char *name, vec3 *out, bool *found)
{
    xnode *c = prop(d, name);
    if (found) *found = c != NULL;
    if (!c) return PK_OK;
    if (strcmp(c->tag, "point") != 0 && strcmp(c->tag, "vector") != 0)
        return xfail(p, PK_ERR_PARSE, c, "%s must be a <point> or <vector>, found <%.32s>", name, c->tag);
    return node_vec(p, c, out);
}

/* ---- colours and spectra ------------------------------------------------------------------ */

static float srgb_to_linear(float c)
{
    return c <= 0.04045f ? c / 12.92f : powf((c + 0.055f) / 1.055f, 2.4f);
}

/* <spectrum value="..."/>: one number, three numbers (RGB, as Mitsuba
 * 0.x's RGB mode reads them) or wavelength:value pairs; reduced to RGB as
 * the scene's Mitsuba version does it (spectra.h): Mitsuba 0.x by
 * spectra_mitsuba06_rgb for every property, a single number grey;
 * Mitsuba 3 by spectra_mitsuba3_rgb, D65-weighted and clamped to [0, 1]
 * for reflectances, unweighted and unbounded for an emitter's radiance
 * (and unbounded for a conductor's eta and k), a single number grey except
 * for an emitter, where it is that number times the sRGB of the
 * equal-energy white. <spectrum type="blackbody"> (Mitsuba 3) holds a
 * <float name="temperature">. */
static pk_status node_spectrum(xp *p, const xnode *n, vec3 *out)
{
    pk_status st;
    const bool mts3 = p->version_major >= 2;
    const bool emitter = n->parent && strcmp(n->parent->tag, "emitter") == 0;
    const char *pname = attr_st(p, n, "name", &st);
    if (st) return st;
    bool unbounded = pname && (strcmp(pname, "eta") == 0 || strcmp(pname, "k") == 0);
    /* a medium's coefficients are unbounded, its albedo a reflectance */
    const xnode *owner = n->parent;
    const char *oname = owner && strcmp(owner->tag, "volume") == 0 ? attr_st(p, owner, "name", &st) : pname;
    if (owner && (strcmp(owner->tag, "medium") == 0 || strcmp(owner->tag, "volume") == 0))
        unbounded = !oname || strcmp(oname, "albedo") != 0;
    const char *ty = attr_st(p, n, "type", &st);
    if (st) return st;
    if (ty && strcmp(ty, "blackbody") == 0) {
        float kelvin = 0.0f;
        pdict d;
        if ((st = xml_props(p, (xnode *)n, &d)) || (st = get_float(p, &d, "temperature", &kelvin))) return st;
        if (!(kelvin > 0.0f) || !isfinite(kelvin))
            return xfail(p, PK_ERR_PARSE, n, "<spectrum type=\"blackbody\"> needs a positive temperature");
        *out = spectra_mitsuba3_blackbody(kelvin);
        return PK_OK;
    }
    const char *v = attr_st(p, n, "value", &st);
    if (st) return st;
    if (!v) {
        const char *f = attr_st(p, n, "filename", &st);
        if (st) return st;
        if (f) {
            xwarn(p, n, "spectrum files are not supported; using grey 0.5");
            *out = v3s(0.5f);
            return PK_OK;
        }
        return xfail(p, PK_ERR_PARSE, n, "<spectrum> needs a value attribute");
    }
    if (!strchr(v, ':')) {
        float f[3];
        int k;
        if ((st = numbers(p, n, "spectrum", v, f, 3, &k))) return st;
        if (k == 1) *out = mts3 && emitter ? spectra_mitsuba3_uniform_emitter(f[0]) : v3s(f[0]);
        else if (k == 3) *out = v3(f[0], f[1], f[2]);
        else return xfail(p, PK_ERR_PARSE, n, "<spectrum> needs 1 or 3 numbers or wavelength:value pairs");
        return PK_OK;
    }
    enum { MAX_SAMPLES = 256 };
    float nm[MAX_SAMPLES], val[MAX_SAMPLES];
    int k = 0;
    const char *c = v, *e = v + strlen(v);
    for (;;) {
        while (c < e && (io_is_blank(*c) || *c == ',' || *c == '\n')) c++;
        if (c == e) break;
        if (k == MAX_SAMPLES) return xfail(p, PK_ERR_LIMIT, n, "<spectrum> holds more than %d samples", MAX_SAMPLES);
        const char *q = io_parse_float(c, e, &nm[k]);
        if (!q || q == e || *q != ':') goto bad;
        q = io_parse_float(q + 1, e, &val[k]);
        if (!q || (q < e && !io_is_blank(*q) && *q != ',' && *q != '\n')) goto bad;
        if (!isfinite(nm[k]) || !isfinite(val[k]) || (k > 0 && !(nm[k] > nm[k - 1])))
            return xfail(p, PK_ERR_PARSE, n, "<spectrum> wavelengths must be finite and increasing");
        k++;
        c = q;
    }
    if (k == 0) goto bad;
    if (k < 2) return xfail(p, PK_ERR_PARSE, n, "<spectrum> needs at least two wavelength:value pairs");
    *out = mts3 ? spectra_mitsuba3_rgb(nm, val, k, emitter, !emitter && !unbounded) : spectra_mitsuba06_rgb(nm, val, k);
    return PK_OK;
bad:;
    char sv[48];
    shown(sv, sizeof sv, v);
    return xfail(p, PK_ERR_PARSE, n, "<spectrum> \"%s\": expected wavelength:value pairs", sv);
}

static int hexval(char c)
{
    if (c >= '0' && c <= '9') return c - '0';
    if (c >= 'a' && c <= 'f') return c - 'a' + 10;
    if (c >= 'A' && c <= 'F') return c - 'A' + 10;
    return -1;
}

/* <blackbody temperature="5000K" scale=/> (Mitsuba 0.x): spectra_mitsuba06_blackbody
 * times scale, in every version (Mitsuba 3 has no such element). */
static pk_status node_blackbody(xp *p, const xnode *n, vec3 *out)
{
    pk_status st;
    const char *t = attr_st(p, n, "temperature", &st);
    if (st) return st;
    if (!t) return xfail(p, PK_ERR_PARSE, n, "<blackbody> needs a temperature");
    const char *e = t + strlen(t);
    while (e > t && (io_is_blank(e[-1]) || e[-1] == 'K' || e[-1] == 'k')) e--;
    float kelvin, scale = 1.0f;
    const char *q = io_parse_float(t, e, &kelvin);
    if (!q || q != e || !(kelvin > 0.0f) || !isfinite(kelvin))
        return xfail(p, PK_ERR_PARSE, n, "<blackbody> temperature must be a positive number of kelvins");
    const char *sc = attr_st(p, n, "scale", &st);
    if (st) return st;
    if (sc) {
        int k;
        if ((st = numbers(p, n, "scale", sc, &scale, 1, &k))) return st;
    }
    *out = v3_scale(spectra_mitsuba06_blackbody(kelvin), scale);
    if (!v3_finite(*out)) return xfail(p, PK_ERR_PARSE, n, "<blackbody> radiance is not finite");
    return PK_OK;
}

/* <rgb>, <srgb>, <spectrum>, <blackbody>, <float> as a colour. */
static pk_status node_color(xp *p, const xnode *n, vec3 *out)
{
    pk_status st;
    if (strcmp(n->tag, "spectrum") == 0) return node_spectrum(p, n, out);
    if (strcmp(n->tag, "blackbody") == 0) return node_blackbody(p, n, out);
    if (strcmp(n->tag, "float") == 0 || strcmp(n->tag, "integer") == 0) {
        float f;
        if ((st = node_float(p, n, &f))) return st;
        *out = v3s(f);
        return PK_OK;
    }
    bool srgb = strcmp(n->tag, "srgb") == 0;
    if (!srgb && strcmp(n->tag, "rgb") != 0)
        return xfail(p, PK_ERR_PARSE, n, "a colour must be <rgb>, <srgb>, <spectrum> or <float>, found <%.32s>",
                     n->tag);
    const char *v;
    if ((st = value_attr(p, n, &v))) return st;
    float f[3];
    int k;
    if (srgb && v[0] == '#') {
        size_t l = strlen(v);
        if (l != 7) return xfail(p, PK_ERR_PARSE, n, "<srgb> \"#rrggbb\" needs six hexadecimal digits");
        for (int i = 0; i < 3; i++) {
            int hi = hexval(v[1 + 2 * i]), lo = hexval(v[2 + 2 * i]);
            if (hi < 0 || lo < 0) return xfail(p, PK_ERR_PARSE, n, "<srgb> \"#rrggbb\" needs six hexadecimal digits");
            f[i] = (float)(hi * 16 + lo) / 255.0f;
        }
        k = 3;
    } else if ((st = numbers(p, n, n->tag, v, f, 3, &k))) {
        return st;
    }
    if (k == 1) f[1] = f[2] = f[0];
    else if (k != 3) return xfail(p, PK_ERR_PARSE, n, "<%s> needs 1 or 3 numbers", n->tag);
    if (srgb)
        for (int i = 0; i < 3; i++) f[i] = srgb_to_linear(f[i]);
    *out = v3(f[0], f[1], f[2]);
    return PK_OK;
}

/* ---- textures: the one place they enter ----------------------------------------------- */

/* Every textured parameter comes here: file is the bitmap's file resolved
 * against the XML file's folder, or NULL for a checkerboard (colours c0, c1);
 * fallback the constant that stands in for it. Where the property takes a
 * texture (p->want_tex), the texture goes there and *out becomes 1 (the
 * texture's value multiplies the constant); elsewhere, and for a bitmap that
 * cannot be read, the constant is used with a warning. uv' = (us u, vs v). */
static pk_status texture_param(xp *p, const xnode *tex, const char *param, const char *file, vec3 c0, vec3 c1,
                               float us, float vs, vec3 fallback, vec3 *out)
{
    char what[64];
    shown(what, sizeof what, param);
    *out = fallback;
    if (!p->want_tex) {
        xwarn(p, tex, "a texture for %s is not supported; using the constant %g %g %g", what, (double)fallback.x,
              (double)fallback.y, (double)fallback.z);
        return PK_OK;
    }
    tex_ref r;
    tex_ref_init(&r);
    r.s[0] = us, r.s[1] = vs;
    if (file) {
        int32_t idx;
        const bool was_ok = p->ctx->status == PK_OK;
        pk_status st = texture_load(p->ctx, p->s, file, true, &idx);
        if (st != PK_OK) {
            char why[PK_ERRMSG_MAX];
            if (!io_demote_error(p->ctx, st, was_ok, why, sizeof why)) return st;
            xwarn(p, tex, "texture not used (%s); using the constant %g %g %g for %s", why, (double)fallback.x,
                  (double)fallback.y, (double)fallback.z, what);
            return PK_OK;
        }
        r.kind = TEX_IMAGE;
        r.tex = idx;
    } else {
        /* Mitsuba's checkerboard: color0 where u and v are both below or both
         * above one half, color1 elsewhere (two squares a side) */
        r.kind = TEX_CHECKER;
        r.even = c0, r.odd = c1;
        r.checker_scale = 2.0f;
    }
    *p->want_tex = r;
    *out = v3s(1.0f);
    return PK_OK;
}

static pk_status texture_value(xp *p, xnode *tex, const char *param, vec3 fallback, vec3 *out, int depth);

/* A texture element: bitmap (file name resolved), checkerboard (the mean
 * of its two colours), scale (the scaled nested texture); others give
 * fallback. */
static pk_status texture_value(xp *p, xnode *tex, const char *param, vec3 fallback, vec3 *out, int depth)
{
    pk_status st;
    if (depth > XML_MAX_BSDF_DEPTH) return xfail(p, PK_ERR_LIMIT, tex, "textures nested too deep");
    if (strcmp(tex->tag, "ref") == 0) {
        const char *id = attr_st(p, tex, "id", &st);
        if (st) return st;
        xnode *t = id ? id_find(p, id) : NULL;
        if (!t || strcmp(t->tag, "texture") != 0) {
            char sid[48];
            shown(sid, sizeof sid, id ? id : "");
            return xfail(p, PK_ERR_PARSE, tex, "no texture has the id \"%s\"", sid);
        }
        if (t->busy) return xfail(p, PK_ERR_PARSE, tex, "reference cycle through texture \"%.40s\"", id);
        t->busy = true;
        st = texture_value(p, t, param, fallback, out, depth + 1);
        t->busy = false;
        return st;
    }
    const char *type = attr_st(p, tex, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, tex, "<texture> needs a type");
    pdict d; /* (no warnings: texture options are the texture system's) */
    if ((st = xml_props(p, tex, &d))) return st;
    if (strcmp(type, "bitmap") == 0) {
        const char *fn = NULL;
        xnode *at;
        if ((st = get_string(p, &d, "filename", &fn, &at))) return st;
        if (!fn) return xfail(p, PK_ERR_PARSE, tex, "bitmap texture needs a filename");
        char *full = path_join(&p->ctx->alloc, tex->file->dir, fn);
        if (!full) return ctx_nomem(p->ctx);
        float us = 1.0f, vs = 1.0f;
        if ((st = get_float(p, &d, "uscale", &us)) || (st = get_float(p, &d, "vscale", &vs))) {
            mem_free(&p->ctx->alloc, full);
            return st;
        }
        st = texture_param(p, tex, param, full, v3s(0.0f), v3s(0.0f), us, vs, fallback, out);
        mem_free(&p->ctx->alloc, full);
        return st;
    }
    if (strcmp(type, "checkerboard") == 0) {
        vec3 c0 = v3s(0.4f), c1 = v3s(0.2f);
        xnode *a = prop(&d, "color0"), *b = prop(&d, "color1");
        if (a && (st = node_color(p, a, &c0))) return st;
        if (b && (st = node_color(p, b, &c1))) return st;
        float us = 1.0f, vs = 1.0f;
        if ((st = get_float(p, &d, "uscale", &us)) || (st = get_float(p, &d, "vscale", &vs))) return st;
        return texture_param(p, tex, param, NULL, c0, c1, us, vs, v3_scale(v3_add(c0, c1), 0.5f), out);
    }
    if (strcmp(type, "scale") == 0) {
        float scale = 1.0f;
        if ((st = get_float(p, &d, "scale", &scale))) return st;
        tex_ref *want = p->want_tex;
        p->want_tex = NULL; /* a scaled texture stands in as a constant */
        for (xnode *c = tex->child; c; c = c->next)
            if (strcmp(c->tag, "texture") == 0 || strcmp(c->tag, "ref") == 0) {
                st = texture_value(p, c, param, fallback, out, depth + 1);
                p->want_tex = want;
                if (st) return st;
                *out = v3_scale(*out, scale);
                return PK_OK;
            }
        p->want_tex = want;
        *out = v3_scale(fallback, scale);
        return PK_OK;
    }
    char ty[40];
    shown(ty, sizeof ty, type);
    xwarn(p, tex, "texture type \"%s\" is not supported; using the constant %g %g %g", ty, (double)fallback.x,
          (double)fallback.y, (double)fallback.z);
    *out = fallback;
    return PK_OK;
}

/* A colour property: absent leaves *out (the default); a texture goes
 * through texture_value with *out as its stand-in. */
static pk_status get_color(xp *p, pdict *d, const char *name, vec3 *out)
{
    xnode *c = prop(d, name);
    if (!c) return PK_OK;
    if (strcmp(c->tag, "texture") == 0 || strcmp(c->tag, "ref") == 0) return texture_value(p, c, name, *out, out, 0);
    pk_status st = node_color(p, c, out);
    if (st == PK_OK && !v3_finite(*out)) return xfail(p, PK_ERR_PARSE, c, "%s is not finite", name);
    return st;
}

/* A colour property that may be a texture, which goes to *tex (a diffuse
 * reflectance: the texture multiplies *out, which becomes 1). */
static pk_status get_color_tex(xp *p, pdict *d, const char *name, vec3 *out, tex_ref *tex)
{
    p->want_tex = tex;
    pk_status st = get_color(p, d, name, out);
    p->want_tex = NULL;
    return st;
}

/* A scalar property that may be a texture (roughness, opacity). */
static pk_status get_scalar(xp *p, pdict *d, const char *name, float *out)
{
    xnode *c = prop(d, name);
    if (!c) return PK_OK;
    vec3 v = v3s(*out);
    pk_status st;
    if (strcmp(c->tag, "texture") == 0 || strcmp(c->tag, "ref") == 0) st = texture_value(p, c, name, v, &v, 0);
    else st = node_color(p, c, &v);
    if (st) return st;
    *out = (v.x + v.y + v.z) / 3.0f;
    return PK_OK;
}

/* ---- transforms ---------------------------------------------------------------------------- */

/* An attribute holding 3 numbers (origin="x, y, z"). */
static pk_status attr_vec3(xp *p, const xnode *n, const char *name, vec3 *out, bool *found)
{
    pk_status st;
    const char *v = attr_st(p, n, name, &st);
    if (st) return st;
    *found = v != NULL;
    if (!v) return PK_OK;
    float f[3];
    int k;
    if ((st = numbers(p, n, name, v, f, 3, &k))) return st;
    if (k != 3) return xfail(p, PK_ERR_PARSE, n, "%s needs 3 numbers", name);
    *out = v3(f[0], f[1], f[2]);
    return PK_OK;
}

/* <transform>: its elements applied in order, each one after (to the left
 * of) those before, as Mitsuba composes them. */
static pk_status parse_transform(xp *p, xnode *t, xform *m)
{
    pk_status st;
    *m = xform_identity();
    if (strcmp(t->tag, "transform") != 0)
        return xfail(p, PK_ERR_PARSE, t, "expected a <transform>, found <%.32s>", t->tag);
    for (xnode *c = t->child; c; c = c->next) {
        xform e = xform_identity();
        if (strcmp(c->tag, "matrix") == 0) {
            const char *v;
            if ((st = value_attr(p, c, &v))) return st;
            float f[16];
            int k;
            if ((st = numbers(p, c, "matrix", v, f, 16, &k))) return st;
            if (k == 16) {
                memcpy(e.m, f, sizeof e.m);
                if (!xform_is_affine(&e))
                    return xfail(p, PK_ERR_PARSE, c, "matrix: projective matrices are not supported (last row must "
                                                    "be 0 0 0 1)");
            } else if (k == 9) {
                for (int i = 0; i < 3; i++)
                    for (int j = 0; j < 3; j++) e.m[4 * i + j] = f[3 * i + j];
            } else {
                return xfail(p, PK_ERR_PARSE, c, "matrix needs 16 (or 9) numbers, found %d", k);
            }
        } else if (strcmp(c->tag, "translate") == 0) {
            vec3 d;
            if ((st = attr_xyz(p, c, 0.0f, &d))) return st;
            e = xform_translate(d);
        } else if (strcmp(c->tag, "scale") == 0) {
            vec3 d;
            if ((st = attr_xyz(p, c, 1.0f, &d))) return st;
            e = xform_scale(d);
        } else if (strcmp(c->tag, "rotate") == 0) {
            vec3 axis;
            float angle = 0.0f;
            const char *a = attr_st(p, c, "angle", &st);
            if (st) return st;
            if (a) {
                int k;
                if ((st = numbers(p, c, "angle", a, &angle, 1, &k))) return st;
                if (k != 1) return xfail(p, PK_ERR_PARSE, c, "angle needs one number");
            }
            if ((st = attr_xyz(p, c, 0.0f, &axis))) return st;
            if (!(v3_len2(axis) > 0.0f)) return xfail(p, PK_ERR_PARSE, c, "rotate: the axis must not be zero");
            e = xform_rotate(v3_norm_scaled(axis), angle);
        } else if (strcmp(c->tag, "lookat") == 0 || strcmp(c->tag, "lookAt") == 0) {
            vec3 o = v3s(0.0f), tg = v3(0.0f, 0.0f, 1.0f), up = v3(0.0f, 1.0f, 0.0f);
            bool has_o, has_t, has_up;
            if ((st = attr_vec3(p, c, "origin", &o, &has_o))) return st;
            if ((st = attr_vec3(p, c, "target", &tg, &has_t))) return st;
            if ((st = attr_vec3(p, c, "up", &up, &has_up))) return st;
            if (!has_o || !has_t) return xfail(p, PK_ERR_PARSE, c, "lookat needs origin and target");
            xform_lookat_status ls = xform_lookat(o, tg, up, has_up, &e);
            if (ls == XFORM_LOOKAT_SAME_POINT)
                return xfail(p, PK_ERR_PARSE, c, "lookat: origin and target are the same point");
            if (ls == XFORM_LOOKAT_BAD_UP)
                return xfail(p, PK_ERR_PARSE, c, "lookat: up is zero or parallel to the view direction");
        } else {
            char tg[40];
            shown(tg, sizeof tg, c->tag);
            xwarn(p, c, "<%s> in a transform is not supported; ignored", tg);
            continue;
        }
        *m = xform_mul(&e, m);
    }
    if (!xform_finite(m)) return xfail(p, PK_ERR_PARSE, t, "the transform is not finite");
    return PK_OK;
}

/* The to_world of a plugin (identity when absent); *found says whether given. */
static pk_status get_to_world(xp *p, pdict *d, xform *m, bool *found)
{
    *m = xform_identity();
    xnode *t = prop(d, "to_world");
    if (found) *found = t != NULL;
    if (!t) return PK_OK;
    return parse_transform(p, t, m);
}

/* ---- materials ------------------------------------------------------------------------------- */

/* An index of refraction: a number or one of Mitsuba's names. */
static pk_status get_ior(xp *p, pdict *d, const char *name, float *out)
{
    xnode *c = prop(d, name);
    if (!c) return PK_OK;
    pk_status st;
    if (strcmp(c->tag, "string") == 0) {
        const char *v;
        if ((st = value_attr(p, c, &v))) return st;
        if (spectra_named_ior(v, out)) return PK_OK;
        float f;
        const char *e = v + strlen(v);
        if (io_parse_float(v, e, &f) == e && f > 0.0f && isfinite(f)) { /* a number written as a string */
            *out = f;
            return PK_OK;
        }
        char sv[48];
        shown(sv, sizeof sv, v);
        return xfail(p, PK_ERR_PARSE, c, "%s: unknown material \"%s\"", name, sv);
    }
    if ((st = node_float(p, c, out))) return st;
    if (!(*out > 0.0f)) return xfail(p, PK_ERR_PARSE, c, "%s must be positive", name);
    return PK_OK;
}

/* int_ior / ext_ior (default in, and air). */
static pk_status get_rel_ior(xp *p, pdict *d, float in, float *ior)
{
    float ext = 1.000277f;
    pk_status st = get_ior(p, d, "int_ior", &in);
    if (st == PK_OK) st = get_ior(p, d, "ext_ior", &ext);
    *ior = in / ext;
    return st;
}

static float clamp01(float x) { return x > 0.0f ? (x < 1.0f ? x : 1.0f) : 0.0f; }
static vec3 clamp01v(vec3 c) { return v3(clamp01(c.x), clamp01(c.y), clamp01(c.z)); }

/* roughness of the rough* plugins: alpha, or alpha_u/alpha_v (alpha_v
 * NULL: averaged, with a warning; else *alpha is alpha_u, along the
 * surface's dp/du, and *alpha_v alpha_v where the two differ, -1 where
 * they do not), and the microfacet distribution (*beckmann: Mitsuba's default "beckmann",
 * and "phong" by Mitsuba's own equivalence of the two for one alpha; false
 * for "ggx"). A texture on alpha goes to *tex (tex NULL: its mean), *alpha
 * becomes 1 and the texture's value is the roughness; textures on alpha_u
 * and alpha_v stand in as their means (warning). */
static pk_status get_alpha(xp *p, pdict *d, float def, float *alpha, float *alpha_v, bool *beckmann, tex_ref *tex)
{
    if (alpha_v) *alpha_v = -1.0f;
    const xnode *b = d->node;
    pk_status st;
    float a = def, au = -1.0f, av = -1.0f;
    p->want_tex = tex;
    st = get_scalar(p, d, "alpha", &a);
    p->want_tex = NULL;
    if (st) return st;
    xnode *cu = prop(d, "alpha_u"), *cv = prop(d, "alpha_v");
    if (cu || cv) {
        if (tex && tex->kind) { /* alpha_u and alpha_v, as Mitsuba reads them, win */
            tex_ref_init(tex);
            a = def;
        }
        au = av = a;
        if ((st = get_scalar(p, d, "alpha_u", &au))) return st;
        if ((st = get_scalar(p, d, "alpha_v", &av))) return st;
        if (au != av && alpha_v) {
            a = au;
            *alpha_v = clamp01(av);
        } else {
            if (au != av) xwarn(p, b, "anisotropic roughness is not supported here; using alpha %g", (double)(0.5f * (au + av)));
            a = 0.5f * (au + av);
        }
    }
    const char *dist = NULL;
    xnode *dist_at = NULL;
    if ((st = get_string(p, d, "distribution", &dist, &dist_at))) return st;
    *beckmann = true;
    if (dist && strcmp(dist, "ggx") == 0) *beckmann = false;
    else if (dist && strcmp(dist, "phong") == 0) {
        if (first_time(p, "phong distribution"))
            xwarn(p, dist_at, "the phong distribution is rendered as Beckmann of the same alpha (Mitsuba's "
                              "exponent 2 / alpha^2 - 2 matches them)");
    } else if (dist && strcmp(dist, "beckmann") != 0) {
        char sd[40];
        shown(sd, sizeof sd, dist);
        xwarn(p, dist_at, "microfacet distribution \"%s\" is unknown; using beckmann", sd);
    }
    *alpha = clamp01(a);
    if (alpha_v && *alpha_v == *alpha) *alpha_v = -1.0f;
    return PK_OK;
}

static pk_status bsdf_material(xp *p, xnode *b, material *m);

/* What a bsdf's creator is given (bsdf_material): the element and its
 * properties, its type (ty: as messages show it), and what the dispatch
 * read for its row: the roughness of a rough row (alpha, beckmann:
 * get_alpha) and int_ior / ext_ior (ior) of a row with an int_ior default.
 * A creator fills *m (material_init'ed). */
typedef struct bsdf_in {
    xnode *b;
    pdict *d;
    const char *type, *ty;
    float alpha, ior;
    float alpha_v; /* rough conductor and dielectric: anisotropic roughness (get_alpha) */
    bool beckmann;
    tex_ref alpha_tex; /* a texture on alpha (get_alpha), TEX_NONE if none */
} bsdf_in;

/* The nested bsdf of a wrapper (its first <bsdf> or <ref> child). */
static xnode *nested_bsdf(xp *p, xnode *b)
{
    for (xnode *c = b->child; c; c = c->next)
        if (strcmp(c->tag, "bsdf") == 0 || (strcmp(c->tag, "ref") == 0 && !attr_st(p, c, "name", &(pk_status){0})))
            return c;
    return NULL;
}

static pk_status bsdf_resolve(xp *p, xnode *b, material *m);
static pk_status material_of(xp *p, xnode *b, uint32_t *index);

/* The first texture child of b other than skip, or the texture a <ref>
 * child names; *t NULL for none. */
static pk_status first_texture(xp *p, xnode *b, const xnode *skip, xnode **t)
{
    pk_status st;
    *t = NULL;
    for (xnode *c = b->child; c && !*t; c = c->next) {
        if (c == skip) continue;
        if (strcmp(c->tag, "texture") == 0) *t = c;
        else if (strcmp(c->tag, "ref") == 0) {
            const char *id = attr_st(p, c, "id", &st);
            if (st) return st;
            xnode *r = id ? id_find(p, id) : NULL;
            if (r && strcmp(r->tag, "texture") == 0) *t = r;
        }
    }
    return PK_OK;
}

/* Mitsuba's normal map (normalmap): the nested bsdf with its shading normal
 * taken from a bitmap of tangent-space normals, RGB -> 2 RGB - 1 in the
 * frame of dp/du and the normal, as the material's map_norm
 * (docs/materials.md). The bitmap is read as its "raw" property says (true,
 * as normal maps are written: the stored values; false, Mitsuba's default:
 * an 8-bit image decoded from sRGB). */
static pk_status bsdf_normalmap(xp *p, const bsdf_in *in, material *m)
{
    xnode *b = in->b, *inner = nested_bsdf(p, b);
    pk_status st;
    if (!inner) {
        xwarn(p, b, "bsdf \"%s\" without a nested bsdf; using a grey diffuse material", in->ty);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    if ((st = bsdf_resolve(p, inner, m))) return st;
    if (m->type == MAT_MIX) {
        xwarn(p, b, "bsdf \"%s\" over a mix of bsdfs is not supported; the mix keeps its normals", in->ty);
        return PK_OK;
    }
    xnode *t;
    if ((st = first_texture(p, b, inner, &t))) return st;
    const char *tt = t ? attr_st(p, t, "type", &st) : NULL;
    if (st) return st;
    if (!t || !tt || strcmp(tt, "bitmap") != 0) {
        xwarn(p, b, "bsdf \"%s\": only a bitmap of normals is supported; using its nested bsdf alone", in->ty);
        return PK_OK;
    }
    pdict d;
    const char *fn = NULL;
    xnode *at;
    bool raw = false;
    if ((st = xml_props(p, t, &d)) || (st = get_string(p, &d, "filename", &fn, &at)) ||
        (st = get_bool(p, &d, "raw", &raw)))
        return st;
    if (!fn) return xfail(p, PK_ERR_PARSE, t, "bitmap texture needs a filename");
    char *full = path_join(&p->ctx->alloc, t->file->dir, fn);
    if (!full) return ctx_nomem(p->ctx);
    int32_t idx;
    const bool was_ok = p->ctx->status == PK_OK;
    st = texture_load(p->ctx, p->s, full, !raw, &idx);
    mem_free(&p->ctx->alloc, full);
    if (st != PK_OK) {
        char why[PK_ERRMSG_MAX];
        if (!io_demote_error(p->ctx, st, was_ok, why, sizeof why)) return st;
        xwarn(p, t, "normal map not used (%s); the normals are the surface's", why);
        return PK_OK;
    }
    tex_ref_init(&m->map_norm);
    m->map_norm.kind = TEX_IMAGE;
    m->map_norm.tex = idx;
    return PK_OK;
}

/* Mitsuba's bump map (bumpmap, Mitsuba 0.x's bump): the nested bsdf with its
 * shading normal bent by a height texture, displaced along the normal in
 * scene units, as the material's map_bump with bm the product of the scale
 * textures wrapped around the bitmap and the bumpmap's own "scale" (Mitsuba
 * 3). A height that is not a bitmap leaves the nested bsdf alone (warning). */
static pk_status bsdf_bump(xp *p, const bsdf_in *in, material *m)
{
    xnode *b = in->b, *inner = nested_bsdf(p, b);
    const char *ty = in->ty;
    pdict *d = in->d;
    pk_status st;
    float scale = 1.0f;
    if ((st = get_float(p, d, "scale", &scale))) return st;
    if (!inner) {
        xwarn(p, b, "bsdf \"%s\" without a nested bsdf; using a grey diffuse material", ty);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    if ((st = bsdf_resolve(p, inner, m))) return st;
    if (m->type == MAT_MIX) { /* each hit shades one of the mix's materials, which have no bump map */
        xwarn(p, b, "bsdf \"%s\" over a mix of bsdfs is not supported; the mix is not bumped", ty);
        return PK_OK;
    }
    /* the height: the first texture child (or a reference to one), through scale textures */
    xnode *t;
    if ((st = first_texture(p, b, inner, &t))) return st;
    for (int depth = 0; t && depth <= XML_MAX_BSDF_DEPTH; depth++) {
        const char *tt = attr_st(p, t, "type", &st);
        if (st) return st;
        if (!tt || strcmp(tt, "scale") != 0) break;
        float f = 1.0f;
        pdict td;
        if ((st = xml_props(p, t, &td)) || (st = get_float(p, &td, "scale", &f))) return st;
        scale *= f;
        xnode *next = NULL;
        for (xnode *c = t->child; c && !next; c = c->next) {
            if (strcmp(c->tag, "texture") == 0) next = c;
            else if (strcmp(c->tag, "ref") == 0) {
                const char *id = attr_st(p, c, "id", &st);
                if (st) return st;
                xnode *r = id ? id_find(p, id) : NULL;
                if (r && strcmp(r->tag, "texture") == 0) next = r;
            }
        }
        t = next;
    }
    const char *tt = t ? attr_st(p, t, "type", &st) : NULL;
    if (st) return st;
    if (!t || !tt || strcmp(tt, "bitmap") != 0) {
        xwarn(p, b, "bsdf \"%s\": only a bitmap height (scaled or not) bends the normal; using its nested bsdf alone",
              ty);
        return PK_OK;
    }
    tex_ref r;
    tex_ref_init(&r);
    tex_ref *want = p->want_tex;
    p->want_tex = &r;
    vec3 v;
    st = texture_value(p, t, "the bump map", v3s(0.0f), &v, 0);
    p->want_tex = want;
    if (st) return st;
    if (r.kind == TEX_NONE) return PK_OK; /* the image could not be read: warned */
    r.bm = scale;
    m->map_bump = r;
    return PK_OK;
}

/* Converts the bsdf (or <ref> to one) n into *m. */
static pk_status bsdf_resolve(xp *p, xnode *n, material *m)
{
    pk_status st;
    if (strcmp(n->tag, "ref") == 0) {
        const char *id = attr_st(p, n, "id", &st);
        if (st) return st;
        if (!id) return xfail(p, PK_ERR_PARSE, n, "<ref> needs an id");
        xnode *t = id_find(p, id);
        if (!t || strcmp(t->tag, "bsdf") != 0) {
            char sid[48];
            shown(sid, sizeof sid, id);
            return xfail(p, PK_ERR_PARSE, n, "no bsdf has the id \"%s\"%s", sid, t ? "" : " (defined before here)");
        }
        n = t;
    }
    if (n->busy) return xfail(p, PK_ERR_PARSE, n, "reference cycle through this bsdf");
    if (p->bsdf_depth >= XML_MAX_BSDF_DEPTH)
        return xfail(p, PK_ERR_LIMIT, n, "bsdfs nested more than %d deep", XML_MAX_BSDF_DEPTH);
    n->busy = true;
    p->bsdf_depth++;
    st = bsdf_material(p, n, m);
    p->bsdf_depth--;
    n->busy = false;
    return st;
}

static void warn_unused(pdict *d, const char *kind, const char *const *quiet);

/* ---- the Mitsuba BSDFs: one creator per plugin type ---------------------------------------- */

static pk_status bsdf_twosided(xp *p, const bsdf_in *in, material *m)
{
    /* one-sided materials are shaded from either side already (the
     * shading normal faces the viewer); only emission is one-sided */
    xnode *inner = nested_bsdf(p, in->b);
    if (!inner) return xfail(p, PK_ERR_PARSE, in->b, "twosided needs a nested bsdf");
    for (xnode *c = inner->next; c; c = c->next)
        if (strcmp(c->tag, "bsdf") == 0) {
            xwarn(p, c, "twosided with a second bsdf for the back side is not supported; the front one is "
                        "used on both");
            break;
        }
    return bsdf_resolve(p, inner, m);
}

static pk_status bsdf_mask(xp *p, const bsdf_in *in, material *m)
{
    xnode *inner = nested_bsdf(p, in->b);
    float opacity = 0.5f;
    pk_status st = get_scalar(p, in->d, "opacity", &opacity);
    if (st) return st;
    if (inner && (st = bsdf_resolve(p, inner, m))) return st;
    if (!inner) material_diffuse(m, v3s(0.5f));
    if (m->type == MAT_MIX) { /* each hit shades one of the mix's materials, which have no mask */
        xwarn(p, in->b, "bsdf \"mask\" over a mix of bsdfs is not supported; the mix is opaque");
        return PK_OK;
    }
    if (m->type != MAT_DIELECTRIC) m->d = clamp01(opacity);
    return PK_OK;
}

/* a dielectric coat over a diffuse base is Paprsek's plastic */
static pk_status bsdf_coating(xp *p, const bsdf_in *in, material *m)
{
    xnode *inner = nested_bsdf(p, in->b);
    float alpha = 0.0f, ior;
    bool bk = false, rough = in->type[0] == 'r';
    pk_status st;
    if (rough && (st = get_alpha(p, in->d, 0.1f, &alpha, NULL, &bk, NULL))) return st;
    if ((st = get_rel_ior(p, in->d, 1.5046f, &ior))) return st;
    if (inner && (st = bsdf_resolve(p, inner, m))) return st;
    if (inner && m->type == MAT_DIFFUSE && ior > 0.0f && ior != 1.0f) {
        vec3 kd = m->kd;
        float opacity = m->d;
        material_init(m);
        m->d = opacity;
        material_plastic(m, kd, ior, alpha);
        m->beckmann = bk;
        static const char *const q[] = {"distribution", NULL};
        warn_unused(in->d, rough ? "bsdf \"roughcoating\"" : "bsdf \"coating\"", q);
        return PK_OK;
    }
    if (!inner) {
        xwarn(p, in->b, "bsdf \"%s\" without a nested bsdf; using a grey diffuse material", in->ty);
        material_init(m);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    xwarn(p, in->b, "bsdf \"%s\" over a non-diffuse bsdf is not supported; using its nested bsdf alone", in->ty);
    return PK_OK;
}

/* polarizer, measured: the nested bsdf alone */
static pk_status bsdf_nested_only(xp *p, const bsdf_in *in, material *m)
{
    xnode *inner = nested_bsdf(p, in->b);
    if (!inner) {
        xwarn(p, in->b, "bsdf \"%s\" is not supported; using a grey diffuse material", in->ty);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    xwarn(p, in->b, "bsdf \"%s\" is not supported; using its nested bsdf alone", in->ty);
    return bsdf_resolve(p, inner, m);
}

static pk_status bsdf_diffuse(xp *p, const bsdf_in *in, material *m)
{
    vec3 r = v3s(0.5f);
    pk_status st = get_color_tex(p, in->d, "reflectance", &r, &m->map_kd);
    if (st) return st;
    if (in->type[0] == 'r') { /* Oren-Nayar: alpha (default 0.2) is the facets' RMS slope, sigma = alpha / sqrt(2) */
        float alpha = 0.2f;
        bool fast = false;
        if ((st = get_scalar(p, in->d, "alpha", &alpha)) || (st = get_bool(p, in->d, "use_fast_approx", &fast)))
            return st;
        material_rough_diffuse(m, clamp01v(r), alpha);
        return PK_OK;
    }
    material_diffuse(m, clamp01v(r));
    return PK_OK;
}

/* Mitsuba 0.6's phong: diffuse_reflectance (0.5), specular_reflectance
 * (0.2), exponent (30). */
static pk_status bsdf_phong(xp *p, const bsdf_in *in, material *m)
{
    vec3 kd = v3s(0.5f), ks = v3s(0.2f);
    float n = 30.0f;
    pk_status st;
    if ((st = get_color_tex(p, in->d, "diffuse_reflectance", &kd, &m->map_kd)) ||
        (st = get_color_tex(p, in->d, "specular_reflectance", &ks, &m->map_ks)) ||
        (st = get_scalar(p, in->d, "exponent", &n)))
        return st;
    material_phong(m, clamp01v(kd), clamp01v(ks), n);
    return PK_OK;
}

/* The nested bsdfs of b (at most max), in order. */
static int nested_bsdfs(xp *p, xnode *b, xnode **out, int max)
{
    int n = 0;
    for (xnode *c = b->child; c; c = c->next)
        if (strcmp(c->tag, "bsdf") == 0 || (strcmp(c->tag, "ref") == 0 && !attr_st(p, c, "name", &(pk_status){0}))) {
            if (n < max) out[n] = c;
            n++;
        }
    return n;
}

/* The scene material of the nested bsdf c, which a mix may name. */
static pk_status mix_part(xp *p, xnode *c, uint32_t *idx)
{
    pk_status st = material_of(p, c, idx);
    if (st == PK_OK && scene_mix_depth(p->s, *idx) >= MATERIAL_MIX_DEPTH)
        return xfail(p, PK_ERR_LIMIT, c, "mixes of bsdfs nested more than %d deep", MATERIAL_MIX_DEPTH);
    return st;
}

/* blendbsdf: the second nested bsdf with probability weight (a float or a
 * texture, 0.5 by default), the first otherwise, chosen per hit. */
static pk_status bsdf_blend(xp *p, const bsdf_in *in, material *m)
{
    xnode *kid[2];
    const int n = nested_bsdfs(p, in->b, kid, 2);
    if (n != 2) {
        xwarn(p, in->b, "bsdf \"blendbsdf\" needs two nested bsdfs, not %d; using %s", n,
              n ? "the first alone" : "a grey diffuse material");
        if (n) return bsdf_resolve(p, kid[0], m);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    vec3 w = v3s(0.5f);
    tex_ref map;
    tex_ref_init(&map);
    uint32_t a, b;
    pk_status st;
    if ((st = get_color_tex(p, in->d, "weight", &w, &map)) || (st = mix_part(p, kid[0], &a)) ||
        (st = mix_part(p, kid[1], &b)))
        return st;
    material_mix(m, (int)a, (int)b, (w.x + w.y + w.z) / 3.0f);
    m->map_alpha = map;
    return PK_OK;
}

/* mixturebsdf: nested bsdf i with probability weights[i] (a list of
 * numbers, "0.3, 0.7"), by a chain of two-way mixes: the first against the
 * rest with weight w0 / (w0 + w1 + ...), and so on. Weights that add up to
 * more than 1 are normalised (Mitsuba's ensureEnergyConservation); to less,
 * the rest goes to a black material (light absorbed, as Mitsuba's sum). */
#define XML_MIXTURE_MAX 16
static pk_status bsdf_mixture(xp *p, const bsdf_in *in, material *m)
{
    xnode *kid[XML_MIXTURE_MAX];
    const int n = nested_bsdfs(p, in->b, kid, XML_MIXTURE_MAX);
    if (n > XML_MIXTURE_MAX)
        return xfail(p, PK_ERR_LIMIT, in->b, "bsdf \"mixturebsdf\": more than %d nested bsdfs", XML_MIXTURE_MAX);
    const char *ws = NULL;
    xnode *at = NULL;
    bool ensure = true;
    pk_status st;
    if ((st = get_string(p, in->d, "weights", &ws, &at)) || (st = get_bool(p, in->d, "ensure_energy_conservation", &ensure)))
        return st;
    float w[XML_MIXTURE_MAX + 1];
    int nw = 0;
    if (ws) {
        const char *c = ws, *e = ws + strlen(ws);
        while (c < e) {
            while (c < e && (io_is_blank(*c) || *c == ',')) c++;
            if (c == e) break;
            float v;
            const char *next = io_parse_float(c, e, &v);
            if (!next || next == c || !(v >= 0.0f) || !isfinite(v))
                return xfail(p, PK_ERR_PARSE, at, "bsdf \"mixturebsdf\": weights must be numbers >= 0");
            if (nw < XML_MIXTURE_MAX) w[nw] = v;
            nw++;
            c = next;
        }
    }
    if (n == 0 || nw != n)
        return xfail(p, PK_ERR_PARSE, at ? at : in->b,
                     "bsdf \"mixturebsdf\" needs as many weights (%d) as nested bsdfs (%d)", nw, n);
    float sum = 0.0f;
    for (int i = 0; i < n; i++) sum += w[i];
    if (!(sum > 0.0f)) return xfail(p, PK_ERR_PARSE, at, "bsdf \"mixturebsdf\": the weights add up to 0");
    if (sum > 1.0f && !ensure)
        xwarn(p, in->b, "bsdf \"mixturebsdf\": weights adding up to %g > 1 are normalised (energy is conserved)",
              (double)sum);
    uint32_t idx[XML_MIXTURE_MAX + 1];
    for (int i = 0; i < n; i++)
        if ((st = mix_part(p, kid[i], &idx[i]))) return st;
    int parts = n;
    if (sum < 1.0f) { /* the absorbed rest */
        char name[96];
        snprintf(name, sizeof name, "mixturebsdf@%s:%lu:black", in->b->file->shown, in->b->line);
        if ((st = scene_add_material(p->ctx, p->s, name, &idx[n]))) return st;
        material_diffuse(&p->s->materials[idx[n]], v3s(0.0f));
        w[n] = 1.0f - sum;
        parts = n + 1;
    }
    /* from the end: rest = mix(part i, rest) with the rest's probability */
    uint32_t rest = idx[parts - 1];
    float wrest = w[parts - 1];
    for (int i = parts - 2; i >= 0; i--) {
        const float total = w[i] + wrest, amount = total > 0.0f ? wrest / total : 0.0f;
        if (i == 0) {
            material_mix(m, (int)idx[0], (int)rest, amount);
            return PK_OK;
        }
        char name[96];
        snprintf(name, sizeof name, "mixturebsdf@%s:%lu:%d", in->b->file->shown, in->b->line, i);
        uint32_t mi;
        if ((st = scene_add_material(p->ctx, p->s, name, &mi))) return st;
        material_mix(&p->s->materials[mi], (int)idx[i], (int)rest, amount);
        if (scene_mix_depth(p->s, mi) > MATERIAL_MIX_DEPTH)
            return xfail(p, PK_ERR_LIMIT, in->b, "mixes of bsdfs nested more than %d deep", MATERIAL_MIX_DEPTH);
        rest = mi, wrest = total;
    }
    return bsdf_resolve(p, kid[0], m); /* one bsdf of weight 1 */
}

static pk_status bsdf_conductor(xp *p, const bsdf_in *in, material *m)
{
    vec3 eta, k;
    spectra_named_metal("Cu", &eta, &k); /* Mitsuba's default */
    vec3 spec = v3s(1.0f);
    float ext = 1.000277f;
    bool none = false;
    const char *mat = NULL;
    xnode *mat_at;
    pk_status st;
    if ((st = get_string(p, in->d, "material", &mat, &mat_at))) return st;
    if (mat) {
        if (strcmp(mat, "none") == 0) none = true;
        else if (!spectra_named_metal(mat, &eta, &k)) {
            char sm[40];
            shown(sm, sizeof sm, mat);
            xwarn(p, mat_at, "conductor material \"%s\" is not in the table (Cu, Au, Ag, Al, Cr, none); using Cu", sm);
        }
    }
    /* a texture on eta or k multiplies it per hit */
    if ((st = get_color_tex(p, in->d, "eta", &eta, &m->map_eta))) return st;
    if ((st = get_color_tex(p, in->d, "k", &k, &m->map_k))) return st;
    if ((st = get_ior(p, in->d, "ext_eta", &ext))) return st;
    if ((st = get_color(p, in->d, "specular_reflectance", &spec))) return st;
    eta = v3_scale(eta, 1.0f / ext), k = v3_scale(k, 1.0f / ext);
    eta = v3(fmaxf(eta.x, 1e-4f), fmaxf(eta.y, 1e-4f), fmaxf(eta.z, 1e-4f));
    k = v3(fmaxf(k.x, 0.0f), fmaxf(k.y, 0.0f), fmaxf(k.z, 0.0f));
    spec = clamp01v(spec);
    /* "none": a perfect mirror (Schlick's Fresnel of F0 = 1 is 1 at every
     * angle). Mitsuba (0.6 and 3) multiplies the conductor's Fresnel term by
     * specular_reflectance, and Tungsten its whole BRDF by albedo (which is
     * where Bitterli's 0.3 on the "Veach, MIS" plates comes from): a factor
     * at every angle, not a smaller F0 that grazing light would raise back
     * to 1 (tests/render/test_veach_plates.c) */
    if (none) material_conductor_f0(m, v3s(1.0f), in->alpha);
    else material_conductor(m, eta, k, in->alpha);
    m->alpha_v = in->alpha_v;
    if (spec.x != 1.0f || spec.y != 1.0f || spec.z != 1.0f) material_conductor_tint(m, spec);
    m->beckmann = in->beckmann;
    return PK_OK;
}

/* The specular_reflectance of dielectric and plastic: only 1 is rendered. */
static pk_status specular_one(xp *p, const bsdf_in *in)
{
    vec3 refl = v3s(1.0f);
    pk_status st = get_color(p, in->d, "specular_reflectance", &refl);
    if (st == PK_OK && (refl.x != 1.0f || refl.y != 1.0f || refl.z != 1.0f))
        xwarn(p, in->b, "%s: specular_reflectance other than 1 is not supported; ignored", in->ty);
    return st;
}

static pk_status bsdf_dielectric(xp *p, const bsdf_in *in, material *m)
{
    vec3 tr = v3s(1.0f);
    float ior = in->ior, alpha = in->alpha;
    pk_status st;
    if ((st = get_color_tex(p, in->d, "specular_transmittance", &tr, &m->map_tf)) || (st = specular_one(p, in)))
        return st;
    if (in->type[0] == 't') { /* a thin sheet: reflects by R' and lets the rest through unbent */
        material_thin_dielectric(m, ior, clamp01v(tr));
        return PK_OK;
    }
    float alpha_v = in->alpha_v;
    if (ior == 1.0f && (alpha > 0.0f || alpha_v > 0.0f)) alpha = 0.0f, alpha_v = -1.0f;
    material_dielectric(m, ior, alpha, clamp01v(tr));
    m->alpha_v = alpha_v;
    m->beckmann = in->beckmann;
    return PK_OK;
}

static pk_status bsdf_plastic(xp *p, const bsdf_in *in, material *m)
{
    vec3 kd = v3s(0.5f);
    pk_status st;
    if ((st = get_color_tex(p, in->d, "diffuse_reflectance", &kd, &m->map_kd)) || (st = specular_one(p, in)))
        return st;
    material_plastic(m, clamp01v(kd), !(in->ior > 0.0f) || in->ior == 1.0f ? 1.49f : in->ior, in->alpha);
    m->beckmann = in->beckmann;
    return PK_OK;
}

/* What principled and principledthin read alike: base_color and roughness
 * (textures allowed: map_kd, map_alpha), the n parameters names[] in [0, 1]
 * (clamped with a warning) into v[], and the nr sampling rates rates[]
 * (>= 0, 1 by default) into rate[]. */
static pk_status principled_common(xp *p, const bsdf_in *in, material *m, const char *const *names, int n, float *v,
                                   const char *const *rates, int nr, float *rate)
{
    vec3 base = v3s(0.5f);
    float roughness = 0.5f;
    material_principled(m, base, 0.0f, roughness);
    pk_status st;
    if ((st = get_color_tex(p, in->d, "base_color", &base, &m->map_kd))) return st;
    p->want_tex = &m->map_alpha;
    st = get_scalar(p, in->d, "roughness", &roughness);
    p->want_tex = NULL;
    if (st) return st;
    for (int k = 0; k < n; k++) {
        if ((st = get_scalar(p, in->d, names[k], &v[k]))) return st;
        if (!(v[k] >= 0.0f && v[k] <= 1.0f)) {
            xwarn(p, in->b, "%s must be in [0, 1], not %g; clamped", names[k], (double)v[k]);
            v[k] = clamp01(v[k]);
        }
    }
    for (int k = 0; k < nr; k++) {
        if ((st = get_float(p, in->d, rates[k], &rate[k]))) return st;
        if (!(rate[k] >= 0.0f)) {
            xwarn(p, in->b, "%s must be >= 0, not %g; using 1", rates[k], (double)rate[k]);
            rate[k] = 1.0f;
        }
    }
    m->kd = clamp01v(base);
    m->roughness = clamp01(roughness);
    return PK_OK;
}

/* Mitsuba 3's principled BSDF with all its parameters (MAT_PRINCIPLED):
 * base_color and roughness may be textures (map_kd, map_alpha), the other
 * parameters are constants (a texture stands in as one, with a warning).
 * eta and specular are two ways to give the index (eta = 2 / (1 - sqrt(0.08
 * specular)) - 1); Mitsuba refuses both at once, here eta wins. */
static pk_status bsdf_principled(xp *p, const bsdf_in *in, material *m)
{
    static const char *const names[] = {"metallic",  "spec_trans", "anisotropic", "spec_tint",      "sheen",
                                        "sheen_tint", "flatness",   "clearcoat",   "clearcoat_gloss"};
    float v[9] = {0};
    float eta = 1.5f, specular = 0.5f;
    float rate[3] = {1.0f, 1.0f, 1.0f};
    static const char *const rates[] = {"main_specular_sampling_rate", "clearcoat_sampling_rate",
                                        "diffuse_reflectance_sampling_rate"};
    pk_status st = principled_common(p, in, m, names, 9, v, rates, 3, rate);
    if (st) return st;
    const bool has_eta = pd_has(in->d, "eta"), has_spec = pd_has(in->d, "specular");
    if ((st = get_float(p, in->d, "eta", &eta)) || (st = get_float(p, in->d, "specular", &specular))) return st;
    const bool has_trans = pd_has(in->d, "spec_trans") && v[1] != 0.0f;
    if (has_eta && has_spec) xwarn(p, in->b, "principled takes eta or specular, not both; using eta %g", (double)eta);
    if (has_eta) {
        if (!(eta > 0.0f)) {
            xwarn(p, in->b, "eta must be > 0, not %g; using 1.5", (double)eta);
            eta = 1.5f;
        }
        if (has_trans && eta == 1.0f) eta = 1.001f; /* as Mitsuba: an index of 1 cannot refract */
    } else {
        if (!(specular >= 0.0f && specular < 12.5f)) {
            xwarn(p, in->b, "specular must be in [0, 12.5), not %g; using 0.5", (double)specular);
            specular = 0.5f;
        }
        if (has_trans && specular == 0.0f) specular = 1e-3f;
        eta = 2.0f / (1.0f - sqrtf(0.08f * specular)) - 1.0f;
    }
    m->metallic = v[0], m->transmission = v[1], m->anisotropic = v[2], m->spec_tint = v[3];
    m->sheen = v[4], m->sheen_tint = v[5], m->flatness = v[6], m->clearcoat = v[7], m->clearcoat_gloss = v[8];
    m->srate_spec = rate[0], m->srate_cc = rate[1], m->srate_diff = rate[2];
    m->ni = eta;
    material_principled_update(m);
    return PK_OK;
}

/* Mitsuba 3's principledthin (MAT_PRINCIPLED with thin): a two-sided sheet
 * with base_color and roughness (textures allowed, as principled's),
 * anisotropic, spec_trans, spec_tint, sheen, sheen_tint, flatness (0 ... 1),
 * diff_trans (0 ... 2, halved as Mitsuba does), eta (1.5) and the four
 * sampling rates. */
static pk_status bsdf_principled_thin(xp *p, const bsdf_in *in, material *m)
{
    static const char *const names[] = {"spec_trans", "anisotropic", "spec_tint", "sheen", "sheen_tint", "flatness"};
    static const char *const rates[] = {"specular_reflectance_sampling_rate", "specular_transmittance_sampling_rate",
                                        "diffuse_reflectance_sampling_rate", "diffuse_transmittance_sampling_rate"};
    float v[6] = {0}, rate[4] = {1.0f, 1.0f, 1.0f, 1.0f};
    float eta = 1.5f, diff_trans = 0.0f;
    pk_status st = principled_common(p, in, m, names, 6, v, rates, 4, rate);
    if (st) return st;
    if ((st = get_scalar(p, in->d, "diff_trans", &diff_trans)) || (st = get_float(p, in->d, "eta", &eta))) return st;
    if (!(diff_trans >= 0.0f && diff_trans <= 2.0f)) {
        xwarn(p, in->b, "diff_trans must be in [0, 2], not %g; clamped", (double)diff_trans);
        diff_trans = diff_trans > 2.0f ? 2.0f : 0.0f;
    }
    if (!(eta > 0.0f)) {
        xwarn(p, in->b, "eta must be > 0, not %g; using 1.5", (double)eta);
        eta = 1.5f;
    }
    m->thin = true;
    m->transmission = v[0], m->anisotropic = v[1], m->spec_tint = v[2];
    m->sheen = v[3], m->sheen_tint = v[4], m->flatness = v[5];
    m->diff_trans = 0.5f * diff_trans;
    m->srate_spec = rate[0], m->srate_st = rate[1], m->srate_diff = rate[2], m->srate_dt = rate[3];
    m->ni = eta;
    material_principled_update(m);
    return PK_OK;
}

/* The MITSUBA dialect's BSDFs. rough: get_alpha first (default 0.1);
 * int_ior: the default of int_ior, read (with ext_ior) next, 0 for none;
 * create NULL: the interface (no surface);
 * kind: the unread properties' warning after the creator (NULL: none or
 * the creator's own; "": bsdf "TYPE"). The names are Mitsuba's;
 * these rules are not the JSON scene's (create_material.c): Mitsuba clamps
 * colours, takes textures, spectra and named indices of refraction in
 * typed elements, and reads a value only when its type asks for it. */
typedef struct bsdf_row {
    const char *type;
    pk_status (*create)(xp *p, const bsdf_in *in, material *m);
    bool rough;
    float int_ior;
    const char *kind;
} bsdf_row;
static const bsdf_row bsdf_rows[] = {
    {"twosided", bsdf_twosided, false, 0.0f, NULL},
    {"mask", bsdf_mask, false, 0.0f, "mask"},
    {"coating", bsdf_coating, false, 0.0f, NULL},
    {"roughcoating", bsdf_coating, false, 0.0f, NULL},
    {"bumpmap", bsdf_bump, false, 0.0f, NULL},
    {"bump", bsdf_bump, false, 0.0f, NULL},
    {"normalmap", bsdf_normalmap, false, 0.0f, NULL},
    {"blendbsdf", bsdf_blend, false, 0.0f, ""},
    {"mixturebsdf", bsdf_mixture, false, 0.0f, ""},
    {"polarizer", bsdf_nested_only, false, 0.0f, NULL},
    {"measured", bsdf_nested_only, false, 0.0f, NULL},
    {"diffuse", bsdf_diffuse, false, 0.0f, ""},
    {"roughdiffuse", bsdf_diffuse, false, 0.0f, ""},
    {"phong", bsdf_phong, false, 0.0f, ""},
    {"conductor", bsdf_conductor, false, 0.0f, ""},
    {"roughconductor", bsdf_conductor, true, 0.0f, ""},
    {"dielectric", bsdf_dielectric, false, 1.5046f, ""},
    {"roughdielectric", bsdf_dielectric, true, 1.5046f, ""},
    {"thindielectric", bsdf_dielectric, false, 1.5046f, ""},
    {"plastic", bsdf_plastic, false, 1.49f, ""},
    {"roughplastic", bsdf_plastic, true, 1.49f, ""},
    {"principled", bsdf_principled, false, 0.0f, ""},
    {"principledthin", bsdf_principled_thin, false, 0.0f, ""},
    {"null", NULL, false, 0.0f, ""}, /* no surface: light passes straight through; it may bound media */
};

/* Fills *m (material_init'ed, name unset) from the bsdf element b: its
 * row's creator, or a grey diffuse for a type with none. */
static pk_status bsdf_material(xp *p, xnode *b, material *m)
{
    pk_status st;
    const char *type = attr_st(p, b, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, b, "<bsdf> needs a type");
    material_init(m);
    char ty[40];
    shown(ty, sizeof ty, type);
    pdict d;
    if ((st = xml_props(p, b, &d))) return st;
    const size_t nrows = sizeof bsdf_rows / sizeof bsdf_rows[0];
    size_t r = 0;
    while (r < nrows && strcmp(bsdf_rows[r].type, type) != 0) r++;
    if (r == nrows) {
        xwarn(p, b, "bsdf \"%s\" is not supported; using a grey diffuse material", ty);
        material_diffuse(m, v3s(0.5f));
        return PK_OK;
    }
    const bsdf_row *row = &bsdf_rows[r];
    bsdf_in in = {.b = b, .d = &d, .type = type, .ty = ty, .alpha_v = -1.0f};
    /* Mitsuba's rough conductor and dielectric take alpha_u and alpha_v; its rough plastic does not */
    const bool aniso = row->create == bsdf_conductor || row->create == bsdf_dielectric;
    tex_ref_init(&in.alpha_tex);
    if (row->rough &&
        (st = get_alpha(p, &d, 0.1f, &in.alpha, aniso ? &in.alpha_v : NULL, &in.beckmann, &in.alpha_tex)))
        return st;
    if (row->int_ior > 0.0f && (st = get_rel_ior(p, &d, row->int_ior, &in.ior))) return st;
    if (!row->create) material_interface(m);
    else if ((st = row->create(p, &in, m)) || !row->kind) return st;
    if (in.alpha_tex.kind) m->map_alpha = in.alpha_tex; /* the roughness is the texture's value (alpha 1) */
    static const char *const quiet[] = {"ext_ior", "ext_eta", "nonlinear", "distribution", "sample_visible", NULL};
    char kind[64];
    snprintf(kind, sizeof kind, "bsdf \"%s\"", ty);
    warn_unused(&d, row->kind[0] ? row->kind : kind, quiet);
    return PK_OK;
}

/* A material for element b (a bsdf or a ref), made once per bsdf element. */
static pk_status material_of(xp *p, xnode *b, uint32_t *index)
{
    pk_status st;
    xnode *target = b;
    if (strcmp(b->tag, "ref") == 0) {
        const char *id = attr_st(p, b, "id", &st);
        if (st) return st;
        xnode *t = id ? id_find(p, id) : NULL;
        if (t && strcmp(t->tag, "bsdf") == 0) target = t;
    }
    if (target->mat >= 0) {
        *index = (uint32_t)target->mat;
        return PK_OK;
    }
    material m;
    if ((st = bsdf_resolve(p, b, &m))) return st;
    char name[96];
    const char *id = attr_st(p, target, "id", &st);
    if (id) {
        shown(name, sizeof name, id);
    } else {
        snprintf(name, sizeof name, "bsdf@%s:%lu", target->file->shown, target->line);
    }
    uint32_t idx;
    if ((st = scene_add_material(p->ctx, p->s, name, &idx))) return st;
    material *dst = &p->s->materials[idx];
    char *owned = dst->name;
    *dst = m;
    dst->name = owned;
    target->mat = (int64_t)idx;
    *index = idx;
    return PK_OK;
}

/* ---- unused properties --------------------------------------------------------------------- */

static bool is_property_tag(const char *t)
{
    static const char *const tags[] = {"float", "integer", "boolean", "string", "rgb", "srgb", "spectrum",
                                       "point", "vector", "transform", "texture", "blackbody", NULL};
    for (int i = 0; tags[i]; i++)
        if (strcmp(t, tags[i]) == 0) return true;
    return false;
}

/* The source's warning for a property no code read: once per (kind,
 * property), kind the dictionary's what; only for the property elements
 * (not nested bsdfs, media, references). */
static void xml_warn_unused(void *self, const pdict *d, const pd_entry *e)
{
    xp *p = self;
    const xnode *c = e->node;
    pk_status st;
    const char *nm = is_property_tag(c->tag) ? attr_st(p, c, "name", &st) : NULL;
    char key[128];
    snprintf(key, sizeof key, "%s/%s", d->what, e->name);
    if (!nm || !first_time(p, key)) return;
    char snm[48];
    shown(snm, sizeof snm, nm);
    xwarn(p, c, "%s: property \"%s\" is not supported; ignored", d->what, snm);
}

/* Warns about the properties of d that no code read (kind: "bsdf \"x\""),
 * except those in quiet (NULL-terminated, snake_case). */
static void warn_unused(pdict *d, const char *kind, const char *const *quiet)
{
    size_t nq = 0;
    while (quiet && quiet[nq]) nq++;
    d->what = kind;
    pd_declare(d, quiet, nq);
    pd_report_unused(d);
}

/* ---- meshes ---------------------------------------------------------------------------------- */

/* Appends triangles (tris: 3 indices each into pos) transformed by m, with
 * material mat (sb_add_mesh). flip reverses the winding; normals (optional,
 * local) are transformed by the inverse transpose; uv (optional) holds 2
 * texture coordinates a vertex. */
static pk_status add_mesh(xp *p, const vec3 *pos, const vec3 *nrm, const float *uv, size_t npos, const uint32_t *tris,
                          size_t ntris, const xform *m, bool flip, uint32_t mat)
{
    sb_set_transform(&p->sb, m);
    sb_set_material(&p->sb, mat);
    const sb_mesh mesh = {pos, nrm, uv, npos, tris, ntris, flip};
    return sb_add_mesh(&p->sb, &mesh);
}

/* The unit square [-1, 1]^2 at z = 0, facing +z. */
static pk_status shape_rectangle(xp *p, const xform *m, bool flip, uint32_t mat)
{
    static const vec3 pos[4] = {{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}};
    static const uint32_t tris[6] = {0, 1, 2, 2, 3, 0};
    static const float uv[8] = {0, 0, 1, 0, 1, 1, 0, 1}; /* as Mitsuba's rectangle */
    return add_mesh(p, pos, NULL, uv, 4, tris, 2, m, flip, mat);
}

/* The cube [-1, 1]^3, faces wound outward. */
static pk_status shape_cube(xp *p, const xform *m, bool flip, uint32_t mat)
{
    vec3 pos[8];
    for (int i = 0; i < 8; i++) pos[i] = v3(i & 1 ? 1.0f : -1.0f, i & 2 ? 1.0f : -1.0f, i & 4 ? 1.0f : -1.0f);
    /* each face: its four corners in counter-clockwise order seen from outside */
    static const uint32_t quads[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4},
                                         {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
    uint32_t tris[36];
    for (int f = 0; f < 6; f++) {
        const uint32_t *q = quads[f];
        uint32_t t[6] = {q[0], q[1], q[2], q[2], q[3], q[0]};
        memcpy(tris + 6 * f, t, sizeof t);
    }
    return add_mesh(p, pos, NULL, NULL, 8, tris, 12, m, flip, mat);
}

/* The unit disk at z = 0, facing +z, as a fan of XML_DISK_SEGMENTS triangles. */
static pk_status shape_disk(xp *p, const xform *m, bool flip, uint32_t mat)
{
    vec3 pos[XML_DISK_SEGMENTS + 1];
    float uv[2 * (XML_DISK_SEGMENTS + 1)];
    uint32_t tris[3 * XML_DISK_SEGMENTS];
    pos[0] = v3s(0.0f);
    uv[0] = uv[1] = 0.5f;
    for (int i = 0; i < XML_DISK_SEGMENTS; i++) {
        float a = 2.0f * PK_PI * (float)i / (float)XML_DISK_SEGMENTS;
        pos[i + 1] = v3(cosf(a), sinf(a), 0.0f);
        uv[2 * (i + 1)] = 0.5f + 0.5f * pos[i + 1].x, uv[2 * (i + 1) + 1] = 0.5f + 0.5f * pos[i + 1].y;
        tris[3 * i] = 0, tris[3 * i + 1] = (uint32_t)(i + 1);
        tris[3 * i + 2] = (uint32_t)((i + 1) % XML_DISK_SEGMENTS + 1);
    }
    return add_mesh(p, pos, NULL, uv, XML_DISK_SEGMENTS + 1, tris, XML_DISK_SEGMENTS, m, flip, mat);
}

/* The unit sphere as a latitude-longitude mesh with vertex normals, wound
 * outward (inward with flip). */
static pk_status shape_sphere_mesh(xp *p, const xform *m, bool flip, uint32_t mat)
{
    enum { R = XML_SPHERE_RINGS, S = XML_SPHERE_SEGMENTS, NV = (R + 1) * (S + 1), NT = 2 * R * S };
    const pk_allocator *a = &p->ctx->alloc;
    vec3 *pos = mem_alloc(a, NV * sizeof *pos);
    float *uv = mem_alloc(a, 2 * NV * sizeof *uv);
    uint32_t *tris = mem_alloc(a, 3 * NT * sizeof *tris);
    pk_status st = PK_OK;
    if (!pos || !uv || !tris) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    for (int i = 0; i <= R; i++) {
        float th = PK_PI * (float)i / (float)R;
        for (int j = 0; j <= S; j++) {
            float ph = 2.0f * PK_PI * (float)j / (float)S;
            pos[i * (S + 1) + j] = v3(sinf(th) * cosf(ph), sinf(th) * sinf(ph), cosf(th));
            uv[2 * (i * (S + 1) + j)] = (float)j / (float)S, uv[2 * (i * (S + 1) + j) + 1] = (float)i / (float)R;
        }
    }
    size_t nt = 0;
    for (int i = 0; i < R; i++)
        for (int j = 0; j < S; j++) {
            uint32_t v00 = (uint32_t)(i * (S + 1) + j), v01 = v00 + 1, v10 = v00 + S + 1, v11 = v10 + 1;
            /* outward: (v00, v10, v11) has normal along +r */
            if (i != R - 1) {
                uint32_t t[3] = {v00, v10, v11};
                memcpy(tris + 3 * nt++, t, sizeof t);
            }
            if (i != 0) {
                uint32_t t[3] = {v00, v11, v01};
                memcpy(tris + 3 * nt++, t, sizeof t);
            }
        }
    st = add_mesh(p, pos, flip ? NULL : pos, uv, NV, tris, nt, m, flip, mat);
out:
    mem_free(a, pos);
    mem_free(a, uv);
    mem_free(a, tris);
    return st;
}

/* Reads file (relative to the XML file of n) into *data. */
static pk_status read_relative(xp *p, const xnode *at, const char *rel, char **full, char **data, size_t *size)
{
    pk_context scratch = io_scratch_context(p->ctx);
    pk_status st = io_read_relative(p->ctx, &scratch, at->file->dir, rel, full, data, size);
    return st ? xfail(p, st, at, "%s", scratch.message) : PK_OK;
}

/* Mitsuba emits (and tells inside from outside) by a mesh's shading
 * normals, Paprsek by the winding: the triangles from t0 on are wound to
 * agree with their vertex normals, or lose them with face_normals; then
 * flip_normals reverses them all. */
static void finish_mesh(xp *p, size_t t0, bool face_normals, bool flip)
{
    pk_scene *s = p->s;
    for (size_t t = t0; t < s->ntris; t++) {
        triangle *tr = &s->tris[t];
        bool swap = flip;
        if (face_normals) {
            tr->n[0] = tr->n[1] = tr->n[2] = -1;
        } else if (tr->n[0] >= 0 && tr->n[1] >= 0 && tr->n[2] >= 0) {
            vec3 a, b, c;
            scene_tri_verts(s, t, &a, &b, &c);
            vec3 ng = v3_cross(v3_sub(b, a), v3_sub(c, a));
            vec3 ns = v3_add(v3_add(s->normals[tr->n[0]], s->normals[tr->n[1]]), s->normals[tr->n[2]]);
            if (v3_dot(ng, ns) < 0.0f) swap = !swap;
        }
        if (swap) {
            uint32_t v = tr->v[1];
            int32_t n = tr->n[1];
            tr->v[1] = tr->v[2], tr->n[1] = tr->n[2];
            tr->v[2] = v, tr->n[2] = n;
        }
    }
}

static pk_status shape_obj(xp *p, pdict *d, const xform *m, bool flip, bool has_bsdf, uint32_t mat)
{
    const xnode *sh = d->node;
    pk_status st;
    const char *fn = NULL;
    xnode *at;
    if ((st = get_string(p, d, "filename", &fn, &at))) return st;
    if (!fn) return xfail(p, PK_ERR_PARSE, sh, "shape obj needs a filename");
    bool face_normals = false;
    if ((st = get_bool(p, d, "face_normals", &face_normals))) return st;
    char *full = NULL, *data = NULL, *dir = NULL;
    size_t size = 0;
    size_t t0 = p->s->ntris;
    if ((st = read_relative(p, at, fn, &full, &data, &size))) goto out;
    dir = path_dirname(&p->ctx->alloc, full);
    if (!dir) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    /* the XML's bsdf replaces the OBJ's materials: its MTL is not read */
    if (has_bsdf) st = obj_parse_with_material(p->ctx, p->s, data, size, full, m, mat);
    else st = obj_parse(p->ctx, p->s, data, size, full, dir, m);
    if (st) goto out;
    finish_mesh(p, t0, face_normals, flip);
out:
    mem_free(&p->ctx->alloc, data);
    mem_free(&p->ctx->alloc, dir);
    mem_free(&p->ctx->alloc, full);
    return st;
}

static pk_status shape_ply(xp *p, pdict *d, const xform *m, bool flip, uint32_t mat)
{
    const xnode *sh = d->node;
    pk_status st;
    const char *fn = NULL;
    xnode *at;
    if ((st = get_string(p, d, "filename", &fn, &at))) return st;
    if (!fn) return xfail(p, PK_ERR_PARSE, sh, "shape ply needs a filename");
    bool face_normals = false;
    if ((st = get_bool(p, d, "face_normals", &face_normals))) return st;
    char *full = NULL, *data = NULL;
    size_t size = 0;
    ply_mesh mesh = {0};
    if ((st = read_relative(p, at, fn, &full, &data, &size))) goto out;
    if ((st = ply_parse(p->ctx, data, size, full, &mesh))) goto out;
    size_t t0 = p->s->ntris;
    st = add_mesh(p, mesh.positions, face_normals ? NULL : mesh.normals, mesh.uvs, mesh.nvertices, mesh.indices, mesh.ntriangles,
                  m, false, mat);
    if (st == PK_OK) finish_mesh(p, t0, face_normals, flip);
out:
    ply_mesh_free(p->ctx, &mesh);
    mem_free(&p->ctx->alloc, data);
    mem_free(&p->ctx->alloc, full);
    return st;
}

/* ---- media ------------------------------------------------------------------------------------- */

/* The asymmetry g of a medium's phase function: its <phase> child (or a
 * <ref> to one): isotropic (0) or hg (g, default 0.8 as in Mitsuba); others
 * are warned about and read as isotropic. No phase: isotropic. */
static pk_status medium_phase(xp *p, xnode *med, float *g)
{
    pk_status st;
    xnode *ph = NULL;
    for (xnode *c = med->child; c && !ph; c = c->next) {
        if (strcmp(c->tag, "phase") == 0) {
            ph = c;
        } else if (strcmp(c->tag, "ref") == 0) {
            const char *id = attr_st(p, c, "id", &st);
            if (st) return st;
            xnode *t = id ? id_find(p, id) : NULL;
            if (t && strcmp(t->tag, "phase") == 0) ph = t;
        }
    }
    *g = 0.0f;
    if (!ph) return PK_OK;
    const char *type = attr_st(p, ph, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, ph, "<phase> needs a type");
    pdict d;
    if ((st = xml_props(p, ph, &d))) return st;
    char ty[40];
    shown(ty, sizeof ty, type);
    if (strcmp(type, "hg") == 0) {
        *g = 0.8f;
        xnode *gn = prop(&d, "g");
        if ((st = get_float(p, &d, "g", g))) return st;
        if (!(*g > -1.0f && *g < 1.0f))
            return xfail(p, PK_ERR_PARSE, gn ? gn : ph, "phase \"hg\": g = %g must lie strictly between -1 and 1",
                         (double)*g);
    } else if (strcmp(type, "isotropic") != 0) {
        xwarn(p, ph, "phase function \"%s\" is not supported (isotropic and hg are); isotropic used", ty);
        return PK_OK;
    }
    char kind[64];
    snprintf(kind, sizeof kind, "phase \"%s\"", ty);
    warn_unused(&d, kind, NULL);
    return PK_OK;
}

/* A medium parameter: a constant (a float or a colour), a constvolume or a
 * gridvolume (read, and placed: to_grid maps the grid's unit cube into
 * the medium's space). */
typedef struct xvol {
    bool present, grid;
    vec3 value;
    medium_grid g;   /* a gridvolume's voxels (the scene's allocator) */
    xform to_world;  /* a gridvolume's unit cube into the medium's space */
    xnode *at;
} xvol;

static pk_status medium_volume_read(xp *p, pdict *md, const char *name, vec3 def, xvol *v)
{
    pk_status st;
    *v = (xvol){.value = def, .to_world = xform_identity()};
    xnode *c = prop(md, name);
    if (!c) return PK_OK;
    v->present = true;
    v->at = c;
    if (strcmp(c->tag, "volume") != 0) {
        if (strcmp(c->tag, "texture") == 0 || strcmp(c->tag, "ref") == 0)
            return xfail(p, PK_ERR_UNSUPPORTED, c, "%s: a texture or reference here is not supported (a value or a "
                                                   "<volume> is)", name);
        if ((st = node_color(p, c, &v->value))) return st;
        if (!v3_finite(v->value)) return xfail(p, PK_ERR_PARSE, c, "%s is not finite", name);
        return PK_OK;
    }
    const char *type = attr_st(p, c, "type", &st);
    if (st) return st;
    char ty[40];
    shown(ty, sizeof ty, type ? type : "");
    pdict d;
    if ((st = xml_props(p, c, &d))) return st;
    if (type && strcmp(type, "constvolume") == 0) {
        xnode *val = prop(&d, "value");
        if (val && (st = node_color(p, val, &v->value))) return st;
        if (!v3_finite(v->value)) return xfail(p, PK_ERR_PARSE, c, "%s is not finite", name);
        warn_unused(&d, "volume \"constvolume\"", NULL);
        return PK_OK;
    }
    if (!type || strcmp(type, "gridvolume") != 0)
        return xfail(p, PK_ERR_UNSUPPORTED, c, "volume \"%s\" is not supported (constvolume and gridvolume are)", ty);
    const char *fn = NULL;
    xnode *fat;
    if ((st = get_string(p, &d, "filename", &fn, &fat))) return st;
    if (!fn) return xfail(p, PK_ERR_PARSE, c, "volume \"gridvolume\" needs a filename");
    char *full = path_join(&p->ctx->alloc, fat->file->dir, fn);
    if (!full) return ctx_nomem(p->ctx);
    pk_context scratch = io_scratch_context(p->ctx);
    aabb box;
    st = grid_read_vol(&scratch, &p->s->alloc, full, &v->g, &box);
    mem_free(&p->ctx->alloc, full);
    if (st) return xfail(p, st, fat, "%s", scratch.message);
    v->grid = true;
    /* the grid's box: Mitsuba 0.x, the file's (or min and max); Mitsuba 3,
     * the unit cube unless use_grid_bbox */
    bool use_box = p->version_major < 2;
    if ((st = get_bool(p, &d, "use_grid_bbox", &use_box))) return st;
    if (p->version_major < 2) {
        bool has_lo, has_hi;
        vec3 lo = box.lo, hi = box.hi;
        if ((st = get_vec(p, &d, "min", &lo, &has_lo)) || (st = get_vec(p, &d, "max", &hi, &has_hi))) return st;
        if (has_lo && has_hi) box.lo = lo, box.hi = hi;
        if (!(box.hi.x > box.lo.x && box.hi.y > box.lo.y && box.hi.z > box.lo.z))
            return xfail(p, PK_ERR_PARSE, c, "the grid's box is empty or inverted");
    }
    if (!use_box) box = (aabb){v3s(0.0f), v3s(1.0f)};
    if (p->version_major < 2) {
        /* Mitsuba 0.x puts the voxels' values at the box's grid points
         * (voxel i at lo + i (hi - lo) / (n - 1)); Paprsek's voxels are cell
         * centred: the cells grow the box by half a cell on each side */
        const int nn[3] = {v->g.nx, v->g.ny, v->g.nz};
        float lo[3] = {box.lo.x, box.lo.y, box.lo.z}, hi[3] = {box.hi.x, box.hi.y, box.hi.z};
        for (int a = 0; a < 3; a++) {
            if (nn[a] < 2) continue;
            const float half = 0.5f * (hi[a] - lo[a]) / (float)(nn[a] - 1);
            lo[a] -= half, hi[a] += half;
        }
        box = (aabb){v3(lo[0], lo[1], lo[2]), v3(hi[0], hi[1], hi[2])};
    }
    xform tw;
    if ((st = get_to_world(p, &d, &tw, NULL))) return st;
    const xform t = xform_translate(box.lo), sc = xform_scale(v3_sub(box.hi, box.lo)), ts = xform_mul(&t, &sc);
    v->to_world = xform_mul(&tw, &ts);
    static const char *const quiet[] = {"filter_type", "wrap_mode", "raw", "accel", "send_data", "max_value", NULL};
    warn_unused(&d, "volume \"gridvolume\"", quiet);
    return PK_OK;
}

/* medium_volume_read, leaving nothing allocated on failure. */
static pk_status medium_volume(xp *p, pdict *md, const char *name, vec3 def, xvol *v)
{
    pk_status st = medium_volume_read(p, md, name, def, v);
    if (st) {
        mem_free(&p->s->alloc, v->g.data);
        v->g.data = NULL;
        v->grid = false;
    }
    return st;
}

static bool xform_near(const xform *a, const xform *b)
{
    for (int i = 0; i < 12; i++)
        if (fabsf(a->m[i] - b->m[i]) > 1e-5f * (1.0f + fabsf(a->m[i]))) return false;
    return true;
}

/* Checks a homogeneous medium's constants and a grid medium's scales. */
static pk_status medium_values(xp *p, const xnode *mn, vec3 sigma_t, vec3 albedo)
{
    if (!(sigma_t.x >= 0.0f && sigma_t.y >= 0.0f && sigma_t.z >= 0.0f) || !v3_finite(sigma_t))
        return xfail(p, PK_ERR_PARSE, mn, "medium: the extinction (%g, %g, %g) must be finite and not negative",
                     (double)sigma_t.x, (double)sigma_t.y, (double)sigma_t.z);
    if (!(albedo.x >= 0.0f && albedo.y >= 0.0f && albedo.z >= 0.0f && albedo.x <= 1.0f && albedo.y <= 1.0f &&
          albedo.z <= 1.0f))
        return xfail(p, PK_ERR_PARSE, mn, "medium: the albedo (%g, %g, %g) must lie in 0..1", (double)albedo.x,
                     (double)albedo.y, (double)albedo.z);
    return PK_OK;
}

/* Fills *m (medium_init'ed; grids allocated with the scene's allocator)
 * from the <medium> element mn. */
static pk_status medium_convert(xp *p, xnode *mn, medium *m)
{
    pk_status st;
    const char *type = attr_st(p, mn, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, mn, "<medium> needs a type");
    char ty[40];
    shown(ty, sizeof ty, type);
    const bool homog = strcmp(type, "homogeneous") == 0, het = strcmp(type, "heterogeneous") == 0;
    if (!homog && !het)
        return xfail(p, PK_ERR_UNSUPPORTED, mn, "medium \"%s\" is not supported (homogeneous and heterogeneous are)", ty);
    const bool v0 = p->version_major < 2;
    pdict d;
    if ((st = xml_props(p, mn, &d))) return st;
    medium_init(m);
    float scale = 1.0f;
    if ((st = get_float(p, &d, "scale", &scale))) return st;
    xnode *dm = prop(&d, "density_multiplier");
    if (dm) { /* Mitsuba 0.4's name of scale */
        float f = 1.0f;
        if ((st = node_float(p, dm, &f))) return st;
        scale *= f;
        xwarn(p, dm, "densityMultiplier is the old name of scale; read as scale");
    }
    if (!(scale >= 0.0f)) return xfail(p, PK_ERR_PARSE, mn, "medium: scale must not be negative");
    if ((st = medium_phase(p, mn, &m->g))) return st;
    if (prop(&d, "material"))
        return xfail(p, PK_ERR_UNSUPPORTED, mn, "medium presets (\"material\") are not supported; give sigma_a and "
                                                "sigma_s, or sigma_t and albedo");
    static const char *const quiet[] = {"sample_emitters", "method", "step_size", "strategy", "has_spectral_extinction",
                                        "medium_sampling_weight", "channel", "monochromatic", "sampling_density",
                                        NULL};
    char kind[64];
    snprintf(kind, sizeof kind, "medium \"%s\"", ty);
    if (homog) {
        xnode *na = prop(&d, "sigma_a"), *ns = prop(&d, "sigma_s");
        xnode *nt = prop(&d, "sigma_t"), *nl = prop(&d, "albedo");
        if ((na || ns) && (nt || nl))
            return xfail(p, PK_ERR_PARSE, nt ? nt : nl, "medium: give sigma_a and sigma_s, or sigma_t and albedo, not "
                                                        "both");
        vec3 sa, ss;
        if (na || ns) {
            sa = ss = v3s(0.0f);
            if ((st = get_color(p, &d, "sigma_a", &sa)) || (st = get_color(p, &d, "sigma_s", &ss))) return st;
            if (v0 && !(na && ns))
                xwarn(p, mn, "medium: %s missing; Mitsuba 0.6 takes it from its default preset, which is not "
                             "supported: 0 used", na ? "sigmaS" : "sigmaA");
        } else {
            vec3 sig = v3s(1.0f);
            if ((st = get_color(p, &d, "sigma_t", &sig))) return st;
            xvol al;
            if ((st = medium_volume(p, &d, "albedo", v3s(0.75f), &al))) return st;
            if (al.grid) {
                double sum[3] = {0, 0, 0};
                const size_t nv = (size_t)al.g.nx * (size_t)al.g.ny * (size_t)al.g.nz;
                for (size_t i = 0; i < nv; i++)
                    for (int c = 0; c < 3; c++) sum[c] += (double)al.g.data[i * (size_t)al.g.channels + (al.g.channels == 3 ? c : 0)];
                al.value = v3((float)(sum[0] / (double)nv), (float)(sum[1] / (double)nv), (float)(sum[2] / (double)nv));
                mem_free(&p->s->alloc, al.g.data);
                xwarn(p, al.at, "a homogeneous medium's albedo grid is not supported; its mean (%g, %g, %g) used",
                      (double)al.value.x, (double)al.value.y, (double)al.value.z);
            }
            if (v0 && (!nt || !nl))
                xwarn(p, mn, "medium: %s missing; Mitsuba 0.6 takes it from its default preset, which is not "
                             "supported: %s used", nt ? "albedo" : "sigmaT", nt ? "0.75" : "1");
            if ((st = medium_values(p, mn, sig, al.value))) return st;
            ss = v3_mul(sig, al.value);
            sa = v3_max(v3_sub(sig, ss), v3s(0.0f));
        }
        if (!(sa.x >= 0.0f && sa.y >= 0.0f && sa.z >= 0.0f && ss.x >= 0.0f && ss.y >= 0.0f && ss.z >= 0.0f))
            return xfail(p, PK_ERR_PARSE, na ? na : ns, "medium: sigma_a and sigma_s must not be negative");
        if (v0 && prop(&d, "g")) { /* Mitsuba 0.6: g scales sigma_s to the reduced (1 - g) sigma_s */
            vec3 gv = v3s(0.0f);
            if ((st = get_color(p, &d, "g", &gv))) return st;
            const float g = (gv.x + gv.y + gv.z) / 3.0f;
            if (!(g > -1.0f && g < 1.0f)) return xfail(p, PK_ERR_PARSE, mn, "medium: g must lie in (-1, 1)");
            ss = v3_scale(ss, 1.0f - g);
        }
        m->kind = MEDIUM_HOMOGENEOUS;
        medium_set_coefficients(m, sa, ss, scale);
        if ((st = medium_values(p, mn, m->sigma_t, m->albedo))) return st;
        warn_unused(&d, kind, quiet);
        return PK_OK;
    }
    /* heterogeneous: Mitsuba 3's sigma_t and albedo (each a value or a
     * volume), Mitsuba 0.6's density and albedo volumes */
    if (prop(&d, "sigma_a") || prop(&d, "sigma_s"))
        return xfail(p, PK_ERR_PARSE, mn, "a heterogeneous medium takes sigma_t (or density) and albedo, not sigma_a "
                                          "and sigma_s");
    xform mw;
    if ((st = get_to_world(p, &d, &mw, NULL))) return st;
    xvol sig, al;
    const char *sname = prop(&d, "density") ? "density" : "sigma_t";
    if ((st = medium_volume(p, &d, sname, v3s(1.0f), &sig))) return st;
    if ((st = medium_volume(p, &d, "albedo", v3s(0.75f), &al))) {
        mem_free(&p->s->alloc, sig.g.data);
        return st;
    }
    /* the grids go to *m at once, so that the caller frees them on failure */
    m->density = sig.g, m->albedo_grid = al.g;
    if (v0 && !sig.present) return xfail(p, PK_ERR_PARSE, mn, "a heterogeneous medium needs a density volume");
    m->albedo = al.grid ? v3s(1.0f) : al.value;
    m->sigma_t = v3_scale(sig.grid ? v3s(1.0f) : sig.value, scale);
    if ((st = medium_values(p, mn, m->sigma_t, m->albedo))) return st;
    if (!sig.grid && !al.grid) { /* constants everywhere: a homogeneous medium */
        m->kind = MEDIUM_HOMOGENEOUS;
        warn_unused(&d, kind, quiet);
        return PK_OK;
    }
    m->kind = MEDIUM_GRID;
    if (sig.grid && al.grid && !xform_near(&sig.to_world, &al.to_world))
        return xfail(p, PK_ERR_UNSUPPORTED, al.at, "the albedo grid must span the same box as the %s grid", sname);
    if (!sig.grid) { /* a constant extinction over the albedo grid's box */
        m->density.data = mem_alloc(&p->s->alloc, sizeof(float));
        if (!m->density.data) return ctx_nomem(p->ctx);
        m->density.data[0] = 1.0f;
        m->density.nx = m->density.ny = m->density.nz = m->density.channels = 1;
        xwarn(p, al.at, "a constant %s with an albedo grid: the medium fills the albedo grid's box only", sname);
    }
    const xform *gw = sig.grid ? &sig.to_world : &al.to_world;
    m->grid_to_world = xform_mul(&mw, gw);
    if (!xform_finite(&m->grid_to_world) || !(xform_det3(&m->grid_to_world) != 0.0))
        return xfail(p, PK_ERR_PARSE, mn, "the grid's placement (to_world) is singular or not finite");
    warn_unused(&d, kind, quiet);
    return PK_OK;
}

/* The scene medium of element n (a <medium> or a <ref> to one), made once
 * per element. */
static pk_status medium_of(xp *p, xnode *n, int32_t *index)
{
    pk_status st;
    xnode *target = n;
    if (strcmp(n->tag, "ref") == 0) {
        const char *id = attr_st(p, n, "id", &st);
        if (st) return st;
        if (!id) return xfail(p, PK_ERR_PARSE, n, "<ref> needs an id");
        target = id_find(p, id);
        if (!target || strcmp(target->tag, "medium") != 0) {
            char sid[48];
            shown(sid, sizeof sid, id);
            return xfail(p, PK_ERR_PARSE, n, "no medium has the id \"%s\"%s", sid, target ? "" : " (defined before here)");
        }
    }
    if (target->medium >= 0) {
        *index = (int32_t)target->medium;
        return PK_OK;
    }
    const char *nid = attr_st(p, target, "id", &st);
    if (st) return st;
    if (target == n && nid && n->parent && strcmp(n->parent->tag, "scene") != 0 && (st = id_add(p, nid, n)))
        return st; /* (a medium inside a shape or sensor; the scene's are added as they come) */
    medium m;
    medium_init(&m);
    if ((st = medium_convert(p, target, &m))) {
        medium_free(&p->s->alloc, &m);
        return st;
    }
    const char *id = attr_st(p, target, "id", &st);
    char name[96];
    if (id) shown(name, sizeof name, id);
    else snprintf(name, sizeof name, "medium@%s:%lu", target->file->shown, target->line);
    m.name = mem_strdup(&p->s->alloc, name);
    if (!m.name) {
        medium_free(&p->s->alloc, &m);
        return ctx_nomem(p->ctx);
    }
    uint32_t idx;
    if ((st = scene_add_medium(p->ctx, p->s, &m, &idx))) return st;
    target->medium = (int64_t)idx;
    *index = (int32_t)idx;
    return PK_OK;
}

/* ---- shapes --------------------------------------------------------------------------------- */

/* An area emitter's radiance: a colour, or a texture (a bitmap or a
 * checkerboard) into *tex with *radiance 1. */
static pk_status parse_emitter_area(xp *p, xnode *e, vec3 *radiance, tex_ref *tex)
{
    pk_status st;
    pdict d;
    if ((st = xml_props(p, e, &d))) return st;
    *radiance = v3s(1.0f);
    if ((st = get_color_tex(p, &d, "radiance", radiance, tex))) return st;
    if (!(radiance->x >= 0.0f && radiance->y >= 0.0f && radiance->z >= 0.0f))
        return xfail(p, PK_ERR_PARSE, e, "radiance must not be negative");
    static const char *const quiet[] = {"sampling_weight", NULL};
    warn_unused(&d, "emitter \"area\"", quiet);
    return PK_OK;
}

static pk_status parse_shape(xp *p, xnode *sh);

/* <shape type="shapegroup" id="...">: its shapes, read as any others, become
 * one mesh in the space their to_world give them, placed by instances. */
static pk_status parse_shapegroup(xp *p, xnode *sh)
{
    pk_status st;
    const char *id = attr_st(p, sh, "id", &st);
    if (st) return st;
    if (!id) return xfail(p, PK_ERR_PARSE, sh, "a shapegroup needs an id (instances refer to it)");
    if (!sb_begin_object(&p->sb)) return xfail(p, PK_ERR_PARSE, sh, "a shapegroup inside a shapegroup");
    if ((st = id_add(p, id, sh))) return st;
    for (xnode *c = sh->child; c; c = c->next) {
        if (strcmp(c->tag, "shape") == 0) {
            if ((st = parse_shape(p, c))) return st;
        } else {
            char tg[40];
            shown(tg, sizeof tg, c->tag);
            xwarn(p, c, "<%s> in a shapegroup is not supported (only shapes); ignored", tg);
        }
    }
    uint32_t mesh;
    if ((st = sb_end_object(&p->sb, &mesh))) return st;
    sh->mesh = mesh;
    return PK_OK;
}

/* <shape type="instance">: <ref id="..."/> to a shapegroup defined before
 * it, placed by its to_world. */
static pk_status parse_instance(xp *p, xnode *sh)
{
    pk_status st;
    if (p->sb.in_object) return xfail(p, PK_ERR_PARSE, sh, "an instance inside a shapegroup");
    const char *id = attr_st(p, sh, "id", &st);
    if (st) return st;
    if (id && (st = id_add(p, id, sh))) return st;
    pdict d;
    if ((st = xml_props(p, sh, &d))) return st;
    xform m;
    if ((st = get_to_world(p, &d, &m, NULL))) return st;
    xnode *group = NULL, *ref = NULL;
    for (xnode *c = sh->child; c; c = c->next) {
        if (strcmp(c->tag, "ref") != 0) continue;
        if (ref) {
            xwarn(p, c, "an instance takes one shapegroup; this one is ignored");
            continue;
        }
        ref = c;
        const char *rid = attr_st(p, c, "id", &st);
        if (st) return st;
        if (!rid) return xfail(p, PK_ERR_PARSE, c, "<ref> needs an id");
        group = id_find(p, rid);
        char sid[48];
        shown(sid, sizeof sid, rid);
        if (!group) return xfail(p, PK_ERR_PARSE, c, "instance: no shapegroup \"%s\" before it", sid);
        if (group->mesh < 0) return xfail(p, PK_ERR_PARSE, c, "instance: \"%s\" is not a shapegroup", sid);
    }
    if (!ref) return xfail(p, PK_ERR_PARSE, sh, "an instance needs a <ref id=\"...\"/> to a shapegroup");
    double det = xform_det3(&m);
    if (!(det != 0.0) || !isfinite(det)) return xfail(p, PK_ERR_PARSE, sh, "instance: to_world is singular");
    sb_set_transform(&p->sb, &m);
    if ((st = sb_add_instance(&p->sb, (uint32_t)group->mesh))) return st;
    warn_unused(&d, "shape \"instance\"", NULL);
    return PK_OK;
}

static pk_status parse_shape(xp *p, xnode *sh)
{
    pk_status st;
    const char *type = attr_st(p, sh, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, sh, "<shape> needs a type");
    if (strcmp(type, "shapegroup") == 0) return parse_shapegroup(p, sh);
    if (strcmp(type, "instance") == 0) return parse_instance(p, sh);
    char ty[40];
    shown(ty, sizeof ty, type);
    enum { SH_OBJ, SH_PLY, SH_RECT, SH_CUBE, SH_DISK, SH_SPHERE, SH_OTHER } kind = SH_OTHER;
    static const char *const names[] = {"obj", "ply", "rectangle", "cube", "disk", "sphere"};
    for (int i = 0; i < 6; i++)
        if (strcmp(type, names[i]) == 0) kind = (int)i;
    if (kind == SH_OTHER) {
        xwarn(p, sh, "shape \"%s\" is not supported; skipped", ty);
        return PK_OK;
    }
    const char *id = attr_st(p, sh, "id", &st);
    if (st) return st;
    if (id && (st = id_add(p, id, sh))) return st;
    pdict d;
    if ((st = xml_props(p, sh, &d))) return st;

    xform m;
    if ((st = get_to_world(p, &d, &m, NULL))) return st;
    bool flip = false;
    if ((st = get_bool(p, &d, "flip_normals", &flip))) return st;

    /* its bsdf (a nested one or a reference), its area emitter and the
     * media inside and outside it */
    xnode *bsdf = NULL, *emitter = NULL, *sides[2] = {NULL, NULL}; /* interior, exterior */
    for (xnode *c = sh->child; c; c = c->next) {
        const char *cname = NULL;
        if (strcmp(c->tag, "ref") == 0 || strcmp(c->tag, "medium") == 0) {
            cname = attr_st(p, c, "name", &st);
            if (st) return st;
        }
        const bool medium_ref = cname && strcmp(c->tag, "ref") == 0 &&
                                (strcmp(cname, "interior") == 0 || strcmp(cname, "exterior") == 0);
        if (strcmp(c->tag, "medium") == 0 || medium_ref) {
            const int side = cname && strcmp(cname, "interior") == 0 ? 0 : cname && strcmp(cname, "exterior") == 0 ? 1 : -1;
            if (side < 0) {
                xwarn(p, c, "a shape's medium needs name=\"interior\" or name=\"exterior\"; ignored");
            } else if (sides[side]) {
                xwarn(p, c, "a shape takes one %s medium; this one is ignored", cname);
            } else {
                sides[side] = c;
            }
            continue;
        }
        if (strcmp(c->tag, "bsdf") == 0 || strcmp(c->tag, "ref") == 0) {
            if (strcmp(c->tag, "ref") == 0) {
                const char *rid = attr_st(p, c, "id", &st);
                if (st) return st;
                xnode *t = rid ? id_find(p, rid) : NULL;
                if (t && strcmp(t->tag, "bsdf") != 0) {
                    if (strcmp(t->tag, "emitter") == 0 && !emitter) emitter = t;
                    else if (strcmp(t->tag, "medium") == 0)
                        xwarn(p, c, "a shape's medium needs name=\"interior\" or name=\"exterior\"; ignored");
                    else xwarn(p, c, "a reference to a <%.32s> in a shape is not supported; ignored", t->tag);
                    continue;
                }
            }
            if (bsdf) {
                xwarn(p, c, "a shape takes one bsdf; this one is ignored");
                continue;
            }
            bsdf = c;
        } else if (strcmp(c->tag, "emitter") == 0) {
            if (emitter) {
                xwarn(p, c, "a shape takes one emitter; this one is ignored");
                continue;
            }
            emitter = c;
        } else if (strcmp(c->tag, "subsurface") == 0) {
            if (first_time(p, "subsurface"))
                xwarn(p, c, "subsurface integrators are not supported (media inside a dielectric are); ignored");
        }
    }
    int32_t med[2] = {MEDIUM_INHERIT, MEDIUM_INHERIT};
    if (sides[0] || sides[1]) { /* a medium transition: a side left out is vacuum */
        for (int i = 0; i < 2; i++) {
            med[i] = MEDIUM_NONE;
            if (sides[i] && (st = medium_of(p, sides[i], &med[i]))) return st;
        }
    }
    uint32_t mat = 0;
    bool has_bsdf = bsdf != NULL;
    if (bsdf && (st = material_of(p, bsdf, &mat))) return st;
    if (!bsdf && (sides[0] || sides[1]) && p->version_major < 2) {
        /* Mitsuba 0.x: a medium transition without a bsdf is index-matched */
        int64_t found = scene_find_material(p->s, "mitsuba-index-matched");
        if (found < 0) {
            uint32_t idx;
            if ((st = scene_add_material(p->ctx, p->s, "mitsuba-index-matched", &idx))) return st;
            material_interface(&p->s->materials[idx]);
            found = idx;
        }
        mat = (uint32_t)found;
    } else if (!bsdf) { /* Mitsuba's default: diffuse, reflectance 0.5 */
        int64_t found = scene_find_material(p->s, "mitsuba-default-diffuse");
        if (found < 0) {
            uint32_t idx;
            if ((st = scene_add_material(p->ctx, p->s, "mitsuba-default-diffuse", &idx))) return st;
            material_diffuse(&p->s->materials[idx], v3s(0.5f));
            found = idx;
        }
        mat = (uint32_t)found;
    }
    if ((sides[0] || sides[1]) && (st = scene_material_with_media(p->ctx, p->s, mat, med[0], med[1], &mat)))
        return st;
    if (emitter) {
        const char *et = attr_st(p, emitter, "type", &st);
        if (st) return st;
        if (!et || strcmp(et, "area") != 0) {
            char se[40];
            shown(se, sizeof se, et ? et : "");
            xwarn(p, emitter, "emitter \"%s\" on a shape is not supported (only \"area\"); ignored", se);
        } else {
            vec3 radiance;
            tex_ref tex;
            tex_ref_init(&tex);
            if ((st = parse_emitter_area(p, emitter, &radiance, &tex))) return st;
            /* a copy of the material that also emits (one-sided, as Mitsuba's) */
            char name[96];
            snprintf(name, sizeof name, "%s+emitter@%lu", p->s->materials[mat].name, emitter->line);
            if ((st = scene_material_with_emission(p->ctx, p->s, mat, name, radiance, false, &mat))) return st;
            if (tex.kind != TEX_NONE) { /* a textured radiance (on a mix's emitting copies too) */
                material *em = &p->s->materials[mat];
                em->map_ke = tex;
                if (em->type == MAT_MIX) {
                    p->s->materials[em->mix_a].map_ke = tex;
                    p->s->materials[em->mix_b].map_ke = tex;
                }
            }
        }
    }
    /* Mitsuba orients an analytic shape's normal by the inverse transpose
     * of to_world, so a mirroring transform keeps it: the winding, which
     * such a transform reverses, is turned back. */
    bool mirror = xform_det3(&m) < 0.0;
    switch (kind) {
    case SH_OBJ: st = shape_obj(p, &d, &m, flip, has_bsdf, mat); break;
    case SH_PLY: st = shape_ply(p, &d, &m, flip, mat); break;
    case SH_RECT: st = shape_rectangle(p, &m, flip != mirror, mat); break;
    case SH_CUBE: st = shape_cube(p, &m, flip != mirror, mat); break;
    case SH_DISK: st = shape_disk(p, &m, flip != mirror, mat); break;
    case SH_SPHERE: {
        vec3 center = v3s(0.0f);
        float radius = 1.0f;
        if ((st = get_vec(p, &d, "center", &center, NULL))) return st;
        if ((st = get_float(p, &d, "radius", &radius))) return st;
        if (!(radius > 0.0f)) return xfail(p, PK_ERR_PARSE, sh, "sphere: radius must be positive");
        /* to_world * translate(center) * scale(radius) */
        xform local = xform_scale(v3s(radius));
        local.m[3] = center.x, local.m[7] = center.y, local.m[11] = center.z;
        xform full = xform_mul(&m, &local);
        /* analytic when full is a similarity (rotation, uniform scale, translation) */
        vec3 cx = v3(full.m[0], full.m[4], full.m[8]), cy = v3(full.m[1], full.m[5], full.m[9]);
        vec3 cz = v3(full.m[2], full.m[6], full.m[10]);
        float lx = v3_len(cx), ly = v3_len(cy), lz = v3_len(cz);
        float tol = 1e-4f * lx;
        bool similar = fabsf(lx - ly) <= tol && fabsf(lx - lz) <= tol && fabsf(v3_dot(cx, cy)) <= tol * lx &&
                       fabsf(v3_dot(cx, cz)) <= tol * lx && fabsf(v3_dot(cy, cz)) <= tol * lx;
        /* anisotropic roughness follows Mitsuba's dp/du (phi about the sphere's
         * own z axis), which only the mesh keeps */
        const bool aniso = material_anisotropic(&p->s->materials[mat]);
        if (similar && !flip && !p->sb.in_object && !aniso) { /* (a shapegroup's spheres are meshes) */
            sphere sp = {xform_point(&full, v3s(0.0f)), lx, mat};
            if (!v3_finite(sp.center) || !(sp.radius > 0.0f) || !isfinite(sp.radius))
                return xfail(p, PK_ERR_PARSE, sh, "sphere: the transformed sphere is not finite");
            st = scene_add_sphere(p->ctx, p->s, &sp);
        } else {
            if (!similar && first_time(p, "sphere-mesh"))
                xwarn(p, sh, "sphere with a non-uniform to_world: tessellated into %d triangles",
                      2 * XML_SPHERE_SEGMENTS * (XML_SPHERE_RINGS - 1));
            st = shape_sphere_mesh(p, &full, flip != mirror, mat);
        }
        break;
    }
    default: break;
    }
    if (st) return st;
    static const char *const quiet[] = {"flip_tex_coords", "collapse", NULL};
    char kindname[64];
    snprintf(kindname, sizeof kindname, "shape \"%s\"", ty);
    warn_unused(&d, kindname, quiet);
    return PK_OK;
}

/* ---- emitters ------------------------------------------------------------------------------------- */

/* Mitsuba 3's projector: a pinhole at the origin of to_world that projects
 * the irradiance texture along +z through a field of view (fov, fov_axis as
 * a perspective sensor's; without fov, focal_length, 50mm by default, over
 * the 36 x 24 mm diagonal). Mitsuba scales the texture by pi * scale /
 * cos^3 of the angle from the axis, so that a plane facing the projector at
 * z = 1 receives pi * scale times the texture (a white diffuse plane there
 * shows the texture times scale): a projection light of intensity
 * pi * scale with the projector's 1 / cos^3 (LIGHT_MAP_PROJECTOR). The image
 * runs as a Mitsuba camera's: u along -x, v along -y (row 0 on top). A
 * constant irradiance is a one-texel image. Texels are taken nearest, where
 * Mitsuba's bitmap filters them bilinearly. */
static pk_status parse_projector(xp *p, xnode *e, pdict *d)
{
    pk_status st;
    xform m;
    float scale = 1.0f, fov = -1.0f;
    vec3 irr = v3s(1.0f);
    tex_ref tex;
    tex_ref_init(&tex);
    if ((st = get_to_world(p, d, &m, NULL)) || (st = get_float(p, d, "scale", &scale))) return st;
    if ((st = get_color_tex(p, d, "irradiance", &irr, &tex))) return st;
    xnode *fn = prop(d, "fov"), *an = NULL, *fl = NULL;
    const char *axis = "x", *focal = NULL;
    if (fn && (st = node_float(p, fn, &fov))) return st;
    if ((st = get_string(p, d, "fov_axis", &axis, &an)) || (st = get_string(p, d, "focal_length", &focal, &fl)))
        return st;
    if (fn && focal) return xfail(p, PK_ERR_PARSE, e, "projector: give either fov or focal_length, not both");
    if (!fn) {
        double f = 50.0;
        if (focal) {
            char *end;
            f = strtod(focal, &end);
            if (end == focal || (*end && strcmp(end, "mm") != 0) || !(f > 0.0) || !isfinite(f))
                return xfail(p, PK_ERR_PARSE, fl, "projector: focal_length must be a length in mm (\"50mm\")");
        }
        fov = (float)(2.0 * atan(sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * f)) * 180.0 / (double)PK_PI);
        axis = "diagonal";
    }
    if (!(fov > 0.0f && fov < 180.0f))
        return xfail(p, PK_ERR_PARSE, fn ? fn : e, "projector: fov must be in (0, 180) degrees");
    if (!(scale >= 0.0f && isfinite(scale)))
        return xfail(p, PK_ERR_PARSE, e, "projector: scale must be finite, not negative");
    if (!v3_finite(irr) || !(v3_min_comp(irr) >= 0.0f))
        return xfail(p, PK_ERR_PARSE, e, "projector: the irradiance must be finite and not negative");
    int32_t idx = tex.kind == TEX_IMAGE ? tex.tex : -1;
    if (idx < 0) { /* a constant: one white texel, the colour in the intensity */
        const float one[3] = {1.0f, 1.0f, 1.0f};
        st = texture_add_pixels(p->ctx, p->s, "<projector: constant>", 1, 1, 3, NULL, one, false, &idx);
        if (st) return st;
    } else if (tex.s[0] != 1.0f || tex.s[1] != 1.0f) {
        xwarn(p, e, "projector: the bitmap's uscale and vscale are not used");
    }
    const tex_level *lv = &p->s->textures[idx].lv[0];
    const double aspect = (double)lv->w / (double)lv->h;
    /* the horizontal field of view, as Mitsuba's sensors compute it */
    double t = tan(0.5 * (double)fov * (double)PK_PI / 180.0);
    if (strcmp(axis, "smaller") == 0) axis = aspect > 1.0 ? "y" : "x";
    else if (strcmp(axis, "larger") == 0) axis = aspect > 1.0 ? "x" : "y";
    if (strcmp(axis, "y") == 0) t *= aspect;
    else if (strcmp(axis, "diagonal") == 0) t = t / sqrt(1.0 + 1.0 / (aspect * aspect));
    else if (strcmp(axis, "x") != 0)
        return xfail(p, PK_ERR_PARSE, an, "fov_axis must be x, y, diagonal, smaller or larger");
    if (!(t > 0.0) || !isfinite(t)) return xfail(p, PK_ERR_PARSE, e, "projector: the field of view is degenerate");
    xform inv;
    if (!xform_invert(&m, &inv)) return xfail(p, PK_ERR_PARSE, e, "projector: to_world is singular");
    float tl[9]; /* world -> the light's frame, x and y turned to the image's u and v */
    for (int r = 0; r < 3; r++)
        for (int c = 0; c < 3; c++) tl[3 * r + c] = (r < 2 ? -1.0f : 1.0f) * inv.m[4 * r + c];
    const vec3 position = xform_point(&m, v3s(0.0f));
    const vec3 intensity = v3_scale(irr, PK_PI * scale);
    if (!v3_finite(position) || !v3_finite(intensity))
        return xfail(p, PK_ERR_PARSE, e, "projector: the position or intensity is not finite");
    return scene_light_mapped(p->ctx, p->s, position, intensity, LIGHT_MAP_PROJECTOR, idx, tl, (float)t, 1.0f,
                              (float)(1.0 / aspect), -1.0f);
}

static pk_status parse_emitter(xp *p, xnode *e)
{
    pk_status st;
    const char *type = attr_st(p, e, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, e, "<emitter> needs a type");
    char ty[40];
    shown(ty, sizeof ty, type);
    char kind[64];
    snprintf(kind, sizeof kind, "emitter \"%s\"", ty);
    static const char *const quiet[] = {"sampling_weight", NULL};
    const char *id = attr_st(p, e, "id", &st);
    if (id && (st = id_add(p, id, e))) return st;
    pdict d;
    if ((st = xml_props(p, e, &d))) return st;

    if (strcmp(type, "point") == 0 || strcmp(type, "spot") == 0) {
        vec3 pos = v3s(0.0f), intensity = v3s(1.0f), axis = v3s(0.0f);
        float cos_inner = 1.0f, cos_outer = 1.0f;
        bool has_pos;
        xform m;
        if ((st = get_to_world(p, &d, &m, NULL))) return st;
        if ((st = get_vec(p, &d, "position", &pos, &has_pos))) return st;
        if ((st = get_color(p, &d, "intensity", &intensity))) return st;
        if (type[0] == 's') {
            /* Mitsuba's spot shines along +z of its to_world: full within
             * beam_width, fading linearly in the angle to nothing at
             * cutoff_angle (degrees, half-angles; beam_width defaults to
             * three quarters of the cutoff) */
            float cutoff = 20.0f, beam = -1.0f;
            if ((st = get_float(p, &d, "cutoff_angle", &cutoff))) return st;
            if ((st = get_float(p, &d, "beam_width", &beam))) return st;
            if (beam < 0.0f) beam = 0.75f * cutoff;
            if (!(cutoff > 0.0f && cutoff <= 180.0f))
                return xfail(p, PK_ERR_PARSE, e, "cutoff_angle must be in (0, 180] degrees");
            if (!(beam >= 0.0f)) return xfail(p, PK_ERR_PARSE, e, "beam_width must not be negative");
            if (beam > cutoff) beam = cutoff;
            const vec3 dir = xform_vector(&m, v3(0.0f, 0.0f, 1.0f));
            const float len = v3_len(dir);
            if (!(len > 0.0f) || !isfinite(len)) return xfail(p, PK_ERR_PARSE, e, "spot light: degenerate to_world");
            axis = v3_scale(dir, 1.0f / len);
            cos_outer = cosf(cutoff * PK_PI / 180.0f);
            cos_inner = cosf(beam * PK_PI / 180.0f);
        }
        const vec3 position = has_pos ? pos : xform_point(&m, v3s(0.0f));
        if (!v3_finite(position) || !v3_finite(intensity))
            return xfail(p, PK_ERR_PARSE, e, "point light: position and intensity must be finite");
        if (!(intensity.x >= 0.0f && intensity.y >= 0.0f && intensity.z >= 0.0f))
            return xfail(p, PK_ERR_PARSE, e, "intensity must not be negative");
        st = type[0] == 's' ? scene_light_spot(p->ctx, p->s, position, axis, cos_inner, cos_outer, SPOT_FALLOFF_ANGLE, intensity)
                            : scene_light_point(p->ctx, p->s, position, intensity);
        if (st) return st;
    } else if (strcmp(type, "projector") == 0) {
        if ((st = parse_projector(p, e, &d))) return st;
    } else if (strcmp(type, "constant") == 0) {
        vec3 r = v3s(1.0f);
        if ((st = get_color(p, &d, "radiance", &r))) return st;
        scene_env_add_radiance(p->s, r);
    } else if (strcmp(type, "envmap") == 0) {
        const char *fn = NULL;
        xnode *at;
        float scale = 1.0f;
        xform m;
        if ((st = get_string(p, &d, "filename", &fn, &at))) return st;
        if (!fn) return xfail(p, PK_ERR_PARSE, e, "envmap needs a filename");
        if ((st = get_float(p, &d, "scale", &scale))) return st;
        if ((st = get_to_world(p, &d, &m, NULL))) return st;
        if (p->s->env.map) {
            xwarn(p, e, "a second envmap is not supported; ignored");
        } else {
            /* the rotation part, columns normalised (a scale means nothing here) */
            float rot[9];
            for (int c = 0; c < 3; c++) {
                vec3 col = v3_norm_scaled(v3(m.m[c], m.m[4 + c], m.m[8 + c]));
                rot[c] = col.x, rot[3 + c] = col.y, rot[6 + c] = col.z;
            }
            scene_env_frame(p->s, rot);
            char *path = path_join(&p->s->alloc, e->file->dir, fn);
            if (!path) return ctx_nomem(p->ctx);
            /* read now, so that a bad map is reported at its element */
            pk_context scratch = io_scratch_context(p->ctx);
            st = scene_env_map(&scratch, p->s, path, scale);
            mem_free(&p->s->alloc, path);
            if (st) return xfail(p, st, e, "envmap: %s", scratch.message);
        }
        static const char *const q2[] = {"sampling_weight", "gamma", "filter_type", "cache", NULL};
        warn_unused(&d, kind, q2);
        return PK_OK;
    } else if (strcmp(type, "sun") == 0 || strcmp(type, "sky") == 0 || strcmp(type, "sunsky") == 0) {
        float turbidity = 3.0f, sun_scale, sky_scale, radius_scale = 1.0f, scale = 1.0f;
        vec3 dir = v3(0.0f, 1.0f, 0.0f), albedo = v3s(0.2f);
        bool has_dir;
        if ((st = get_float(p, &d, "turbidity", &turbidity))) return st;
        if ((st = get_float(p, &d, "scale", &scale))) return st;
        sun_scale = sky_scale = scale; /* sunsky: scale is the default of both */
        if ((st = get_float(p, &d, "sun_scale", &sun_scale))) return st;
        if ((st = get_float(p, &d, "sky_scale", &sky_scale))) return st;
        if ((st = get_color(p, &d, "albedo", &albedo))) return st;
        if ((st = get_float(p, &d, "sun_radius_scale", &radius_scale))) return st;
        if ((st = get_vec(p, &d, "sun_direction", &dir, &has_dir))) return st;
        if (!has_dir) {
            xwarn(p, e, "%s: the sun's position from date, time and place is not computed; give sun_direction "
                        "(the sun is put at 45 degrees)",
                  ty);
            dir = v3(0.0f, 0.7071068f, 0.7071068f);
        }
        if (!(v3_len2(dir) > 0.0f)) return xfail(p, PK_ERR_PARSE, e, "sun_direction must not be zero");
        dir = v3_norm_scaled(dir);
        if (!(turbidity >= 1.0f && turbidity <= 10.0f)) {
            xwarn(p, e, "turbidity %g is outside 1..10; clamped", (double)turbidity);
            turbidity = turbidity < 1.0f ? 1.0f : 10.0f;
        }
        bool sun = type[2] == 'n', sky = strcmp(type, "sky") == 0 || strcmp(type, "sunsky") == 0;
        if (strcmp(type, "sun") == 0) sun_scale = scale;
        if (strcmp(type, "sky") == 0) sky_scale = scale;
        pk_context scratch = io_scratch_context(p->ctx);
        if (sun) {
            /* sun_radius_scale widens the disc keeping its power */
            float rs = radius_scale > 0.0f ? fminf(radius_scale, 90.0f / 0.5358f) : 1.0f;
            vec3 le =
                v3_scale(spectra_mitsuba06_sun(acosf(fminf(fmaxf(dir.y, 0.0f), 1.0f)), turbidity), sun_scale / (rs * rs));
            if ((st = scene_env_sun(&scratch, p->s, dir, le, 0.5358f * rs)))
                return xfail(p, st, e, "%s: %s", ty, scratch.message);
        }
        /* the Hosek-Wilkie sky as Mitsuba 0.6 evaluates it (env.h) */
        if (sky && (st = scene_env_sky(&scratch, p->s, dir, turbidity, sky_scale, true, clamp01v(albedo))))
            return xfail(p, st, e, "%s: %s", ty, scratch.message);
        static const char *const q2[] = {"sampling_weight", "resolution", "stretch", "extend", NULL};
        warn_unused(&d, kind, q2);
        return PK_OK;
    } else if (strcmp(type, "directional") == 0 || strcmp(type, "distant") == 0) {
        vec3 dir = v3(0.0f, 0.0f, 1.0f), irr = v3s(1.0f);
        bool has_dir;
        xform m;
        bool has_m;
        if ((st = get_to_world(p, &d, &m, &has_m))) return st;
        if ((st = get_vec(p, &d, "direction", &dir, &has_dir))) return st;
        if (!has_dir && has_m) dir = xform_vector(&m, v3(0.0f, 0.0f, 1.0f));
        if ((st = get_color(p, &d, "irradiance", &irr))) return st;
        if (!(v3_len2(dir) > 0.0f)) return xfail(p, PK_ERR_PARSE, e, "direction must not be zero");
        if (!v3_finite(irr) || !(irr.x >= 0.0f && irr.y >= 0.0f && irr.z >= 0.0f))
            return xfail(p, PK_ERR_PARSE, e, "irradiance must be finite and not negative");
        if ((st = scene_light_distant(p->ctx, p->s, v3_neg(v3_norm_scaled(dir)), irr))) return st;
    } else if (strcmp(type, "area") == 0) {
        xwarn(p, e, "an area emitter belongs inside a shape; ignored");
        return PK_OK;
    } else {
        xwarn(p, e, "emitter \"%s\" is not supported; ignored", ty);
        return PK_OK;
    }
    warn_unused(&d, kind, quiet);
    return PK_OK;
}

/* ---- sensor, film, sampler, integrator ------------------------------------------------------- */

/* A film's <rfilter>: Mitsuba's filters (0.6 and 3 alike) and their
 * parameters. gaussian: stddev (0.5), radius 4 stddev; box: radius 0.5;
 * tent: radius 1; mitchell and catmullrom: B and C (1/3, 1/3 and 0, 0.5),
 * radius 2; lanczos: lobes (3), the window sinc(x / lobes) over radius
 * lobes. A radius property, where given, is taken as well. */
static pk_status parse_rfilter(xp *p, xnode *rf)
{
    pk_status st = PK_OK;
    const char *type = attr_st(p, rf, "type", &st);
    if (st) return st;
    if (!type) type = "";
    pdict d;
    if ((st = xml_props(p, rf, &d))) return st;
    pk_filter f;
    if (strcmp(type, "box") == 0) {
        pk_filter_init(&f, PK_FILTER_BOX);
    } else if (strcmp(type, "tent") == 0) {
        pk_filter_init(&f, PK_FILTER_TRIANGLE);
        f.radius_x = f.radius_y = 1.0f;
    } else if (strcmp(type, "gaussian") == 0) {
        pk_filter_init(&f, PK_FILTER_GAUSSIAN);
        if ((st = get_float(p, &d, "stddev", &f.sigma))) return st;
        if (!(f.sigma > 0.0f && f.sigma <= 0.25f * PK_FILTER_MAX_RADIUS))
            return xfail(p, PK_ERR_PARSE, rf, "rfilter gaussian: stddev %g must be in (0, %g]", (double)f.sigma,
                         0.25 * (double)PK_FILTER_MAX_RADIUS);
        f.radius_x = f.radius_y = 4.0f * f.sigma;
    } else if (strcmp(type, "mitchell") == 0 || strcmp(type, "catmullrom") == 0) {
        pk_filter_init(&f, PK_FILTER_MITCHELL);
        if (type[0] == 'c') {
            f.b = 0.0f, f.c = 0.5f;
        } else if ((st = get_float(p, &d, "b", &f.b)) || (st = get_float(p, &d, "c", &f.c))) {
            return st;
        }
        if (!(fabsf(f.b) <= 16.0f && fabsf(f.c) <= 16.0f))
            return xfail(p, PK_ERR_PARSE, rf, "rfilter mitchell: B %g and C %g must be in [-16, 16]", (double)f.b,
                         (double)f.c);
    } else if (strcmp(type, "lanczos") == 0) {
        pk_filter_init(&f, PK_FILTER_LANCZOS);
        int64_t lobes = 3;
        bool found;
        if ((st = get_int(p, &d, "lobes", &lobes, &found))) return st;
        if (lobes < 1 || lobes > (int64_t)PK_FILTER_MAX_RADIUS)
            return xfail(p, PK_ERR_PARSE, rf, "rfilter lanczos: lobes %lld must be in 1..%d", (long long)lobes,
                         (int)PK_FILTER_MAX_RADIUS);
        f.radius_x = f.radius_y = f.tau = (float)lobes;
    } else {
        props_all_read(&d);
        xwarn(p, rf, "rfilter \"%s\" is not supported; using \"gaussian\"", type);
        return PK_OK;
    }
    float r = -1.0f;
    if ((st = get_float(p, &d, "radius", &r))) return st;
    if (r != -1.0f) {
        if (!(r > 0.0f && r <= PK_FILTER_MAX_RADIUS))
            return xfail(p, PK_ERR_PARSE, rf, "rfilter %s: radius %g must be in (0, %g]", type, (double)r,
                         (double)PK_FILTER_MAX_RADIUS);
        f.radius_x = f.radius_y = r;
    }
    warn_unused(&d, "rfilter", NULL);
    return scene_render_filter(p->ctx, p->s, &f);
}

static pk_status parse_film(xp *p, xnode *f)
{
    pk_status st;
    pdict d;
    if ((st = xml_props(p, f, &d))) return st;
    int64_t w = XML_DEFAULT_WIDTH, h = XML_DEFAULT_HEIGHT;
    bool hw, hh;
    if ((st = get_int(p, &d, "width", &w, &hw))) return st;
    if ((st = get_int(p, &d, "height", &h, &hh))) return st;
    const pk_int_option *ow = pk_int_option_find("width"), *oh = pk_int_option_find("height");
    if (w < ow->min || w > ow->max || h < oh->min || h > oh->max)
        return xfail(p, (w > ow->max || h > oh->max) ? PK_ERR_LIMIT : PK_ERR_PARSE, f,
                     "film: width and height must be in %d..%d", ow->min, ow->max);
    if ((uint64_t)w * (uint64_t)h > (uint64_t)PK_MAX_IMAGE_PIXELS)
        return xfail(p, PK_ERR_LIMIT, f, "film: %dx%d is more than %u pixels", (int)w, (int)h,
                     (unsigned)PK_MAX_IMAGE_PIXELS);
    if ((st = scene_render_int(p->ctx, p->s, "width", (int)w)) || (st = scene_render_int(p->ctx, p->s, "height", (int)h)))
        return st;
    p->film_w = (int)w, p->film_h = (int)h;
    xnode *crop = prop(&d, "crop_width");
    if (crop) xwarn(p, crop, "film: crop windows are not supported; the whole image is rendered");
    prop(&d, "crop_height"), prop(&d, "crop_offset_x"), prop(&d, "crop_offset_y");
    for (xnode *c = f->child; c; c = c->next)
        if (strcmp(c->tag, "rfilter") == 0 && (st = parse_rfilter(p, c))) return st;
    static const char *const quiet[] = {"file_format", "pixel_format", "component_format", "banner", "gamma",
                                        "high_quality_edges", "attach_log", "exposure", "tonemap_method",
                                        "rfilter", "label", "key", "burn", NULL};
    warn_unused(&d, "film", quiet);
    return PK_OK;
}

static pk_status parse_sampler(xp *p, xnode *smp)
{
    pk_status st;
    pdict d;
    if ((st = xml_props(p, smp, &d))) return st;
    int64_t spp = 4;
    bool found;
    if ((st = get_int(p, &d, "sample_count", &spp, &found))) return st;
    if (found) {
        const pk_int_option *o = pk_int_option_find("spp");
        if (spp < o->min || spp > o->max) {
            int64_t c = spp < o->min ? o->min : o->max;
            xwarn(p, smp, "sample_count %lld is outside %d..%d; using %lld", (long long)spp, o->min, o->max,
                  (long long)c);
            spp = c;
        }
        if ((st = scene_render_int(p->ctx, p->s, "spp", (int)spp))) return st;
    }
    static const char *const quiet[] = {"seed", "scramble", "dimension", "jitter", NULL};
    warn_unused(&d, "sampler", quiet);
    return PK_OK;
}

static pk_status parse_sensor(xp *p, xnode *sn)
{
    pk_status st;
    const char *type = attr_st(p, sn, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, sn, "<sensor> needs a type");
    char ty[40];
    shown(ty, sizeof ty, type);
    pdict d;
    if ((st = xml_props(p, sn, &d))) return st;
    const bool thinlens = strcmp(type, "thinlens") == 0, ortho = strcmp(type, "orthographic") == 0;
    if (strcmp(type, "perspective") != 0 && !thinlens && !ortho) {
        xwarn(p, sn, "sensor \"%s\" is not supported; rendered as a perspective camera", ty);
        for (size_t i = 0; i < d.n; i++) d.e[i].used = strcmp(d.e[i].type, "transform") != 0;
    }
    xform m;
    bool has_m;
    if ((st = get_to_world(p, &d, &m, &has_m))) return st;
    float fov = XML_DEFAULT_FOV;
    const char *axis = "x";
    if (!ortho) { /* (the orthographic sensor's view is its to_world's scale) */
        xnode *fn = prop(&d, "fov");
        if (fn && (st = node_float(p, fn, &fov))) return st;
        if (fn && !(fov > 0.0f && fov < 180.0f)) return xfail(p, PK_ERR_PARSE, fn, "fov must be in (0, 180) degrees");
        if (!fn && prop(&d, "focal_length"))
            xwarn(p, sn, "focal_length is not supported; using fov %g", (double)fov);
        xnode *an;
        if ((st = get_string(p, &d, "fov_axis", &axis, &an))) return st;
        if (strcmp(axis, "x") && strcmp(axis, "y") && strcmp(axis, "diagonal") && strcmp(axis, "smaller") &&
            strcmp(axis, "larger"))
            return xfail(p, PK_ERR_PARSE, an, "fov_axis must be x, y, diagonal, smaller or larger");
    }
    snprintf(p->fov_axis, sizeof p->fov_axis, "%s", axis);
    p->fov = fov;
    p->has_fov = true;
    /* Mitsuba's thin lens: aperture_radius (required, scene units) and
     * focus_distance (the distance to the plane in focus along the view;
     * Mitsuba's default is far_clip, itself 10^4 by default) */
    float aperture = 0.0f, focus = 0.0f, far_clip = 1e4f;
    if (thinlens) {
        xnode *ap = prop(&d, "aperture_radius");
        if (!ap) return xfail(p, PK_ERR_PARSE, sn, "sensor \"thinlens\" needs aperture_radius");
        if ((st = get_float(p, &d, "aperture_radius", &aperture))) return st;
        if (!(aperture >= 0.0f && isfinite(aperture)))
            return xfail(p, PK_ERR_PARSE, ap, "aperture_radius must be a finite number, not negative");
        if ((st = get_float(p, &d, "far_clip", &far_clip))) return st;
        focus = far_clip;
        xnode *fd = prop(&d, "focus_distance");
        if ((st = get_float(p, &d, "focus_distance", &focus))) return st;
        if (!(focus > 0.0f && isfinite(focus)))
            return xfail(p, PK_ERR_PARSE, fd ? fd : sn, "focus_distance must be a finite number above 0");
    }
    /* Mitsuba's orthographic sensor sees x in [-1, 1] of its frame, scaled
     * by to_world (y follows the film's aspect): the view is twice as wide
     * as to_world's x axis is long */
    float ortho_width = 0.0f;
    if (ortho) {
        const float sx = v3_len(xform_vector(&m, v3(1.0f, 0.0f, 0.0f)));
        const float sy = v3_len(xform_vector(&m, v3(0.0f, 1.0f, 0.0f)));
        ortho_width = 2.0f * sx;
        if (!(ortho_width > 0.0f) || !isfinite(ortho_width))
            return xfail(p, PK_ERR_PARSE, sn, "the orthographic sensor's to_world gives no usable view width");
        if (fabsf(sx - sy) > 1e-4f * sx)
            xwarn(p, sn, "the orthographic sensor's to_world scales x and y differently; the view is %g wide and "
                         "its height follows the image's aspect", (double)ortho_width);
    }

    /* Mitsuba's camera looks along +z of its frame with +y up; its image x
     * runs along -x (so a right-handed frame has the image's right on the
     * right). */
    vec3 o = xform_point(&m, v3s(0.0f));
    vec3 fwd = v3_norm_scaled(xform_vector(&m, v3(0.0f, 0.0f, 1.0f)));
    vec3 up = v3_norm_scaled(xform_vector(&m, v3(0.0f, 1.0f, 0.0f)));
    vec3 right = v3_neg(xform_vector(&m, v3(1.0f, 0.0f, 0.0f)));
    if (v3_dot(v3_cross(fwd, up), right) < 0.0f)
        xwarn(p, sn, "the camera's to_world mirrors the image; rendered unmirrored");
    pk_camera cam;
    camera_look(&cam, o, v3_add(o, fwd), up);
    cam.lens_radius = aperture;
    cam.focus_distance = focus;
    if (ortho) {
        cam.projection = PK_PROJECTION_ORTHOGRAPHIC;
        cam.ortho_width = ortho_width;
    }
    if (scene_set_camera(p->s, &cam) != CAMERA_OK)
        return xfail(p, PK_ERR_PARSE, sn, "the sensor's to_world gives no usable camera (singular or not finite)");
    p->sensor = sn;

    for (xnode *c = sn->child; c; c = c->next) {
        if (strcmp(c->tag, "film") == 0) {
            if ((st = parse_film(p, c))) return st;
        } else if (strcmp(c->tag, "sampler") == 0) {
            if ((st = parse_sampler(p, c))) return st;
        } else if (strcmp(c->tag, "medium") == 0 || strcmp(c->tag, "ref") == 0) { /* the camera's medium */
            if (strcmp(c->tag, "ref") == 0) {
                const char *rid = attr_st(p, c, "id", &st);
                if (st) return st;
                const xnode *t = rid ? id_find(p, rid) : NULL;
                if (t && strcmp(t->tag, "medium") != 0) continue;
            }
            int32_t med;
            if ((st = medium_of(p, c, &med))) return st;
            scene_set_camera_medium(p->s, med);
        }
    }
    static const char *const quiet[] = {"near_clip", "far_clip", "focus_distance", "shutter_open", "shutter_close",
                                        "principal_point_offset_x", "principal_point_offset_y", NULL};
    warn_unused(&d, "sensor", quiet);
    return PK_OK;
}

/* The vertical fov of the camera from Mitsuba's fov and fov_axis, for the
 * film's aspect (the XML's film size; a size given on the command line
 * later keeps this vertical angle). */
static pk_status finish_camera(xp *p)
{
    if (!p->sensor) return PK_OK;
    int w = p->film_w ? p->film_w : XML_DEFAULT_WIDTH, h = p->film_h ? p->film_h : XML_DEFAULT_HEIGHT;
    double t = tan(0.5 * (double)p->fov * (double)PK_PI / 180.0), ty;
    const char *ax = p->fov_axis;
    if (strcmp(ax, "smaller") == 0) ax = w <= h ? "x" : "y";
    if (strcmp(ax, "larger") == 0) ax = w >= h ? "x" : "y";
    if (strcmp(ax, "x") == 0) ty = t * (double)h / (double)w;
    else if (strcmp(ax, "y") == 0) ty = t;
    else ty = t * (double)h / sqrt((double)w * w + (double)h * h);
    float fov = (float)(2.0 * atan(ty) * 180.0 / (double)PK_PI);
    pk_camera cam = p->s->camera;
    cam.fov_deg = fov;
    if (!(fov > 0.0f && fov < 180.0f) || scene_set_camera(p->s, &cam) != CAMERA_OK)
        return xfail(p, PK_ERR_PARSE, p->sensor, "the vertical fov is out of range");
    return PK_OK;
}

static pk_status parse_integrator(xp *p, xnode *in, int depth)
{
    pk_status st;
    if (depth > 4) return xfail(p, PK_ERR_LIMIT, in, "integrators nested too deep");
    const char *type = attr_st(p, in, "type", &st);
    if (st) return st;
    if (!type) return xfail(p, PK_ERR_PARSE, in, "<integrator> needs a type");
    char ty[40];
    shown(ty, sizeof ty, type);
    if (strcmp(type, "aov") == 0 || strcmp(type, "moment") == 0 || strcmp(type, "adaptive") == 0 ||
        strcmp(type, "irrcache") == 0 || strcmp(type, "multichannel") == 0) {
        for (xnode *c = in->child; c; c = c->next)
            if (strcmp(c->tag, "integrator") == 0) return parse_integrator(p, c, depth + 1);
        return PK_OK;
    }
    pdict d;
    if ((st = xml_props(p, in, &d))) return st;
    static const char *const pathlike[] = {"path", "volpath", "volpath_simple", "volpathmis", "prb", "prbvolpath",
                                           "direct_projective", "prb_projective", "path_reparam", NULL};
    bool path = false;
    for (int i = 0; pathlike[i]; i++)
        if (strcmp(type, pathlike[i]) == 0) path = true;
    static const char *const vol[] = {"volpath", "volpathmis", "volpath_simple", "prbvolpath", NULL};
    bool volumetric = false;
    for (int i = 0; vol[i]; i++)
        if (strcmp(type, vol[i]) == 0) volumetric = true;
    scene_render_integrator(p->s, volumetric ? PK_INTEGRATOR_VOLPATH : PK_INTEGRATOR_PATH);
    int64_t md = -1;
    bool found = false;
    if (strcmp(type, "direct") == 0) {
        md = 2;
        path = true;
        prop(&d, "emitter_samples"), prop(&d, "bsdf_samples"), prop(&d, "shading_samples");
    } else if ((st = get_int(p, &d, "max_depth", &md, &found))) {
        return st;
    }
    if (!path) {
        props_all_read(&d);
        char depth_text[32];
        if (md < 0) snprintf(depth_text, sizeof depth_text, "unbounded");
        else snprintf(depth_text, sizeof depth_text, "%lld", (long long)md);
        xwarn(p, in, "integrator \"%s\" is not supported; rendered with the path tracer (max_depth %s)", ty,
              depth_text);
    }
    /* Mitsuba counts path segments (1: emitters seen directly, 2: direct
     * light); Paprsek counts bounces after the first hit: one less. -1 is
     * unbounded, as deep as Paprsek goes. */
    int pd;
    if (md < 0) pd = PK_MAX_DEPTH;
    else if (md == 0) {
        xwarn(p, in, "max_depth 0 renders nothing in Mitsuba; rendering the emitters seen directly");
        pd = 0;
    } else pd = md - 1 > PK_MAX_DEPTH ? PK_MAX_DEPTH : (int)(md - 1);
    if ((st = scene_render_int(p->ctx, p->s, "max_depth", pd))) return st;
    static const char *const quiet[] = {"rr_depth", "strict_normals", "hide_emitters", "samples_per_pass",
                                        "block_size", "timeout", "luminance_samples", NULL};
    warn_unused(&d, "integrator", quiet);
    return PK_OK;
}

/* ---- the document ------------------------------------------------------------------------- */

static pk_status parse_scene(xp *p, xnode *root, int include_depth);

static pk_status parse_include(xp *p, xnode *inc, int include_depth)
{
    pk_status st;
    const char *fn = attr_st(p, inc, "filename", &st);
    if (st) return st;
    if (!fn) return xfail(p, PK_ERR_PARSE, inc, "<include> needs a filename");
    if (include_depth >= XML_MAX_INCLUDE_DEPTH)
        return xfail(p, PK_ERR_LIMIT, inc, "includes nested more than %d deep (a file that includes itself?)",
                     XML_MAX_INCLUDE_DEPTH);
    if (p->nfiles >= XML_MAX_FILES) return xfail(p, PK_ERR_LIMIT, inc, "more than %d included files", XML_MAX_FILES);
    char *full = NULL, *data = NULL, *dir = NULL;
    size_t size = 0;
    if ((st = read_relative(p, inc, fn, &full, &data, &size))) goto out;
    xml_file *f = arena_alloc(p, sizeof *f);
    dir = path_dirname(&p->ctx->alloc, full);
    if (!f || !dir) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    f->shown = arena_strdup(p, full);
    f->dir = arena_strdup(p, dir);
    if (!f->shown || !f->dir) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    p->nfiles++;
    xnode *root;
    if ((st = parse_tree(p, data, size, f, &root))) goto out;
    st = parse_scene(p, root, include_depth + 1);
out:
    mem_free(&p->ctx->alloc, data);
    mem_free(&p->ctx->alloc, dir);
    mem_free(&p->ctx->alloc, full);
    return st;
}

static pk_status parse_scene(xp *p, xnode *root, int include_depth)
{
    pk_status st;
    for (xnode *c = root->child; c; c = c->next) {
        const char *t = c->tag;
        if (strcmp(t, "default") == 0) {
            const char *nm = attr_st(p, c, "name", &st);
            if (st) return st;
            const char *v = attr_st(p, c, "value", &st);
            if (st) return st;
            if (!nm || !v) return xfail(p, PK_ERR_PARSE, c, "<default> needs name and value");
            if (param_find(p, nm, strlen(nm))) continue; /* the first definition holds */
            if (p->nparams == XML_MAX_PARAMS)
                return xfail(p, PK_ERR_LIMIT, c, "more than %d <default> parameters", XML_MAX_PARAMS);
            p->params[p->nparams].name = nm;
            p->params[p->nparams].value = v;
            p->nparams++;
        } else if (strcmp(t, "include") == 0) {
            if ((st = parse_include(p, c, include_depth))) return st;
        } else if (strcmp(t, "bsdf") == 0 || strcmp(t, "texture") == 0) {
            const char *id = attr_st(p, c, "id", &st);
            if (st) return st;
            if (id && (st = id_add(p, id, c))) return st;
        } else if (strcmp(t, "shape") == 0) {
            if ((st = parse_shape(p, c))) return st;
        } else if (strcmp(t, "emitter") == 0) {
            if ((st = parse_emitter(p, c))) return st;
        } else if (strcmp(t, "sensor") == 0 || strcmp(t, "camera") == 0) {
            if (p->sensor) {
                xwarn(p, c, "a second sensor is not supported; ignored");
                continue;
            }
            if ((st = parse_sensor(p, c))) return st;
        } else if (strcmp(t, "integrator") == 0) {
            if ((st = parse_integrator(p, c, 0))) return st;
        } else if (strcmp(t, "medium") == 0) { /* made now, so that a bad one is reported where it is */
            const char *id = attr_st(p, c, "id", &st);
            if (st) return st;
            if (id && (st = id_add(p, id, c))) return st;
            int32_t med;
            if ((st = medium_of(p, c, &med))) return st;
        } else if (strcmp(t, "phase") == 0) {
            const char *id = attr_st(p, c, "id", &st);
            if (st) return st;
            if (id && (st = id_add(p, id, c))) return st;
        } else if (strcmp(t, "ref") == 0 || strcmp(t, "null") == 0) {
            continue;
        } else {
            char tg[40];
            shown(tg, sizeof tg, t);
            char key[64];
            snprintf(key, sizeof key, "element %s", tg);
            if (first_time(p, key)) xwarn(p, c, "<%s> is not supported; ignored", tg);
        }
    }
    return PK_OK;
}

pk_status scene_xml_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                          const char *base_dir, const char *const *params, size_t nparams)
{
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "scene_xml_parse: no data");
    xp *p = mem_calloc(&ctx->alloc, 1, sizeof *p);
    if (!p) return ctx_nomem(ctx);
    p->ctx = ctx;
    p->s = s;
    sb_init(&p->sb, ctx, s);
    xml_file top = {name ? name : "scene.xml", base_dir ? base_dir : "."};
    xnode *root;
    pk_status st = PK_OK;
    /* parameters from the caller (paprsek render -D name=value) come first */
    for (size_t i = 0; i < nparams && st == PK_OK; i++) {
        const char *d = params[i], *eq = d ? strchr(d, '=') : NULL;
        char shown_d[64];
        shown(shown_d, sizeof shown_d, d ? d : "");
        if (!eq || eq == d) {
            st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "parameter '%s': expected NAME=VALUE", shown_d);
            break;
        }
        for (const char *c = d; c < eq; c++)
            if (!is_ident(*c)) {
                st = ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "parameter '%s': a name is letters, digits and _",
                               shown_d);
                break;
            }
        if (st) break;
        if (param_find(p, d, (size_t)(eq - d))) continue; /* the first one holds */
        if (p->nparams == XML_MAX_PARAMS) {
            st = ctx_error(ctx, PK_ERR_LIMIT, "more than %d parameters", XML_MAX_PARAMS);
            break;
        }
        const char *nm = arena_strndup(p, d, (size_t)(eq - d)), *v = arena_strdup(p, eq + 1);
        if (!nm || !v) {
            st = ctx_nomem(ctx);
            break;
        }
        p->params[p->nparams].name = nm;
        p->params[p->nparams].value = v;
        p->nparams++;
    }
    if (st == PK_OK) st = parse_tree(p, data ? data : "", size, &top, &root);
    if (st == PK_OK) {
        const char *version = NULL;
        for (int i = 0; i < root->nattrs; i++)
            if (strcmp(root->attrs[i].name, "version") == 0) version = root->attrs[i].value;
        if (!version) xwarn(p, root, "<scene> has no version; read as Mitsuba 3");
        p->version_major = version ? atoi(version) : 3;
        /* the film's pixel filter when it names none: Mitsuba's gaussian */
        pk_filter gauss;
        pk_filter_init(&gauss, PK_FILTER_GAUSSIAN);
        gauss.radius_x = gauss.radius_y = 4.0f * gauss.sigma;
        st = scene_render_filter(ctx, s, &gauss);
        if (st == PK_OK) st = parse_scene(p, root, 0);
    }
    if (st == PK_OK) st = finish_camera(p);
    arena_free(p);
    mem_free(&ctx->alloc, p->ids);
    mem_free(&ctx->alloc, p);
    return st;
}
