/*
 * scene_json.c - JSON scene files: camera, film and render settings, meshes
 * (OBJ files with optional transforms), materials, spheres, point lights,
 * ambient light and participating media (homogeneous and grid media, the
 * media on either side of materials, the camera's medium), parsed with cJSON
 * into a pk_scene (docs/scene-format.md, docs/media.md).
 * Errors read "file:line: json.path: what is wrong". cJSON keeps no positions,
 * so a line is found by a scan of the text that numbers values in the same
 * pre-order as the parsed tree.
 */
#include "create_light.h"
#include "create_material.h"
#include "grid_io.h"
#include "io_util.h"
#include "readers.h"
#include "scene_record.h"
#include "../math/xform.h"
#include "../options.h"
#include "../scene/camera.h"
#include "../scene/scene.h"

#include <cjson/cJSON.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#define JP_PATH_MAX 192
#define JP_WARN_MAX 32
#define JP_DEFAULT_FOV 45.0f

/* One parse. warned[] holds the index-free paths ("spheres[].colour") of the
 * unknown keys already reported, so that each is reported once. */
typedef struct jp {
    pk_context *ctx;
    pk_scene *s;
    const char *text;
    size_t size;
    const char *name;      /* file name for messages */
    const char *base_dir;  /* meshes are read relative to it; NULL = as written */
    const cJSON *root;
    size_t named_limit;    /* materials findable by name (inline ones come after) */
    size_t nwarned;        /* <= JP_WARN_MAX */
    bool warn_full;        /* the "not reported" point was passed */
    char warned[JP_WARN_MAX][JP_PATH_MAX];
} jp;

/* The record forms that `paprsek convert` writes (at the end of this file). */
static pk_status parse_material_record(jp *p, const cJSON *e, const char *path);
static pk_status parse_ply_mesh(jp *p, const cJSON *it, const char *path);
static pk_status parse_instance(jp *p, const cJSON *it, const char *path);
static pk_status place_instance(jp *p, const cJSON *it, const char *path, uint32_t mesh);
static pk_status parse_light_record(jp *p, const cJSON *it, const char *path);
static pk_status parse_environment_record(jp *p, const cJSON *it);
static pk_status parse_medium_record(jp *p, const cJSON *it, const char *path);

/* ---- positions ------------------------------------------------------------ */

static bool is_ws(char c) { return (unsigned char)c <= 32; } /* cJSON's whitespace */

static int line_at(const char *t, size_t off)
{
    int line = 1;
    for (size_t i = 0; i < off; i++)
        if (t[i] == '\n') line++;
    return line;
}

/* Pre-order number of target under node (root = 0); false when absent. */
static bool preorder_index(const cJSON *node, const cJSON *target, size_t *k)
{
    if (node == target) return true;
    (*k)++;
    for (const cJSON *c = node->child; c; c = c->next)
        if (preorder_index(c, target, k)) return true;
    return false;
}

/* Line where the k-th value (pre-order, keys not counted) of valid JSON text
 * starts; 0 when there is none. */
static int value_line(const char *t, size_t n, size_t k)
{
    int line = 1;
    size_t count = 0, i = 0;
    if (n >= 3 && memcmp(t, "\xEF\xBB\xBF", 3) == 0) i = 3;
    while (i < n) {
        char c = t[i];
        if (c == '\n') {
            line++;
            i++;
            continue;
        }
        if (is_ws(c) || c == ',' || c == ':' || c == '}' || c == ']') {
            i++;
            continue;
        }
        if (c == '"') {
            int start = line;
            size_t j = i + 1;
            while (j < n && t[j] != '"') {
                if (t[j] == '\\') j++;
                if (j < n && t[j] == '\n') line++;
                j++;
            }
            j++;
            size_t m = j;
            while (m < n && is_ws(t[m])) m++;
            i = j;
            if (m < n && t[m] == ':') continue; /* a key, not a value */
            if (count++ == k) return start;
            continue;
        }
        if (count++ == k) return line;
        if (c == '{' || c == '[') {
            i++;
            continue;
        }
        while (i < n && !is_ws(t[i]) && t[i] != ',' && t[i] != ':' && t[i] != ']' && t[i] != '}') i++;
    }
    return 0;
}

static int item_line(const jp *p, const cJSON *item)
{
    size_t k = 0;
    if (!item || !preorder_index(p->root, item, &k)) return 1;
    int line = value_line(p->text, p->size, k);
    return line > 0 ? line : 1;
}

/* ---- messages ------------------------------------------------------------- */

static pk_status jfail(jp *p, pk_status st, const cJSON *at, const char *path, const char *fmt, ...)
    PK_PRINTF(5, 6);

static pk_status jfail(jp *p, pk_status st, const cJSON *at, const char *path, const char *fmt, ...)
{
    char msg[PK_ERRMSG_MAX];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof msg, fmt, ap);
    va_end(ap);
    int line = item_line(p, at);
    if (path[0]) return ctx_error(p->ctx, st, "%s:%d: %s: %s", p->name, line, path, msg);
    return ctx_error(p->ctx, st, "%s:%d: %s", p->name, line, msg);
}

/* Copies in to out (n bytes) with control characters as '?', for messages. */
static void sanitize(char *out, size_t n, const char *in)
{
    size_t i = 0;
    for (; in[i] && i + 1 < n; i++) out[i] = ((unsigned char)in[i] < 32 || in[i] == 127) ? '?' : in[i];
    out[i] = '\0';
}

/* out = base.key (or key at the top level); control characters become '?'. */
static void path_key(char *out, const char *base, const char *key)
{
    size_t o = 0;
    for (const char *c = base; *c && o + 1 < JP_PATH_MAX; c++) out[o++] = *c;
    if (base[0] && o + 1 < JP_PATH_MAX) out[o++] = '.';
    sanitize(out + o, JP_PATH_MAX - o, key ? key : "");
}

static void path_index(char *out, const char *base, int i) { snprintf(out, JP_PATH_MAX, "%s[%d]", base, i); }

static void warn_unknown(jp *p, const cJSON *member, const char *path)
{
    char generic[JP_PATH_MAX];
    size_t o = 0;
    for (const char *c = path; *c && o + 1 < sizeof generic; c++) {
        generic[o++] = *c;
        if (*c == '[')
            while (c[1] && c[1] != ']') c++;
    }
    generic[o] = '\0';
    if (p->warn_full) return;
    for (size_t i = 0; i < p->nwarned; i++)
        if (strcmp(p->warned[i], generic) == 0) return;
    if (p->nwarned == JP_WARN_MAX) {
        /* finding a line scans the text: stop before that costs n^2 */
        p->warn_full = true;
        ctx_warn(p->ctx, "%s: more unknown keys ignored and not reported", p->name);
        return;
    }
    memcpy(p->warned[p->nwarned++], generic, o + 1);
    ctx_warn(p->ctx, "%s:%d: %s: unknown key ignored", p->name, item_line(p, member), path);
}

/* Checks that obj is an object and finds its known keys: fields[i] is the
 * member named known[i] or NULL. Unknown keys are warned about; a known key
 * given twice is an error. */
static pk_status object_fields(jp *p, const cJSON *obj, const char *path, const char *const *known,
                               size_t nknown, const cJSON **fields)
{
    if (!cJSON_IsObject(obj)) return jfail(p, PK_ERR_PARSE, obj, path, "must be an object");
    for (size_t i = 0; i < nknown; i++) fields[i] = NULL;
    for (const cJSON *m = obj->child; m; m = m->next) {
        char mp[JP_PATH_MAX];
        path_key(mp, path, m->string);
        size_t i = 0;
        while (i < nknown && (!m->string || strcmp(m->string, known[i]) != 0)) i++;
        if (i == nknown) {
            warn_unknown(p, m, mp);
            continue;
        }
        if (fields[i]) return jfail(p, PK_ERR_PARSE, m, mp, "duplicate key");
        fields[i] = m;
    }
    return PK_OK;
}

/* ---- values --------------------------------------------------------------- */

static pk_status get_float(jp *p, const cJSON *it, const char *path, float *out)
{
    if (!cJSON_IsNumber(it)) return jfail(p, PK_ERR_PARSE, it, path, "must be a number");
    float f = (float)it->valuedouble;
    if (!isfinite(f)) return jfail(p, PK_ERR_PARSE, it, path, "must be a finite number");
    *out = f;
    return PK_OK;
}

/* A texture's "clamp": true (both axes), false (repeat), "u" or "v" (that
 * axis clamps, the other repeats), as a TEX_CLAMP_* mask. */
static pk_status get_wrap(jp *p, const cJSON *it, const char *path, uint8_t *out)
{
    if (cJSON_IsBool(it)) {
        *out = cJSON_IsTrue(it) ? TEX_CLAMP : 0;
        return PK_OK;
    }
    if (cJSON_IsString(it) && (strcmp(it->valuestring, "u") == 0 || strcmp(it->valuestring, "v") == 0)) {
        *out = it->valuestring[0] == 'u' ? TEX_CLAMP_U : TEX_CLAMP_V;
        return PK_OK;
    }
    return jfail(p, PK_ERR_PARSE, it, path, "must be true, false, \"u\" or \"v\"");
}

static pk_status get_floats(jp *p, const cJSON *it, const char *path, float *out, int n)
{
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return jfail(p, PK_ERR_PARSE, it, path, "must be an array of %d numbers", n);
    int i = 0;
    for (const cJSON *e = it->child; e; e = e->next, i++) {
        if (!cJSON_IsNumber(e)) return jfail(p, PK_ERR_PARSE, it, path, "must be an array of %d numbers", n);
        out[i] = (float)e->valuedouble;
        if (!isfinite(out[i])) return jfail(p, PK_ERR_PARSE, e, path, "numbers must be finite");
    }
    return PK_OK;
}

static pk_status get_vec3(jp *p, const cJSON *it, const char *path, vec3 *out)
{
    float f[3];
    pk_status st = get_floats(p, it, path, f, 3);
    if (st == PK_OK) *out = v3(f[0], f[1], f[2]);
    return st;
}

static pk_status get_color(jp *p, const cJSON *it, const char *path, vec3 *out)
{
    pk_status st = get_vec3(p, it, path, out);
    if (st == PK_OK && (out->x < 0.0f || out->y < 0.0f || out->z < 0.0f))
        return jfail(p, PK_ERR_PARSE, it, path, "colour components must not be negative");
    return st;
}

/* An integer in lo..hi; above hi is PK_ERR_LIMIT. */
static pk_status get_int(jp *p, const cJSON *it, const char *path, int lo, int hi, int *out)
{
    if (!cJSON_IsNumber(it) || it->valuedouble != floor(it->valuedouble))
        return jfail(p, PK_ERR_PARSE, it, path, "must be an integer");
    double v = it->valuedouble;
    if (v < (double)lo || v > (double)hi)
        return jfail(p, v > (double)hi ? PK_ERR_LIMIT : PK_ERR_PARSE, it, path, "must be an integer in %d..%d",
                     lo, hi);
    *out = (int)v;
    return PK_OK;
}

static pk_status get_array(jp *p, const cJSON *it, const char *path)
{
    return cJSON_IsArray(it) ? PK_OK : jfail(p, PK_ERR_PARSE, it, path, "must be an array");
}

/* ---- textures --------------------------------------------------------------- */

enum { TX_TEXTURE, TX_CHECKER, TX_SCALE, TX_OFFSET, TX_CLAMP, TX_STRENGTH, TX_UVSET, TX_COUNT };
static const char *const tx_keys[TX_COUNT] = {"texture", "checker", "scale", "offset", "clamp", "strength", "uvset"};

/* A checker's colour: three numbers, or one for a scalar parameter. */
static pk_status get_checker_value(jp *p, const cJSON *it, const char *path, vec3 *out)
{
    if (cJSON_IsNumber(it)) {
        float f = 0.0f;
        pk_status st = get_float(p, it, path, &f);
        if (st == PK_OK && f < 0.0f) return jfail(p, PK_ERR_PARSE, it, path, "must not be negative");
        *out = v3s(f);
        return st;
    }
    return get_color(p, it, path, out);
}

/* A parameter given as a texture object: {"texture": "file.png", "scale": [su, sv],
 * "offset": [ou, ov], "clamp": false, "uvset": 0} or {"checker": {"even": c, "odd": c,
 * "scale": n}, ...}; bump maps also take "strength" (-bm). Fills *ref. An image that cannot be used is a warning:
 * ref stays without a texture and *loaded is false. colour: the image holds
 * colours (decoded from sRGB). */
static pk_status get_texture(jp *p, const cJSON *it, const char *path, bool colour, tex_ref *ref, bool *loaded)
{
    *loaded = false;
    const cJSON *f[TX_COUNT];
    pk_status st = object_fields(p, it, path, tx_keys, TX_COUNT, f);
    if (st) return st;
    tex_ref r;
    tex_ref_init(&r);
    char fp[JP_PATH_MAX];
    if (!f[TX_TEXTURE] == !f[TX_CHECKER])
        return jfail(p, PK_ERR_PARSE, it, path, "a texture needs \"texture\" (an image file) or \"checker\", one of them");
    if (f[TX_SCALE]) {
        path_key(fp, path, "scale");
        if (cJSON_IsNumber(f[TX_SCALE])) {
            if ((st = get_float(p, f[TX_SCALE], fp, &r.s[0]))) return st;
            r.s[1] = r.s[0];
        } else if ((st = get_floats(p, f[TX_SCALE], fp, r.s, 2))) {
            return st;
        }
    }
    if (f[TX_OFFSET]) {
        path_key(fp, path, "offset");
        if ((st = get_floats(p, f[TX_OFFSET], fp, r.o, 2))) return st;
    }
    if (f[TX_STRENGTH]) {
        path_key(fp, path, "strength");
        if ((st = get_float(p, f[TX_STRENGTH], fp, &r.bm))) return st;
    }
    if (f[TX_CLAMP]) {
        path_key(fp, path, "clamp");
        if ((st = get_wrap(p, f[TX_CLAMP], fp, &r.clamp))) return st;
    }
    if (f[TX_UVSET]) {
        int set = 0;
        path_key(fp, path, "uvset");
        if ((st = get_int(p, f[TX_UVSET], fp, INT32_MIN + 1, INT32_MAX, &set))) return st;
        if (set != 0 && set != 1) return jfail(p, PK_ERR_PARSE, f[TX_UVSET], fp, "must be 0 or 1 (the uv set)");
        r.uvset = (uint8_t)set;
    }
    if (f[TX_CHECKER]) {
        static const char *const ck[3] = {"even", "odd", "scale"};
        const cJSON *c[3];
        char cp[JP_PATH_MAX];
        path_key(cp, path, "checker");
        if ((st = object_fields(p, f[TX_CHECKER], cp, ck, 3, c))) return st;
        r.kind = TEX_CHECKER;
        r.even = v3s(0.8f), r.odd = v3s(0.2f), r.checker_scale = 8.0f;
        if (c[0]) {
            path_key(fp, cp, "even");
            if ((st = get_checker_value(p, c[0], fp, &r.even))) return st;
        }
        if (c[1]) {
            path_key(fp, cp, "odd");
            if ((st = get_checker_value(p, c[1], fp, &r.odd))) return st;
        }
        if (c[2]) {
            path_key(fp, cp, "scale");
            if ((st = get_float(p, c[2], fp, &r.checker_scale))) return st;
            if (!(r.checker_scale > 0.0f)) return jfail(p, PK_ERR_PARSE, c[2], fp, "must be a positive number");
        }
        *ref = r;
        *loaded = true;
        return PK_OK;
    }
    path_key(fp, path, "texture");
    if (!cJSON_IsString(f[TX_TEXTURE]) || !f[TX_TEXTURE]->valuestring[0])
        return jfail(p, PK_ERR_PARSE, f[TX_TEXTURE], fp, "must be a file name");
    const pk_allocator *a = &p->ctx->alloc;
    char *full = path_join(a, p->base_dir, f[TX_TEXTURE]->valuestring);
    if (!full) return ctx_nomem(p->ctx);
    int32_t idx;
    const bool was_ok = p->ctx->status == PK_OK;
    st = texture_load(p->ctx, p->s, full, colour, &idx);
    mem_free(a, full);
    if (st == PK_OK) {
        r.kind = TEX_IMAGE;
        r.tex = idx;
        *ref = r;
        *loaded = true;
    } else {
        char why[PK_ERRMSG_MAX], name[128];
        if (io_demote_error(p->ctx, st, was_ok, why, sizeof why)) {
            sanitize(name, sizeof name, f[TX_TEXTURE]->valuestring);
            ctx_warn(p->ctx, "%s:%d: %s: texture '%s' not used (%s); the constant value is used", p->name,
                     item_line(p, f[TX_TEXTURE]), fp, name, why);
            st = PK_OK;
        }
    }
    return st;
}

/* ---- media ------------------------------------------------------------------- */

/* A medium by name ("name"), or null (vacuum): *out is its number or
 * MEDIUM_NONE. */
static pk_status get_medium_ref(jp *p, const cJSON *it, const char *path, int32_t *out)
{
    if (cJSON_IsNull(it)) {
        *out = MEDIUM_NONE;
        return PK_OK;
    }
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return jfail(p, PK_ERR_PARSE, it, path, "must be the name of a medium of \"media\", or null (vacuum)");
    const int64_t idx = scene_find_medium(p->s, it->valuestring);
    if (idx < 0) {
        char shown[64];
        sanitize(shown, sizeof shown, it->valuestring);
        return jfail(p, PK_ERR_PARSE, it, path, "unknown medium \"%s\"", shown);
    }
    *out = (int32_t)idx;
    return PK_OK;
}

/* A medium coefficient: a number or three numbers, finite and >= 0. */
static pk_status get_coeff(jp *p, const cJSON *it, const char *path, vec3 *out)
{
    pk_status st;
    if (cJSON_IsNumber(it)) {
        float f = 0.0f;
        if ((st = get_float(p, it, path, &f))) return st;
        *out = v3s(f);
    } else if (cJSON_IsArray(it)) {
        if ((st = get_vec3(p, it, path, out))) return st;
    } else {
        return jfail(p, PK_ERR_PARSE, it, path, "must be a number or an array of 3 numbers");
    }
    if (out->x < 0.0f || out->y < 0.0f || out->z < 0.0f) return jfail(p, PK_ERR_PARSE, it, path, "must not be negative");
    return PK_OK;
}

/* An inline grid {"size": [nx, ny, nz], "channels": 1 | 3, "data": [...]}
 * (x fastest, channels innermost), allocated with the scene's allocator. */
static pk_status get_inline_grid(jp *p, const cJSON *it, const char *path, bool nonneg, medium_grid *g)
{
    enum { G_SIZE, G_CHANNELS, G_DATA, G_COUNT };
    static const char *const keys[G_COUNT] = {"size", "channels", "data"};
    const cJSON *f[G_COUNT];
    char fp[JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, keys, G_COUNT, f);
    if (st) return st;
    if (!f[G_SIZE]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"size\" ([nx, ny, nz])");
    if (!f[G_DATA]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"data\"");
    path_key(fp, path, "size");
    if (!cJSON_IsArray(f[G_SIZE]) || cJSON_GetArraySize(f[G_SIZE]) != 3)
        return jfail(p, PK_ERR_PARSE, f[G_SIZE], fp, "must be an array of 3 integers");
    int n[3], channels = 1, i = 0;
    for (const cJSON *e = f[G_SIZE]->child; e; e = e->next, i++)
        if ((st = get_int(p, e, fp, 1, 1 << 30, &n[i]))) return st;
    if (f[G_CHANNELS]) {
        path_key(fp, path, "channels");
        if ((st = get_int(p, f[G_CHANNELS], fp, 1, 3, &channels))) return st;
        if (channels == 2) return jfail(p, PK_ERR_PARSE, f[G_CHANNELS], fp, "must be 1 or 3");
    }
    const size_t voxels = (size_t)n[0] * (size_t)n[1] * (size_t)n[2];
    if (voxels > MEDIUM_MAX_VOXELS)
        return jfail(p, PK_ERR_LIMIT, f[G_SIZE], path, "%dx%dx%d voxels is over the limit of %zu", n[0], n[1], n[2],
                     (size_t)MEDIUM_MAX_VOXELS);
    path_key(fp, path, "data");
    const cJSON *data = f[G_DATA];
    if (!cJSON_IsArray(data)) return jfail(p, PK_ERR_PARSE, data, fp, "must be an array of numbers");
    const size_t want = voxels * (size_t)channels, have = (size_t)cJSON_GetArraySize(data);
    if (have != want)
        return jfail(p, PK_ERR_PARSE, data, fp, "holds %zu numbers; a %dx%dx%d grid of %d channel%s needs %zu", have,
                     n[0], n[1], n[2], channels, channels == 1 ? "" : "s", want);
    float *v = mem_alloc(&p->s->alloc, want * sizeof *v);
    if (!v) return ctx_nomem(p->ctx);
    size_t k = 0;
    for (const cJSON *e = data->child; e; e = e->next, k++) {
        if (!cJSON_IsNumber(e) || !isfinite((float)e->valuedouble) || (nonneg && e->valuedouble < 0.0)) {
            mem_free(&p->s->alloc, v);
            return jfail(p, PK_ERR_PARSE, e, fp, "value %zu must be a finite number%s", k, nonneg ? ", not negative" : "");
        }
        v[k] = (float)e->valuedouble;
    }
    g->nx = n[0], g->ny = n[1], g->nz = n[2];
    g->channels = channels;
    g->data = v;
    return PK_OK;
}

/* A grid from a file, by its extension: Mitsuba .vol, NanoVDB .nvdb,
 * OpenVDB .vdb (the float grid named gridname, NULL: the first), relative
 * to the scene's folder; *box is the box the file says it spans. */
static pk_status get_grid_file(jp *p, const cJSON *it, const char *path, const char *gridname, medium_grid *g,
                               aabb *box)
{
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return jfail(p, PK_ERR_PARSE, it, path, "must be a non-empty string (a path)");
    const char *fn = it->valuestring, *dot = strrchr(fn, '.');
    const int kind = !dot ? -1 : strcmp(dot, ".vol") == 0 ? 0 : strcmp(dot, ".nvdb") == 0 ? 1 : strcmp(dot, ".vdb") == 0 ? 2 : -1;
    if (kind < 0)
        return jfail(p, PK_ERR_UNSUPPORTED, it, path,
                     "grid files are Mitsuba .vol, NanoVDB .nvdb or OpenVDB .vdb files (by the name's ending)");
    const pk_allocator *a = &p->ctx->alloc;
    char *full = path_join(a, p->base_dir, fn);
    if (!full) return ctx_nomem(p->ctx);
    pk_context scratch = io_scratch_context(p->ctx);
    pk_status st = kind == 0   ? grid_read_vol(&scratch, &p->s->alloc, full, g, box)
                   : kind == 1 ? grid_read_nanovdb(&scratch, &p->s->alloc, full, gridname, g, box)
                               : grid_read_openvdb(&scratch, &p->s->alloc, full, gridname, g, box);
    mem_free(a, full);
    if (st) return jfail(p, st, it, path, "%s", scratch.message);
    return PK_OK;
}

enum { MD_NAME, MD_TYPE, MD_SIGMA_A, MD_SIGMA_S, MD_SIGMA_T, MD_ALBEDO, MD_SCALE, MD_G, MD_EMISSION, MD_FILE,
       MD_DENSITY, MD_ALBEDO_FILE, MD_ALBEDO_GRID, MD_EMISSION_FILE, MD_EMISSION_GRID, MD_BOUNDS, MD_TRANSFORM,
       MD_GRID, MD_COUNT };
static const char *const medium_keys[MD_COUNT] = {
    "name",  "type", "sigma_a",     "sigma_s",     "sigma_t",       "albedo",        "scale",  "g",        "emission",
    "file",  "density", "albedo_file", "albedo_grid", "emission_file", "emission_grid", "bounds", "transform", "grid"};

static pk_status parse_transform(jp *p, const cJSON *it, const char *path, xform *m);

/* One element of "media", filled into *m (the caller adds it). */
static pk_status read_medium(jp *p, const cJSON *it, const char *path, medium *m)
{
    const cJSON *f[MD_COUNT];
    char fp[MD_COUNT][JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, medium_keys, MD_COUNT, f);
    if (st) return st;
    for (int i = 0; i < MD_COUNT; i++) path_key(fp[i], path, medium_keys[i]);
    if (!f[MD_NAME]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"name\"");
    if (!cJSON_IsString(f[MD_NAME]) || !f[MD_NAME]->valuestring[0])
        return jfail(p, PK_ERR_PARSE, f[MD_NAME], fp[MD_NAME], "must be a non-empty string");
    if (!f[MD_TYPE]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"type\" (\"homogeneous\" or \"grid\")");
    const char *ty = cJSON_IsString(f[MD_TYPE]) ? f[MD_TYPE]->valuestring : "";
    const bool grid = strcmp(ty, "grid") == 0;
    if (!grid && strcmp(ty, "homogeneous") != 0)
        return jfail(p, PK_ERR_PARSE, f[MD_TYPE], fp[MD_TYPE], "must be \"homogeneous\" or \"grid\"");
    if (!grid)
        for (int k = MD_FILE; k <= MD_GRID; k++)
            if (f[k]) return jfail(p, PK_ERR_PARSE, f[k], fp[k], "belongs to a grid medium (\"type\": \"grid\")");
    medium_init(m);
    m->kind = grid ? MEDIUM_GRID : MEDIUM_HOMOGENEOUS;
    /* the coefficients: sigma_a and/or sigma_s, or sigma_t and/or albedo
     * (default: sigma_t 1, albedo 1) */
    vec3 sa = v3s(0.0f), ss = v3s(0.0f), stv = v3s(1.0f), al = v3s(1.0f);
    const bool as = f[MD_SIGMA_A] || f[MD_SIGMA_S], ta = f[MD_SIGMA_T] || f[MD_ALBEDO];
    if (as && ta) {
        const int k = f[MD_SIGMA_T] ? MD_SIGMA_T : MD_ALBEDO;
        return jfail(p, PK_ERR_PARSE, f[k], fp[k], "give \"sigma_a\" and \"sigma_s\" or \"sigma_t\" and \"albedo\", not both");
    }
    if (f[MD_SIGMA_A] && (st = get_coeff(p, f[MD_SIGMA_A], fp[MD_SIGMA_A], &sa))) return st;
    if (f[MD_SIGMA_S] && (st = get_coeff(p, f[MD_SIGMA_S], fp[MD_SIGMA_S], &ss))) return st;
    if (f[MD_SIGMA_T] && (st = get_coeff(p, f[MD_SIGMA_T], fp[MD_SIGMA_T], &stv))) return st;
    if (f[MD_ALBEDO]) {
        if ((st = get_coeff(p, f[MD_ALBEDO], fp[MD_ALBEDO], &al))) return st;
        if (al.x > 1.0f || al.y > 1.0f || al.z > 1.0f)
            return jfail(p, PK_ERR_PARSE, f[MD_ALBEDO], fp[MD_ALBEDO], "must lie in 0..1");
    }
    float scale = 1.0f;
    if (f[MD_SCALE]) {
        if ((st = get_float(p, f[MD_SCALE], fp[MD_SCALE], &scale))) return st;
        if (scale < 0.0f) return jfail(p, PK_ERR_PARSE, f[MD_SCALE], fp[MD_SCALE], "must not be negative");
    }
    if (as) {
        medium_set_coefficients(m, sa, ss, scale);
    } else {
        m->sigma_t = v3_scale(stv, scale);
        m->albedo = al;
    }
    if (!v3_finite(m->sigma_t)) return jfail(p, PK_ERR_PARSE, it, path, "the extinction times \"scale\" is not finite");
    if (f[MD_G]) {
        if ((st = get_float(p, f[MD_G], fp[MD_G], &m->g))) return st;
        if (!(m->g > -1.0f && m->g < 1.0f))
            return jfail(p, PK_ERR_PARSE, f[MD_G], fp[MD_G], "must lie strictly between -1 and 1");
    }
    if (f[MD_EMISSION] && (st = get_coeff(p, f[MD_EMISSION], fp[MD_EMISSION], &m->le))) return st;
    if (!grid) return PK_OK;

    /* the grids, each given inline or as a file */
    if (!f[MD_FILE] == !f[MD_DENSITY])
        return jfail(p, PK_ERR_PARSE, it, path, "a grid medium needs \"file\" (a .vol, .nvdb or .vdb file) or \"density\", one of them");
    aabb box = {v3s(0.0f), v3s(1.0f)};
    bool file_box = false;
    if (f[MD_FILE]) {
        if (f[MD_GRID] && (!cJSON_IsString(f[MD_GRID]) || !f[MD_GRID]->valuestring[0]))
            return jfail(p, PK_ERR_PARSE, f[MD_GRID], fp[MD_GRID], "must be a grid's name");
        if ((st = get_grid_file(p, f[MD_FILE], fp[MD_FILE], f[MD_GRID] ? f[MD_GRID]->valuestring : NULL, &m->density,
                                &box)))
            return st;
        file_box = true;
    } else if ((st = get_inline_grid(p, f[MD_DENSITY], fp[MD_DENSITY], true, &m->density))) {
        return st;
    }
    struct {
        int file, inline_, what;
        medium_grid *g;
        bool nonneg;
    } extra[2] = {{MD_ALBEDO_FILE, MD_ALBEDO_GRID, 0, &m->albedo_grid, true},
                  {MD_EMISSION_FILE, MD_EMISSION_GRID, 1, &m->emission_grid, true}};
    for (int e = 0; e < 2; e++) {
        if (f[extra[e].file] && f[extra[e].inline_])
            return jfail(p, PK_ERR_PARSE, f[extra[e].inline_], fp[extra[e].inline_], "give \"%s\" or \"%s\", not both",
                         medium_keys[extra[e].file], medium_keys[extra[e].inline_]);
        if (f[extra[e].file]) {
            aabb b2;
            if ((st = get_grid_file(p, f[extra[e].file], fp[extra[e].file], NULL, extra[e].g, &b2))) return st;
            if (file_box && memcmp(&b2, &box, sizeof box) != 0)
                return jfail(p, PK_ERR_PARSE, f[extra[e].file], fp[extra[e].file],
                             "the file's box differs from the density file's (the grids of a medium share one box)");
        } else if (f[extra[e].inline_] &&
                   (st = get_inline_grid(p, f[extra[e].inline_], fp[extra[e].inline_], extra[e].nonneg, extra[e].g))) {
            return st;
        }
    }
    if (m->emission_grid.data && !f[MD_EMISSION]) m->le = v3s(1.0f); /* the grid is the radiance */
    /* placement: the grid's unit cube onto "bounds" (or the file's box),
     * then "transform" */
    if (f[MD_BOUNDS]) {
        static const char *const bk[2] = {"min", "max"};
        const cJSON *b[2];
        char bp[JP_PATH_MAX];
        if ((st = object_fields(p, f[MD_BOUNDS], fp[MD_BOUNDS], bk, 2, b))) return st;
        if (!b[0] || !b[1]) return jfail(p, PK_ERR_PARSE, f[MD_BOUNDS], fp[MD_BOUNDS], "needs \"min\" and \"max\"");
        path_key(bp, fp[MD_BOUNDS], "min");
        if ((st = get_vec3(p, b[0], bp, &box.lo))) return st;
        path_key(bp, fp[MD_BOUNDS], "max");
        if ((st = get_vec3(p, b[1], bp, &box.hi))) return st;
        if (!(box.hi.x > box.lo.x && box.hi.y > box.lo.y && box.hi.z > box.lo.z))
            return jfail(p, PK_ERR_PARSE, b[1], bp, "must exceed \"min\" on every axis");
    }
    const xform t = xform_translate(box.lo), sc = xform_scale(v3_sub(box.hi, box.lo));
    m->grid_to_world = xform_mul(&t, &sc);
    if (f[MD_TRANSFORM]) {
        xform x;
        if ((st = parse_transform(p, f[MD_TRANSFORM], fp[MD_TRANSFORM], &x))) return st;
        m->grid_to_world = xform_mul(&x, &m->grid_to_world);
    }
    if (!xform_finite(&m->grid_to_world) || !(xform_det3(&m->grid_to_world) != 0.0))
        return jfail(p, PK_ERR_PARSE, it, path, "the grid's placement is singular or not finite");
    return PK_OK;
}

static pk_status parse_medium(jp *p, const cJSON *it, const char *path)
{
    if (cJSON_GetObjectItemCaseSensitive(it, "record")) return parse_medium_record(p, it, path);
    medium m;
    medium_init(&m);
    pk_status st = read_medium(p, it, path, &m);
    if (st) {
        medium_free(&p->s->alloc, &m);
        return st;
    }
    const char *name = cJSON_GetObjectItemCaseSensitive(it, "name")->valuestring;
    if (scene_find_medium(p->s, name) >= 0) {
        medium_free(&p->s->alloc, &m);
        char shown[64];
        sanitize(shown, sizeof shown, name);
        return jfail(p, PK_ERR_PARSE, cJSON_GetObjectItemCaseSensitive(it, "name"), path,
                     "a medium named \"%s\" is defined already", shown);
    }
    m.name = mem_strdup(&p->s->alloc, name);
    if (!m.name) {
        medium_free(&p->s->alloc, &m);
        return ctx_nomem(p->ctx);
    }
    uint32_t idx;
    return scene_add_medium(p->ctx, p->s, &m, &idx);
}

/* A material's "interior" and "exterior" (absent: the surface keeps the
 * ray's medium). */
static pk_status read_medium_sides(jp *p, const cJSON *obj, const char *path, material *m)
{
    static const char *const sides[2] = {"interior", "exterior"};
    int32_t *dst[2] = {&m->medium_in, &m->medium_out};
    char fp[JP_PATH_MAX];
    for (int i = 0; i < 2; i++) {
        const cJSON *it = cJSON_IsObject(obj) ? cJSON_GetObjectItemCaseSensitive(obj, sides[i]) : NULL;
        if (!it) continue;
        path_key(fp, path, sides[i]);
        pk_status st = get_medium_ref(p, it, fp, dst[i]);
        if (st) return st;
    }
    return PK_OK;
}

/* ---- materials ------------------------------------------------------------ */

/* What the parameter dictionary (pdict.h) asks of this reader: messages at
 * "file:line: json.path", the unknown-key warning with its once-per-path
 * rule, textures relative to the scene, nested objects. */
static pk_status pd_json_fail(void *self, const pdict *d, const pd_entry *e, long elem, pk_status st, const char *msg)
{
    jp *p = self;
    if (!e) return jfail(p, st, d->node, d->path, "%s", msg);
    if (elem == PD_AT_ENTRY) return jfail(p, st, e->node, d->path, "%s", msg);
    char fp[JP_PATH_MAX];
    path_key(fp, d->path, e->name);
    const cJSON *at = elem >= 0 ? cJSON_GetArrayItem(e->node, (int)elem) : e->node;
    return jfail(p, st, at, fp, "%s", msg);
}

static void pd_json_warn(void *self, const pdict *d, const pd_entry *e)
{
    char fp[JP_PATH_MAX];
    path_key(fp, d->path, e->name);
    warn_unknown(self, e->node, fp);
}

static pk_status pd_json_texture(void *self, const pdict *d, const pd_entry *e, bool colour, tex_ref *ref,
                                 bool *loaded)
{
    char fp[JP_PATH_MAX];
    path_key(fp, d->path, e->name);
    return get_texture(self, e->node, fp, colour, ref, loaded);
}

static pk_status pd_json_nested(void *self, const pdict *d, const pd_entry *e, pdict *sub)
{
    (void)self;
    char fp[JP_PATH_MAX];
    path_key(fp, d->path, e->name);
    return pd_from_cjson(sub, e->node, fp);
}

/* A mix's material by name: an element of a list of names, defined before. */
static pk_status pd_json_material(void *self, const pdict *d, const pd_entry *e, long elem, uint32_t *index)
{
    jp *p = self;
    char fp[JP_PATH_MAX], ep[JP_PATH_MAX];
    path_key(fp, d->path, e->name);
    snprintf(ep, sizeof ep, "%.*s[%ld]", JP_PATH_MAX - 24, fp, elem);
    const cJSON *it = cJSON_IsArray((const cJSON *)e->node) ? cJSON_GetArrayItem(e->node, (int)elem) : NULL;
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return jfail(p, PK_ERR_PARSE, it ? it : e->node, it ? ep : fp, "must be a material's name");
    const int64_t i = scene_find_material(p->s, it->valuestring);
    if (i < 0)
        return jfail(p, PK_ERR_PARSE, it, ep, "no material named \"%.60s\" before this one", it->valuestring);
    if (scene_mix_depth(p->s, (uint32_t)i) >= MATERIAL_MIX_DEPTH)
        return jfail(p, PK_ERR_LIMIT, it, ep, "mixes nested more than %d deep", MATERIAL_MIX_DEPTH);
    *index = (uint32_t)i;
    return PK_OK;
}

static const pd_source pd_json = {pd_json_fail, pd_json_warn, pd_json_texture, pd_json_nested, pd_json_material};

/* Reads a material object into *m (name not set): the creators of
 * create_material.c through the cJSON adapter, then the media on its sides.
 * with_name: "name" is known (*name_item: its member). */
static pk_status read_material(jp *p, const cJSON *obj, const char *path, bool with_name, material *m,
                               const cJSON **name_item)
{
    if (!cJSON_IsObject(obj)) return jfail(p, PK_ERR_PARSE, obj, path, "must be an object");
    pdict d;
    pd_init(&d, p->ctx, &pd_json, p, "material", false);
    pk_status st = pd_from_cjson(&d, obj, path);
    if (st == PK_OK && with_name) {
        static const char *const name_key[1] = {"name"};
        pd_declare(&d, name_key, 1);
    }
    if (st == PK_OK) st = create_material(&d, m);
    pd_free(&d);
    if (st) return st;
    if (name_item) *name_item = with_name ? cJSON_GetObjectItemCaseSensitive(obj, "name") : NULL;
    return read_medium_sides(p, obj, path, m);
}

static pk_status add_material(jp *p, const material *m, const char *name, uint32_t *index)
{
    uint32_t idx;
    pk_status st = scene_add_material(p->ctx, p->s, name, &idx);
    if (st) return st;
    material *dst = &p->s->materials[idx];
    char *owned = dst->name;
    *dst = *m;
    dst->name = owned;
    if (index) *index = idx;
    return PK_OK;
}

static pk_status parse_materials(jp *p, const cJSON *it)
{
    pk_status st;
    material m;
    char mp[JP_PATH_MAX];
    if (cJSON_IsObject(it)) {
        for (const cJSON *e = it->child; e; e = e->next) {
            path_key(mp, "materials", e->string);
            if (!e->string || !e->string[0]) return jfail(p, PK_ERR_PARSE, e, mp, "material name must not be empty");
            if ((st = read_material(p, e, mp, false, &m, NULL))) return st;
            if ((st = add_material(p, &m, e->string, NULL))) return st;
        }
        return PK_OK;
    }
    if (!cJSON_IsArray(it))
        return jfail(p, PK_ERR_PARSE, it, "materials", "must be an object (name: material) or an array");
    int i = 0;
    for (const cJSON *e = it->child; e; e = e->next, i++) {
        const cJSON *name = NULL;
        path_index(mp, "materials", i);
        if (cJSON_GetObjectItemCaseSensitive(e, "record")) {
            if ((st = parse_material_record(p, e, mp))) return st;
            continue;
        }
        if ((st = read_material(p, e, mp, true, &m, &name))) return st;
        if (!name) return jfail(p, PK_ERR_PARSE, e, mp, "missing \"name\"");
        char np[JP_PATH_MAX];
        path_key(np, mp, "name");
        if (!cJSON_IsString(name) || !name->valuestring[0])
            return jfail(p, PK_ERR_PARSE, name, np, "must be a non-empty string");
        if ((st = add_material(p, &m, name->valuestring, NULL))) return st;
    }
    return PK_OK;
}

/* ---- camera, film, render, ambient ---------------------------------------- */

static pk_status parse_camera(jp *p, const cJSON *it)
{
    enum { C_FROM, C_AT, C_UP, C_FOV, C_LENS, C_FOCUS, C_PROJ, C_OWIDTH, C_MEDIUM, C_COUNT };
    static const char *const keys[C_COUNT] = {"look_from",   "look_at",        "up",         "fov",        "lens_radius",
                                              "focus_distance", "projection", "ortho_width", "medium"};
    const cJSON *f[C_COUNT];
    pk_status st = object_fields(p, it, "camera", keys, C_COUNT, f);
    if (st) return st;
    if (!f[C_FROM]) return jfail(p, PK_ERR_PARSE, it, "camera", "missing \"look_from\"");
    if (!f[C_AT]) return jfail(p, PK_ERR_PARSE, it, "camera", "missing \"look_at\"");
    vec3 from, at, up = v3(0.0f, 1.0f, 0.0f);
    float fov = JP_DEFAULT_FOV;
    if ((st = get_vec3(p, f[C_FROM], "camera.look_from", &from))) return st;
    if ((st = get_vec3(p, f[C_AT], "camera.look_at", &at))) return st;
    if (f[C_UP] && (st = get_vec3(p, f[C_UP], "camera.up", &up))) return st;
    if (f[C_FOV] && (st = get_float(p, f[C_FOV], "camera.fov", &fov))) return st;
    pk_camera cam;
    camera_look(&cam, from, at, up);
    cam.fov_deg = fov;
    if (f[C_LENS] && (st = get_float(p, f[C_LENS], "camera.lens_radius", &cam.lens_radius))) return st;
    if (f[C_FOCUS] && (st = get_float(p, f[C_FOCUS], "camera.focus_distance", &cam.focus_distance))) return st;
    if (f[C_OWIDTH] && (st = get_float(p, f[C_OWIDTH], "camera.ortho_width", &cam.ortho_width))) return st;
    if (f[C_PROJ]) {
        const char *pr = cJSON_IsString(f[C_PROJ]) ? f[C_PROJ]->valuestring : "";
        if (strcmp(pr, "perspective") == 0)
            cam.projection = PK_PROJECTION_PERSPECTIVE;
        else if (strcmp(pr, "orthographic") == 0)
            cam.projection = PK_PROJECTION_ORTHOGRAPHIC;
        else
            return jfail(p, PK_ERR_PARSE, f[C_PROJ], "camera.projection", "must be \"perspective\" or \"orthographic\"");
    }
    /* the one camera rule (scene/camera.c), with the messages of this format */
    switch (camera_check(&cam)) {
    case CAMERA_OK: break;
    case CAMERA_NOT_FINITE: /* get_vec3 and get_float refuse non-finite numbers */
    case CAMERA_FOV:
        return jfail(p, PK_ERR_PARSE, f[C_FOV] ? f[C_FOV] : it, "camera.fov",
                     "must be between 0 and 180 degrees (exclusive)");
    case CAMERA_TOO_FAR: return jfail(p, PK_ERR_PARSE, f[C_AT], "camera.look_at", "is too far from look_from");
    case CAMERA_SAME_POINT: return jfail(p, PK_ERR_PARSE, f[C_AT], "camera.look_at", "must differ from look_from");
    case CAMERA_UP_ZERO: return jfail(p, PK_ERR_PARSE, f[C_UP], "camera.up", "must not be zero");
    case CAMERA_UP_PARALLEL:
        if (f[C_UP]) return jfail(p, PK_ERR_PARSE, f[C_UP], "camera.up", "is parallel to the view direction");
        return jfail(p, PK_ERR_PARSE, it, "camera",
                     "the default up [0, 1, 0] is parallel to the view direction; give \"up\"");
    case CAMERA_LENS:
        return jfail(p, PK_ERR_PARSE, f[C_LENS], "camera.lens_radius", "must not be negative (0: a pinhole)");
    case CAMERA_FOCUS:
        return jfail(p, PK_ERR_PARSE, f[C_FOCUS], "camera.focus_distance",
                     "must not be negative (0: the distance to look_at)");
    case CAMERA_PROJECTION: /* checked above */
    case CAMERA_ORTHO_WIDTH:
        return jfail(p, PK_ERR_PARSE, f[C_OWIDTH] ? f[C_OWIDTH] : it, "camera.ortho_width",
                     "must not be negative (0: the perspective view's width at look_at)");
    }
    if (f[C_MEDIUM]) {
        int32_t med;
        if ((st = get_medium_ref(p, f[C_MEDIUM], "camera.medium", &med))) return st;
        const cJSON *top = cJSON_GetObjectItemCaseSensitive(p->root, "medium");
        if (top && med != p->s->camera_medium)
            return jfail(p, PK_ERR_PARSE, f[C_MEDIUM], "camera.medium", "differs from the scene's \"medium\"; give one of them");
        scene_set_camera_medium(p->s, med);
    }
    scene_set_camera(p->s, &cam); /* checked above */
    return PK_OK;
}

static pk_status parse_size(jp *p, const cJSON *wi, const cJSON *hi, const cJSON *obj, const char *path)
{
    scene_render_settings *r = &p->s->render;
    char fp[JP_PATH_MAX];
    pk_status st;
    const cJSON *side[2] = {wi, hi};
    static const char *const names[2] = {"width", "height"};
    for (int i = 0; i < 2; i++) {
        if (!side[i]) continue;
        path_key(fp, path, names[i]);
        const pk_int_option *o = pk_int_option_find(names[i]);
        int v = 0;
        if ((st = get_int(p, side[i], fp, o->min, o->max, &v)) || (st = scene_render_int(p->ctx, p->s, names[i], v)))
            return st;
    }
    if ((uint64_t)r->opt.width * (uint64_t)r->opt.height > (uint64_t)PK_MAX_IMAGE_PIXELS)
        return jfail(p, PK_ERR_LIMIT, obj, path, "%dx%d is more than %u pixels", r->opt.width, r->opt.height,
                     (unsigned)PK_MAX_IMAGE_PIXELS);
    return PK_OK;
}

static pk_status parse_film(jp *p, const cJSON *it)
{
    static const char *const keys[] = {"width", "height"};
    const cJSON *f[2];
    pk_status st = object_fields(p, it, "film", keys, 2, f);
    if (st) return st;
    return parse_size(p, f[0], f[1], it, "film");
}

/* render.filter: {"type", "radius" (a number or [x, y]), "sigma", "b", "c",
 * "tau"}; what the type does not name keeps the type's default. */
static pk_status parse_filter(jp *p, const cJSON *it)
{
    enum { F_TYPE, F_RADIUS, F_SIGMA, F_B, F_C, F_TAU, F_COUNT };
    static const char *const keys[F_COUNT] = {"type", "radius", "sigma", "b", "c", "tau"};
    const char *path = "render.filter";
    const cJSON *f[F_COUNT];
    if (!cJSON_IsObject(it)) return jfail(p, PK_ERR_PARSE, it, path, "must be an object with a \"type\"");
    pk_status st = object_fields(p, it, path, keys, F_COUNT, f);
    if (st) return st;
    pk_filter_type type;
    if (!f[F_TYPE] || !cJSON_IsString(f[F_TYPE]) || pk_filter_parse(f[F_TYPE]->valuestring, &type) != PK_OK)
        return jfail(p, PK_ERR_PARSE, f[F_TYPE] ? f[F_TYPE] : it, "render.filter.type",
                     "must be one of \"box\", \"triangle\", \"gaussian\", \"mitchell\", \"blackman-harris\", "
                     "\"lanczos\"");
    pk_filter flt;
    pk_filter_init(&flt, type);
    if (f[F_RADIUS]) {
        if (cJSON_IsNumber(f[F_RADIUS])) {
            if ((st = get_float(p, f[F_RADIUS], "render.filter.radius", &flt.radius_x))) return st;
            flt.radius_y = flt.radius_x;
        } else {
            float r[2];
            if ((st = get_floats(p, f[F_RADIUS], "render.filter.radius", r, 2))) return st;
            flt.radius_x = r[0], flt.radius_y = r[1];
        }
        if (!(flt.radius_x > 0.0f && flt.radius_x <= PK_FILTER_MAX_RADIUS && flt.radius_y > 0.0f &&
              flt.radius_y <= PK_FILTER_MAX_RADIUS))
            return jfail(p, PK_ERR_PARSE, f[F_RADIUS], "render.filter.radius", "must be in (0, %g]",
                         (double)PK_FILTER_MAX_RADIUS);
    }
    /* each parameter where its type has it */
    static const struct {
        int key;
        pk_filter_type type;
        const char *path;
    } params[] = {{F_SIGMA, PK_FILTER_GAUSSIAN, "render.filter.sigma"},
                  {F_B, PK_FILTER_MITCHELL, "render.filter.b"},
                  {F_C, PK_FILTER_MITCHELL, "render.filter.c"},
                  {F_TAU, PK_FILTER_LANCZOS, "render.filter.tau"}};
    float *dst[] = {&flt.sigma, &flt.b, &flt.c, &flt.tau};
    for (size_t i = 0; i < sizeof params / sizeof params[0]; i++) {
        const cJSON *v = f[params[i].key];
        if (!v) continue;
        if (params[i].type != type)
            return jfail(p, PK_ERR_PARSE, v, params[i].path, "is not a parameter of the %s filter",
                         pk_filter_name(type));
        if ((st = get_float(p, v, params[i].path, dst[i]))) return st;
    }
    if (type == PK_FILTER_GAUSSIAN && !(flt.sigma > 0.0f))
        return jfail(p, PK_ERR_PARSE, f[F_SIGMA], "render.filter.sigma", "must be positive");
    if (type == PK_FILTER_MITCHELL && !(fabsf(flt.b) <= 16.0f && fabsf(flt.c) <= 16.0f))
        return jfail(p, PK_ERR_PARSE, f[F_B] ? f[F_B] : f[F_C], "render.filter", "b and c must be in [-16, 16]");
    if (type == PK_FILTER_LANCZOS && !(flt.tau > 0.0f && flt.tau <= 1024.0f))
        return jfail(p, PK_ERR_PARSE, f[F_TAU], "render.filter.tau", "must be in (0, 1024]");
    return scene_render_filter(p->ctx, p->s, &flt);
}

static pk_status parse_render(jp *p, const cJSON *it)
{
    enum { R_W, R_H, R_SPP, R_LS, R_DEPTH, R_THREADS, R_SEED, R_ACCEL, R_FRESNEL, R_INTEGRATOR, R_REGULARIZE, R_LIGHT_TREE, R_CLAMP, R_ENERGY, R_FILTER, R_COUNT };
    static const char *const keys[R_COUNT] = {"width",   "height", "spp",   "light_samples", "max_depth",
                                              "threads", "seed",   "accel", "fresnel",       "integrator",
                                              "regularize", "light_tree", "clamp_indirect", "energy_compensation",
                                              "filter"};
    const cJSON *f[R_COUNT];
    pk_status st = object_fields(p, it, "render", keys, R_COUNT, f);
    if (st) return st;
    /* ranges from the one option table (options.c), as the API and the CLI */
    static const int ints[] = {R_SPP, R_LS, R_DEPTH, R_THREADS, R_SEED, R_REGULARIZE, R_LIGHT_TREE};
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++) {
        const int k = ints[i];
        if (!f[k]) continue;
        char fp[JP_PATH_MAX];
        path_key(fp, "render", keys[k]);
        const pk_int_option *o = pk_int_option_find(keys[k]);
        int v = 0;
        if ((st = get_int(p, f[k], fp, o->min, o->max, &v)) || (st = scene_render_int(p->ctx, p->s, keys[k], v)))
            return st;
    }
    if (f[R_ACCEL]) {
        pk_accel_kind kind;
        if (!cJSON_IsString(f[R_ACCEL]) || pk_accel_kind_parse(f[R_ACCEL]->valuestring, &kind) != PK_OK)
            return jfail(p, PK_ERR_PARSE, f[R_ACCEL], "render.accel",
                         "must be one of \"none\", \"midpoint\", \"bvh\", \"embree\"");
        scene_render_accel(p->s, kind);
    }
    if (f[R_INTEGRATOR]) {
        pk_integrator_kind kind;
        if (!cJSON_IsString(f[R_INTEGRATOR]) || pk_integrator_parse(f[R_INTEGRATOR]->valuestring, &kind) != PK_OK)
            return jfail(p, PK_ERR_PARSE, f[R_INTEGRATOR], "render.integrator",
                         "must be \"path\", \"volpath\", \"whitted\" or \"default\"");
        scene_render_integrator(p->s, kind);
    }
    if (f[R_FRESNEL]) {
        if (!cJSON_IsBool(f[R_FRESNEL])) return jfail(p, PK_ERR_PARSE, f[R_FRESNEL], "render.fresnel", "must be true or false");
        scene_render_fresnel(p->s, cJSON_IsTrue(f[R_FRESNEL]));
    }
    if (f[R_ENERGY]) {
        if (!cJSON_IsBool(f[R_ENERGY]))
            return jfail(p, PK_ERR_PARSE, f[R_ENERGY], "render.energy_compensation", "must be true or false");
        scene_render_energy_compensation(p->s, cJSON_IsTrue(f[R_ENERGY]));
    }
    if (f[R_CLAMP]) {
        float clamp = 0.0f;
        if ((st = get_float(p, f[R_CLAMP], "render.clamp_indirect", &clamp))) return st;
        if (!(clamp >= 0.0f))
            return jfail(p, PK_ERR_PARSE, f[R_CLAMP], "render.clamp_indirect", "must be 0 (off) or more");
        if ((st = scene_render_clamp(p->ctx, p->s, clamp))) return st;
    }
    if (f[R_FILTER] && (st = parse_filter(p, f[R_FILTER]))) return st;
    return parse_size(p, f[R_W], f[R_H], it, "render");
}

/* ---- meshes ---------------------------------------------------------------- */

/* A 4x4 row-major affine transform from 16 numbers or from
 * {"translate", "scale", "rotate"} composed as T * R * S. */
static pk_status parse_transform(jp *p, const cJSON *it, const char *path, xform *m)
{
    pk_status st;
    char fp[JP_PATH_MAX];
    if (cJSON_IsArray(it)) {
        if ((st = get_floats(p, it, path, m->m, 16))) return st;
        if (!xform_is_affine(m)) return jfail(p, PK_ERR_PARSE, it, path, "the last row must be 0 0 0 1");
    } else {
        enum { T_TRANSLATE, T_SCALE, T_ROTATE, T_COUNT };
        static const char *const keys[T_COUNT] = {"translate", "scale", "rotate"};
        const cJSON *f[T_COUNT];
        if (!cJSON_IsObject(it))
            return jfail(p, PK_ERR_PARSE, it, path,
                         "must be an array of 16 numbers or an object with translate, scale, rotate");
        if ((st = object_fields(p, it, path, keys, T_COUNT, f))) return st;
        xform t = xform_identity(), r = xform_identity(), s = xform_identity();
        if (f[T_TRANSLATE]) {
            vec3 v;
            path_key(fp, path, "translate");
            if ((st = get_vec3(p, f[T_TRANSLATE], fp, &v))) return st;
            t = xform_translate(v);
        }
        if (f[T_SCALE]) {
            vec3 v = v3s(1.0f);
            path_key(fp, path, "scale");
            if (cJSON_IsNumber(f[T_SCALE])) {
                if ((st = get_float(p, f[T_SCALE], fp, &v.x))) return st;
                v.y = v.z = v.x;
            } else if (!cJSON_IsArray(f[T_SCALE])) {
                return jfail(p, PK_ERR_PARSE, f[T_SCALE], fp, "must be a number or an array of 3 numbers");
            } else if ((st = get_vec3(p, f[T_SCALE], fp, &v))) {
                return st;
            }
            if (v.x == 0.0f || v.y == 0.0f || v.z == 0.0f)
                return jfail(p, PK_ERR_PARSE, f[T_SCALE], fp, "must not be zero");
            s = xform_scale(v);
        }
        if (f[T_ROTATE]) {
            float a[4];
            path_key(fp, path, "rotate");
            if ((st = get_floats(p, f[T_ROTATE], fp, a, 4))) return st;
            vec3 ax = v3(a[1], a[2], a[3]);
            if (!(v3_len2(ax) > 0.0f) || !isfinite(v3_len2(ax)))
                return jfail(p, PK_ERR_PARSE, f[T_ROTATE], fp, "the axis must not be zero");
            r = xform_rotate(v3_norm(ax), a[0]);
        }
        /* (each product of T R S has one non-zero term, so the sums in double
         * of xform_mul give the float products these were written with) */
        xform rs = xform_mul(&r, &s);
        *m = xform_mul(&t, &rs);
    }
    double det = xform_det3(m);
    if (!(det != 0.0) || !isfinite(det)) return jfail(p, PK_ERR_PARSE, it, path, "the transform is singular");
    if (!xform_finite(m)) return jfail(p, PK_ERR_PARSE, it, path, "the transform is not finite");
    return PK_OK;
}

static pk_status parse_mesh(jp *p, const cJSON *it, const char *path)
{
    enum { M_OBJ, M_TRANSFORM, M_INSTANCES, M_COUNT };
    static const char *const keys[M_COUNT] = {"obj", "transform", "instances"};
    const cJSON *f[M_COUNT];
    char fp[JP_PATH_MAX];
    xform xf;
    if (cJSON_GetObjectItemCaseSensitive(it, "ply")) return parse_ply_mesh(p, it, path);
    if (cJSON_GetObjectItemCaseSensitive(it, "instance")) return parse_instance(p, it, path);
    pk_status st = object_fields(p, it, path, keys, M_COUNT, f);
    if (st) return st;
    if (!f[M_OBJ]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"obj\"");
    path_key(fp, path, "obj");
    if (!cJSON_IsString(f[M_OBJ]) || !f[M_OBJ]->valuestring[0])
        return jfail(p, PK_ERR_PARSE, f[M_OBJ], fp, "must be a non-empty string (a path)");
    if (f[M_TRANSFORM]) {
        char tp[JP_PATH_MAX];
        path_key(tp, path, "transform");
        if ((st = parse_transform(p, f[M_TRANSFORM], tp, &xf))) return st;
    }
    char ip[JP_PATH_MAX];
    path_key(ip, path, "instances");
    if (f[M_INSTANCES] && (st = get_array(p, f[M_INSTANCES], ip))) return st;
    pk_scene *s = p->s;
    const size_t pos0 = s->npositions, nrm0 = s->nnormals, uv0 = s->nuvs, tri0 = s->ntris;

    const pk_allocator *a = &p->ctx->alloc;
    pk_context scratch;
    char *data = NULL, *dir = NULL;
    size_t size = 0;
    char *full = path_join(a, p->base_dir, f[M_OBJ]->valuestring);
    if (!full) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    dir = path_dirname(a, full);
    if (!dir) {
        st = ctx_nomem(p->ctx);
        goto out;
    }
    /* Read through a scratch context so that the message can say where in the
     * JSON file the path came from. */
    scratch = io_scratch_context(p->ctx);
    st = file_read_all(&scratch, full, &data, &size);
    if (st) {
        jfail(p, st, f[M_OBJ], fp, "%s", scratch.message);
        goto out;
    }
    st = obj_parse(p->ctx, p->s, data, size, full, dir, f[M_TRANSFORM] ? &xf : NULL);
    if (st == PK_OK && f[M_INSTANCES]) {
        /* one mesh, placed by each transform of "instances" (after "transform") */
        uint32_t mesh;
        if ((st = scene_capture_mesh(p->ctx, s, pos0, nrm0, uv0, tri0, &mesh))) goto out;
        int i = 0;
        for (const cJSON *e = f[M_INSTANCES]->child; e && st == PK_OK; e = e->next, i++) {
            char ep[JP_PATH_MAX];
            xform x;
            snprintf(ep, sizeof ep, "%.*s[%d]", JP_PATH_MAX - 16, ip, i);
            if ((st = parse_transform(p, e, ep, &x))) break;
            scratch = io_scratch_context(p->ctx);
            if ((st = scene_add_instance(&scratch, s, mesh, &x, SCENE_MESH_MATERIAL)))
                jfail(p, st, e, ep, "%s", scratch.message);
        }
    }
out:
    mem_free(a, data);
    mem_free(a, dir);
    mem_free(a, full);
    return st;
}

/* ---- spheres and lights ---------------------------------------------------- */

/* Newest material named name among the first limit; -1 when absent. Inline
 * sphere materials come after limit and are never found by name. */
static int64_t find_material_below(const pk_scene *s, const char *name, size_t limit)
{
    int64_t newest = scene_find_material(s, name);
    if (newest < (int64_t)limit) return newest;
    /* an inline material's name ("spheres[2].material") hides a named one */
    for (size_t i = limit; i-- > 0;)
        if (strcmp(s->materials[i].name, name) == 0) return (int64_t)i;
    return -1;
}

static pk_status parse_sphere(jp *p, const cJSON *it, const char *path)
{
    enum { S_CENTER, S_RADIUS, S_MATERIAL, S_COUNT };
    static const char *const keys[S_COUNT] = {"center", "radius", "material"};
    const cJSON *f[S_COUNT];
    char fp[JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, keys, S_COUNT, f);
    if (st) return st;
    if (!f[S_CENTER]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"center\"");
    if (!f[S_RADIUS]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"radius\"");
    sphere sp = {.material = 0};
    path_key(fp, path, "center");
    if ((st = get_vec3(p, f[S_CENTER], fp, &sp.center))) return st;
    path_key(fp, path, "radius");
    const cJSON *r = f[S_RADIUS];
    sp.radius = cJSON_IsNumber(r) ? (float)r->valuedouble : 0.0f;
    if (!(sp.radius > 0.0f) || !isfinite(sp.radius))
        return jfail(p, PK_ERR_PARSE, r, fp, "must be a positive number");
    const cJSON *mi = f[S_MATERIAL];
    if (mi) {
        path_key(fp, path, "material");
        if (cJSON_IsString(mi)) {
            int64_t idx = find_material_below(p->s, mi->valuestring, p->named_limit);
            if (idx < 0) {
                char shown[64];
                sanitize(shown, sizeof shown, mi->valuestring);
                return jfail(p, PK_ERR_PARSE, mi, fp, "unknown material \"%s\"", shown);
            }
            sp.material = (uint32_t)idx;
        } else if (cJSON_IsObject(mi)) {
            material m;
            if ((st = read_material(p, mi, fp, false, &m, NULL))) return st;
            if ((st = add_material(p, &m, fp, &sp.material))) return st;
        } else {
            return jfail(p, PK_ERR_PARSE, mi, fp, "must be a material name or a material object");
        }
    }
    return scene_add_sphere(p->ctx, p->s, &sp);
}

static pk_status parse_light(jp *p, const cJSON *it, const char *path)
{
    if (!cJSON_IsObject(it)) return jfail(p, PK_ERR_PARSE, it, path, "must be an object");
    if (cJSON_GetObjectItemCaseSensitive(it, "record")) return parse_light_record(p, it, path);
    pdict d;
    pd_init(&d, p->ctx, &pd_json, p, "light", false);
    pk_status st = pd_from_cjson(&d, it, path);
    if (st == PK_OK) st = create_light(&d, p->s);
    pd_free(&d);
    return st;
}

/* Calls fn on each element of the array at the top-level key. */
static pk_status each_element(jp *p, const cJSON *arr, const char *key,
                              pk_status (*fn)(jp *, const cJSON *, const char *))
{
    pk_status st = get_array(p, arr, key);
    if (st) return st;
    char ep[JP_PATH_MAX];
    int i = 0;
    for (const cJSON *e = arr->child; e; e = e->next, i++) {
        path_index(ep, key, i);
        if ((st = fn(p, e, ep))) return st;
    }
    return PK_OK;
}

/* ---- the environment ---------------------------------------------------------- */

/* A unit direction; zero vectors refused. */
static pk_status get_direction(jp *p, const cJSON *it, const char *path, vec3 *out)
{
    pk_status st = get_vec3(p, it, path, out);
    if (st) return st;
    float len = v3_len(*out);
    if (!(len > 0.0f) || !isfinite(len)) return jfail(p, PK_ERR_PARSE, it, path, "must be a non-zero direction");
    *out = v3_scale(*out, 1.0f / len);
    return PK_OK;
}

static pk_status parse_sun(jp *p, const cJSON *it, const char *path, vec3 *to_sun)
{
    enum { U_DIRECTION, U_IRRADIANCE, U_RADIANCE, U_ANGLE, U_COUNT };
    static const char *const keys[U_COUNT] = {"direction", "irradiance", "radiance", "angle"};
    const cJSON *f[U_COUNT];
    char fp[JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, keys, U_COUNT, f);
    if (st) return st;
    if (!f[U_DIRECTION]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"direction\" (toward the sun)");
    path_key(fp, path, "direction");
    if ((st = get_direction(p, f[U_DIRECTION], fp, to_sun))) return st;
    float angle = p->s->env.sun_angle;
    if (f[U_ANGLE]) {
        path_key(fp, path, "angle");
        if ((st = get_float(p, f[U_ANGLE], fp, &angle))) return st;
        if (!(angle > 0.0f && angle <= 90.0f))
            return jfail(p, PK_ERR_PARSE, f[U_ANGLE], fp, "must be an angular diameter in (0, 90] degrees");
    }
    if (f[U_IRRADIANCE] && f[U_RADIANCE]) {
        path_key(fp, path, "radiance");
        return jfail(p, PK_ERR_PARSE, f[U_RADIANCE], fp, "give \"irradiance\" or \"radiance\", not both");
    }
    vec3 radiance = v3s(0.0f);
    if (f[U_RADIANCE]) {
        path_key(fp, path, "radiance");
        if ((st = get_color(p, f[U_RADIANCE], fp, &radiance))) return st;
    } else {
        /* irradiance on a surface facing the sun (default: 100, a bright
         * day in the units of the sky) */
        vec3 e = v3s(100.0f);
        path_key(fp, path, "irradiance");
        if (f[U_IRRADIANCE] && (st = get_color(p, f[U_IRRADIANCE], fp, &e))) return st;
        radiance = scene_sun_radiance(e, angle);
    }
    return scene_env_sun(p->ctx, p->s, *to_sun, radiance, angle);
}

static pk_status parse_sky(jp *p, const cJSON *it, bool has_sun, vec3 to_sun)
{
    enum { K_TURBIDITY, K_SCALE, K_SUN_DIRECTION, K_N };
    static const char *const sk[K_N] = {"turbidity", "scale", "sun_direction"};
    const cJSON *g[K_N];
    float turbidity = p->s->env.sky_turbidity, scale = p->s->env.sky_scale;
    pk_status st = object_fields(p, it, "environment.sky", sk, K_N, g);
    if (st) return st;
    if (g[K_TURBIDITY]) {
        if ((st = get_float(p, g[K_TURBIDITY], "environment.sky.turbidity", &turbidity))) return st;
        if (!(turbidity >= 2.0f && turbidity <= 10.0f))
            return jfail(p, PK_ERR_PARSE, g[K_TURBIDITY], "environment.sky.turbidity", "must be in 2..10");
    }
    if (g[K_SCALE]) {
        if ((st = get_float(p, g[K_SCALE], "environment.sky.scale", &scale))) return st;
        if (scale < 0.0f) return jfail(p, PK_ERR_PARSE, g[K_SCALE], "environment.sky.scale", "must not be negative");
    }
    if (g[K_SUN_DIRECTION]) {
        if (has_sun)
            return jfail(p, PK_ERR_PARSE, g[K_SUN_DIRECTION], "environment.sky.sun_direction",
                         "the sky follows environment.sun.direction; give one of them");
        if ((st = get_direction(p, g[K_SUN_DIRECTION], "environment.sky.sun_direction", &to_sun))) return st;
    } else if (!has_sun) {
        return jfail(p, PK_ERR_PARSE, it, "environment.sky",
                     "needs the sun's direction: an environment.sun or a \"sun_direction\"");
    }
    return scene_env_sky(p->ctx, p->s, to_sun, turbidity, scale, false, v3s(0.0f));
}

static pk_status parse_environment(jp *p, const cJSON *it)
{
    scene_environment *env = &p->s->env;
    scene_env_none(p->s); /* what the description below adds to */
    pk_status st;
    if (cJSON_IsString(it) && strcmp(it->valuestring, "none") == 0) return PK_OK;
    if (cJSON_GetObjectItemCaseSensitive(it, "record")) return parse_environment_record(p, it);
    vec3 radiance = v3s(0.0f);
    if (cJSON_IsArray(it) || cJSON_IsNumber(it)) {
        if ((st = get_color(p, it, "environment", &radiance))) return st;
        scene_env_add_radiance(p->s, radiance);
        return PK_OK;
    }
    enum { E_RADIANCE, E_MAP, E_SCALE, E_ROTATION, E_SUN, E_SKY, E_COUNT };
    static const char *const keys[E_COUNT] = {"radiance", "map", "scale", "rotation", "sun", "sky"};
    const cJSON *f[E_COUNT];
    if (!cJSON_IsObject(it))
        return jfail(p, PK_ERR_PARSE, it, "environment", "must be \"none\", a colour or an object");
    if ((st = object_fields(p, it, "environment", keys, E_COUNT, f))) return st;
    if (f[E_RADIANCE]) {
        if ((st = get_color(p, f[E_RADIANCE], "environment.radiance", &radiance))) return st;
        scene_env_add_radiance(p->s, radiance);
    }
    float scale = 1.0f, rot[9], deg = 0.0f;
    if (f[E_SCALE]) {
        if ((st = get_float(p, f[E_SCALE], "environment.scale", &scale))) return st;
        if (scale < 0.0f) return jfail(p, PK_ERR_PARSE, f[E_SCALE], "environment.scale", "must not be negative");
    }
    if (f[E_ROTATION]) {
        if ((st = get_float(p, f[E_ROTATION], "environment.rotation", &deg))) return st;
        scene_rotation_y(deg, rot);
        scene_env_frame(p->s, rot);
    }
    vec3 to_sun = env->sun_dir;
    if (f[E_SUN] && (st = parse_sun(p, f[E_SUN], "environment.sun", &to_sun))) return st;
    if (f[E_SKY] && (st = parse_sky(p, f[E_SKY], f[E_SUN] != NULL, to_sun))) return st;
    if (f[E_MAP]) {
        if (!cJSON_IsString(f[E_MAP]) || !f[E_MAP]->valuestring[0])
            return jfail(p, PK_ERR_PARSE, f[E_MAP], "environment.map", "must be a non-empty string (a path)");
        char *path = path_join(&p->ctx->alloc, p->base_dir, f[E_MAP]->valuestring);
        if (!path) return ctx_nomem(p->ctx);
        /* loaded now, so that a bad map is reported at its line */
        pk_context scratch = io_scratch_context(p->ctx);
        st = scene_env_map(&scratch, p->s, path, scale);
        mem_free(&p->ctx->alloc, path);
        if (st) return jfail(p, st, f[E_MAP], "environment.map", "%s", scratch.message);
    }
    return PK_OK;
}

/* ---- records (scene_record.h): what `paprsek convert` writes ----------------- */

/* Reads the plain fields of table t present in obj into dst; the keys of
 * extra are the caller's (skipped here); other keys are warned about. */
static pk_status rec_read(jp *p, const cJSON *obj, const char *path, const rec_field *t, size_t n,
                          const char *const *extra, void *dst)
{
    if (!cJSON_IsObject(obj)) return jfail(p, PK_ERR_PARSE, obj, path, "must be an object");
    char fp[JP_PATH_MAX];
    pk_status st;
    for (const cJSON *m = obj->child; m; m = m->next) {
        path_key(fp, path, m->string);
        size_t i = 0;
        while (i < n && (!m->string || strcmp(m->string, t[i].name) != 0)) i++;
        if (i == n) {
            bool known = false;
            for (const char *const *e = extra; e && *e && !known; e++) known = m->string && strcmp(m->string, *e) == 0;
            if (!known) warn_unknown(p, m, fp);
            continue;
        }
        void *at = (char *)dst + t[i].offset;
        switch (t[i].type) {
        case REC_FLOAT: st = get_float(p, m, fp, (float *)at); break;
        case REC_VEC3: st = get_vec3(p, m, fp, (vec3 *)at); break;
        case REC_F2: st = get_floats(p, m, fp, (float *)at, 2); break;
        case REC_F9: st = get_floats(p, m, fp, (float *)at, 9); break;
        case REC_F16: st = get_floats(p, m, fp, (float *)at, 16); break;
        case REC_INT: st = get_int(p, m, fp, INT32_MIN + 1, INT32_MAX, (int *)at); break;
        case REC_U8: {
            int v = 0;
            st = get_int(p, m, fp, 0, 255, &v);
            *(uint8_t *)at = (uint8_t)v;
            break;
        }
        case REC_BOOL:
            st = cJSON_IsBool(m) ? PK_OK : jfail(p, PK_ERR_PARSE, m, fp, "must be true or false");
            *(bool *)at = cJSON_IsTrue(m);
            break;
        case REC_WRAP: st = get_wrap(p, m, fp, (uint8_t *)at); break;
        default: st = PK_OK;
        }
        if (st) return st;
    }
    return PK_OK;
}

/* A raw pixel or voxel file of a record: exactly count elements of elem
 * bytes, read relative to the scene's folder into *out (owned). */
static pk_status rec_raw_file(jp *p, const cJSON *it, const char *path, size_t count, size_t elem, void **out)
{
    *out = NULL;
    if (!cJSON_IsString(it) || !it->valuestring[0])
        return jfail(p, PK_ERR_PARSE, it, path, "must be a non-empty string (a path)");
    const pk_allocator *a = &p->ctx->alloc;
    char *data;
    size_t size;
    pk_context scratch = io_scratch_context(p->ctx);
    pk_status st = io_read_relative(p->ctx, &scratch, p->base_dir, it->valuestring, NULL, &data, &size);
    if (st) return jfail(p, st, it, path, "%s", scratch.message);
    if (count > SIZE_MAX / elem || size != count * elem) {
        mem_free(a, data);
        return jfail(p, PK_ERR_PARSE, it, path, "holds %zu bytes; the record's sizes need %zu", size,
                     count <= SIZE_MAX / elem ? count * elem : SIZE_MAX);
    }
    *out = data;
    return PK_OK;
}

/* A positive size of n integers (image sides, grid sides) at key of obj,
 * each at most hi, their product *count at most max_count. */
static pk_status rec_sizes(jp *p, const cJSON *obj, const char *path, const char *key, int n, int hi,
                           size_t max_count, int *out, size_t *count)
{
    char fp[JP_PATH_MAX];
    path_key(fp, path, key);
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!cJSON_IsArray(it) || cJSON_GetArraySize(it) != n)
        return jfail(p, PK_ERR_PARSE, it ? it : obj, fp, "must be an array of %d integers", n);
    *count = 1;
    int i = 0;
    for (const cJSON *e = it->child; e; e = e->next, i++) {
        pk_status st = get_int(p, e, fp, 1, hi, &out[i]);
        if (st) return st;
        if ((size_t)out[i] > max_count / *count)
            return jfail(p, PK_ERR_LIMIT, it, fp, "more than %zu elements", max_count);
        *count *= (size_t)out[i];
    }
    return PK_OK;
}

/* A texture reference: its plain fields, and an image by path
 * ("image", "colour") or by raw level-0 pixels ("pixels": {"file", "key",
 * "size", "channels", "float", "colour"}). */
static pk_status read_texref_record(jp *p, const cJSON *it, const char *path, tex_ref *r)
{
    static const char *const extra[] = {"image", "colour", "pixels", NULL};
    tex_ref_init(r);
    pk_status st = rec_read(p, it, path, rec_texref, rec_ntexref, extra, r);
    if (st) return st;
    if (r->kind > TEX_CHECKER) return jfail(p, PK_ERR_PARSE, it, path, "kind must be 0 (none), 1 (image) or 2 (checker)");
    if (r->uvset > 1) return jfail(p, PK_ERR_PARSE, it, path, "uvset must be 0 or 1");
    if (r->kind != TEX_IMAGE) return PK_OK;
    char fp[JP_PATH_MAX];
    const cJSON *img = cJSON_GetObjectItemCaseSensitive(it, "image");
    const cJSON *px = cJSON_GetObjectItemCaseSensitive(it, "pixels");
    bool colour = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(it, "colour"));
    if (img) {
        path_key(fp, path, "image");
        if (!cJSON_IsString(img) || !img->valuestring[0])
            return jfail(p, PK_ERR_PARSE, img, fp, "must be a non-empty string (a path)");
        char *full = path_join(&p->ctx->alloc, p->base_dir, img->valuestring);
        if (!full) return ctx_nomem(p->ctx);
        pk_context scratch = io_scratch_context(p->ctx);
        st = texture_load(&scratch, p->s, full, colour, &r->tex);
        mem_free(&p->ctx->alloc, full);
        if (st) return jfail(p, st, img, fp, "%s", scratch.message);
        return PK_OK;
    }
    path_key(fp, path, "pixels");
    if (!cJSON_IsObject(px)) return jfail(p, PK_ERR_PARSE, px ? px : it, fp, "an image map needs \"image\" or \"pixels\"");
    const cJSON *key = cJSON_GetObjectItemCaseSensitive(px, "key");
    const cJSON *fl = cJSON_GetObjectItemCaseSensitive(px, "float");
    colour = cJSON_IsTrue(cJSON_GetObjectItemCaseSensitive(px, "colour"));
    if (!cJSON_IsString(key)) return jfail(p, PK_ERR_PARSE, px, fp, "missing \"key\" (a string)");
    if ((r->tex = texture_find(p->s, key->valuestring, colour)) >= 0) return PK_OK;
    int wh[2], nc = 0;
    size_t count;
    if ((st = rec_sizes(p, px, fp, "size", 2, PK_MAX_TEXTURE_SIDE, PK_MAX_TEXTURE_PIXELS, wh, &count))) return st;
    char cp[JP_PATH_MAX];
    path_key(cp, fp, "channels");
    const cJSON *ch = cJSON_GetObjectItemCaseSensitive(px, "channels");
    if ((st = get_int(p, ch ? ch : px, cp, 1, 4, &nc))) return st;
    const bool isf = cJSON_IsTrue(fl);
    void *data;
    char filep[JP_PATH_MAX];
    path_key(filep, fp, "file");
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(px, "file");
    if ((st = rec_raw_file(p, file ? file : px, filep, count * (size_t)nc, isf ? sizeof(float) : 1, &data))) return st;
    pk_context scratch = io_scratch_context(p->ctx);
    st = texture_add_pixels(&scratch, p->s, key->valuestring, wh[0], wh[1], nc, isf ? NULL : (const uint8_t *)data,
                            isf ? (const float *)data : NULL, colour, &r->tex);
    mem_free(&p->ctx->alloc, data);
    if (st) return jfail(p, st, px, fp, "%s", scratch.message);
    return PK_OK;
}

/* {"name": ..., "record": {...}} in "materials" (array form): a material as
 * the scene holds it (convert writes these). */
static pk_status parse_material_record(jp *p, const cJSON *e, const char *path)
{
    static const char *const outer[] = {"name", "record"};
    const cJSON *f[2];
    pk_status st = object_fields(p, e, path, outer, 2, f);
    if (st) return st;
    char fp[JP_PATH_MAX];
    path_key(fp, path, "name");
    if (!cJSON_IsString(f[0]) || !f[0]->valuestring[0])
        return jfail(p, PK_ERR_PARSE, f[0] ? f[0] : e, fp, "must be a non-empty string");
    path_key(fp, path, "record");
    /* the record's keys read below: the maps and the media */
    const char *extra[MATERIAL_NMAPS + 3];
    for (int k = 0; k < MATERIAL_NMAPS; k++) extra[k] = material_map_names[k];
    extra[MATERIAL_NMAPS] = "interior", extra[MATERIAL_NMAPS + 1] = "exterior", extra[MATERIAL_NMAPS + 2] = NULL;
    material m;
    material_init(&m);
    if ((st = rec_read(p, f[1], fp, rec_material, rec_nmaterial, extra, &m))) return st;
    if (m.type < MAT_MTL || m.type > MAT_LAST)
        return jfail(p, PK_ERR_PARSE, f[1], fp, "type must be in %d..%d", (int)MAT_MTL, (int)MAT_LAST);
    if (m.type == MAT_MIX && (m.mix_a < 0 || m.mix_b < 0 || (size_t)m.mix_a >= p->s->nmaterials ||
                              (size_t)m.mix_b >= p->s->nmaterials))
        return jfail(p, PK_ERR_PARSE, f[1], fp, "mix_a and mix_b must be numbers of materials before this one");
    if (m.illum < 0 || m.illum > 10) return jfail(p, PK_ERR_PARSE, f[1], fp, "illum must be in 0..10");
    if (m.type == MAT_COATED &&
        (!(m.layer.thickness > 0.0f) || !(m.layer.g > -1.0f && m.layer.g < 1.0f) || m.layer.maxdepth < 1 ||
         m.layer.nsamples < 1 || (m.coat_base != MATERIAL_BASE_DIFFUSE && m.coat_base != MATERIAL_BASE_CONDUCTOR)))
        return jfail(p, PK_ERR_PARSE, f[1], fp,
                     "a coated material needs coat_base 0 or 1, coat_thickness > 0, coat_g in (-1, 1), "
                     "coat_maxdepth and coat_nsamples >= 1");
    for (int k = 0; k < MATERIAL_NMAPS; k++) {
        const cJSON *it = cJSON_GetObjectItemCaseSensitive(f[1], material_map_names[k]);
        if (!it) continue;
        char mp[JP_PATH_MAX];
        path_key(mp, fp, material_map_names[k]);
        if ((st = read_texref_record(p, it, mp, material_map(&m, k)))) return st;
    }
    if ((st = read_medium_sides(p, f[1], fp, &m))) return st;
    return add_material(p, &m, f[0]->valuestring, NULL);
}

/* One PLY file of a "ply" mesh: its vertices and triangles added to the
 * scene, each face's "material" an index of mats (nmat names). */
static pk_status load_ply_file(jp *p, const cJSON *file, const char *fp, const uint32_t *mats, size_t nmat)
{
    if (!cJSON_IsString(file) || !file->valuestring[0])
        return jfail(p, PK_ERR_PARSE, file, fp, "must be a non-empty string (a path)");
    pk_scene *s = p->s;
    ply_mesh m;
    pk_context scratch = io_scratch_context(p->ctx);
    pk_status st = ply_read_relative(p->ctx, &scratch, p->base_dir, file->valuestring, &m);
    if (st) {
        jfail(p, st, file, fp, "%s", scratch.message);
        goto out;
    }
    const size_t pos0 = s->npositions, nrm0 = s->nnormals, uv0 = s->nuvs;
    for (size_t v = 0; v < m.nvertices && st == PK_OK; v++) {
        st = scene_add_position(p->ctx, s, m.positions[v]);
        if (st == PK_OK && m.normals) st = scene_add_normal(p->ctx, s, m.normals[v]);
        if (st == PK_OK && m.uvs) st = scene_add_uv(p->ctx, s, (uv2){m.uvs[2 * v], m.uvs[2 * v + 1]});
    }
    for (size_t v = 0; m.colors && v < m.nvertices && st == PK_OK; v++) {
        const float *c = m.colors + 4 * v;
        st = scene_set_color(p->ctx, s, pos0 + v, (rgba){c[0], c[1], c[2], c[3]});
    }
    for (size_t v = 0; m.tangents && v < m.nvertices && st == PK_OK; v++) {
        const float *c = m.tangents + 4 * v;
        st = scene_set_tangent(p->ctx, s, pos0 + v, (vtangent){{c[0], c[1], c[2]}, c[3]});
    }
    for (size_t v = 0; m.uvs1 && v < m.nvertices && st == PK_OK; v++)
        st = scene_set_uv1(p->ctx, s, pos0 + v, (uv2){m.uvs1[2 * v], m.uvs1[2 * v + 1]});
    for (size_t t = 0; t < m.ntriangles && st == PK_OK; t++) {
        triangle tri;
        tri.material = 0;
        if (m.face_material) {
            if (m.face_material[t] >= nmat) {
                st = jfail(p, PK_ERR_PARSE, file, fp, "triangle %zu: material %u is not an index of \"materials\"", t,
                           m.face_material[t]);
                break;
            }
            tri.material = mats[m.face_material[t]];
        }
        for (int j = 0; j < 3; j++) {
            const uint32_t vi = m.indices[3 * t + (size_t)j];
            tri.v[j] = (uint32_t)(pos0 + vi);
            tri.n[j] = m.normals ? (int32_t)(nrm0 + vi) : -1;
            tri.t[j] = m.uvs ? (int32_t)(uv0 + vi) : -1;
        }
        st = scene_add_triangle(p->ctx, s, &tri);
    }
out:
    ply_mesh_free(p->ctx, &m);
    return st;
}

/* {"ply": FILE or [FILE, ...], "materials": [names], "instances": [...]}:
 * PLY meshes (the files in order) whose faces' "material" property indexes
 * "materials" (default: material 0); corners take the file's normals and
 * uvs when it has them. Without "instances" the triangles are in world
 * space; with it they are one object-space mesh, placed by each element
 * {"transform": T, "material": NAME} (material: all its triangles'; absent:
 * their own), and the mesh can be placed again by {"instance": ...}. */
static pk_status parse_ply_mesh(jp *p, const cJSON *it, const char *path)
{
    enum { P_PLY, P_MATERIALS, P_INSTANCES, P_COUNT };
    static const char *const keys[P_COUNT] = {"ply", "materials", "instances"};
    const cJSON *f[P_COUNT];
    char fp[JP_PATH_MAX], mp[JP_PATH_MAX], ip[JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, keys, P_COUNT, f);
    if (st) return st;
    pk_scene *s = p->s;
    const pk_allocator *a = &p->ctx->alloc;
    size_t nmat = 0;
    uint32_t *mats = NULL;
    path_key(mp, path, "materials");
    path_key(ip, path, "instances");
    if (f[P_INSTANCES] && (st = get_array(p, f[P_INSTANCES], ip))) return st;
    if (f[P_MATERIALS]) {
        if ((st = get_array(p, f[P_MATERIALS], mp))) return st;
        nmat = (size_t)cJSON_GetArraySize(f[P_MATERIALS]);
        mats = mem_calloc(a, nmat ? nmat : 1, sizeof *mats);
        if (!mats) return ctx_nomem(p->ctx);
        size_t i = 0;
        for (const cJSON *e = f[P_MATERIALS]->child; e; e = e->next, i++) {
            const int64_t idx = cJSON_IsString(e) ? scene_find_material(s, e->valuestring) : -1;
            if (idx < 0) {
                mem_free(a, mats);
                return jfail(p, PK_ERR_PARSE, e, mp, "element %zu is not the name of a material", i);
            }
            mats[i] = (uint32_t)idx;
        }
    }
    const size_t pos0 = s->npositions, nrm0 = s->nnormals, uv0 = s->nuvs, tri0 = s->ntris;
    path_key(fp, path, "ply");
    if (cJSON_IsArray(f[P_PLY])) {
        int i = 0;
        for (const cJSON *e = f[P_PLY]->child; e && st == PK_OK; e = e->next, i++) {
            char ep[JP_PATH_MAX];
            snprintf(ep, sizeof ep, "%.*s[%d]", JP_PATH_MAX - 16, fp, i);
            st = load_ply_file(p, e, ep, mats, nmat);
        }
    } else {
        st = load_ply_file(p, f[P_PLY], fp, mats, nmat);
    }
    mem_free(a, mats);
    if (st || !f[P_INSTANCES]) return st;
    uint32_t mesh;
    if ((st = scene_capture_mesh(p->ctx, s, pos0, nrm0, uv0, tri0, &mesh))) return st;
    int i = 0;
    for (const cJSON *e = f[P_INSTANCES]->child; e && st == PK_OK; e = e->next, i++) {
        char ep[JP_PATH_MAX];
        snprintf(ep, sizeof ep, "%.*s[%d]", JP_PATH_MAX - 16, ip, i);
        st = place_instance(p, e, ep, mesh);
    }
    return st;
}

/* {"transform": T, "material": NAME}: mesh placed once (material: for all
 * its triangles; absent: their own). */
static pk_status place_instance(jp *p, const cJSON *it, const char *path, uint32_t mesh)
{
    enum { I_TRANSFORM, I_MATERIAL, I_MESH, I_COUNT };
    static const char *const keys[I_COUNT] = {"transform", "material", "mesh"};
    const cJSON *f[I_COUNT];
    char fp[JP_PATH_MAX];
    pk_status st = object_fields(p, it, path, keys, I_COUNT, f);
    if (st) return st;
    path_key(fp, path, "transform");
    if (!f[I_TRANSFORM]) return jfail(p, PK_ERR_PARSE, it, path, "missing \"transform\"");
    xform x;
    if ((st = parse_transform(p, f[I_TRANSFORM], fp, &x))) return st;
    uint32_t mat = SCENE_MESH_MATERIAL;
    if (f[I_MATERIAL]) {
        path_key(fp, path, "material");
        const int64_t idx = cJSON_IsString(f[I_MATERIAL]) ? scene_find_material(p->s, f[I_MATERIAL]->valuestring) : -1;
        if (idx < 0) return jfail(p, PK_ERR_PARSE, f[I_MATERIAL], fp, "must be the name of a material");
        mat = (uint32_t)idx;
    }
    pk_context scratch = io_scratch_context(p->ctx);
    if ((st = scene_add_instance(&scratch, p->s, mesh, &x, mat))) return jfail(p, st, it, path, "%s", scratch.message);
    return PK_OK;
}

/* {"instance": {"mesh": K, "transform": T, "material": NAME}} in "meshes":
 * the scene's mesh K (the K-th mesh with "instances" of this file, from 0)
 * placed once more. */
static pk_status parse_instance(jp *p, const cJSON *it, const char *path)
{
    static const char *const outer[] = {"instance"};
    const cJSON *f[1];
    pk_status st = object_fields(p, it, path, outer, 1, f);
    if (st) return st;
    char fp[JP_PATH_MAX], mp[JP_PATH_MAX];
    path_key(fp, path, "instance");
    const cJSON *mi = cJSON_IsObject(f[0]) ? cJSON_GetObjectItemCaseSensitive(f[0], "mesh") : NULL;
    path_key(mp, fp, "mesh");
    if (!mi) return jfail(p, PK_ERR_PARSE, f[0], fp, "missing \"mesh\"");
    int k = 0;
    if ((st = get_int(p, mi, mp, 0, INT32_MAX, &k))) return st;
    if ((size_t)k >= p->s->nmeshes) return jfail(p, PK_ERR_PARSE, mi, mp, "no mesh %d (%zu so far)", k, p->s->nmeshes);
    return place_instance(p, f[0], fp, (uint32_t)k);
}

/* {"record": {...}} in "lights": a light as the scene holds it. */
static pk_status parse_light_record(jp *p, const cJSON *it, const char *path)
{
    static const char *const outer[] = {"record"};
    const cJSON *f[1];
    pk_status st = object_fields(p, it, path, outer, 1, f);
    if (st) return st;
    char fp[JP_PATH_MAX];
    path_key(fp, path, "record");
    point_light l;
    memset(&l, 0, sizeof l);
    static const char *const extra[] = {"map", NULL};
    if ((st = rec_read(p, f[0], fp, rec_light, rec_nlight, extra, &l))) return st;
    if (l.map_kind != LIGHT_MAP_NONE) { /* an image-shaped point light: its image, then the constructor's checks */
        const cJSON *mj = cJSON_GetObjectItemCaseSensitive(f[0], "map");
        char mp[JP_PATH_MAX];
        path_key(mp, fp, "map");
        tex_ref r;
        tex_ref_init(&r);
        if (!mj) return jfail(p, PK_ERR_PARSE, f[0], fp, "map_kind %d needs a \"map\"", l.map_kind);
        if ((st = read_texref_record(p, mj, mp, &r))) return st;
        if (r.kind != TEX_IMAGE) return jfail(p, PK_ERR_PARSE, mj, mp, "must be an image");
        if (l.intensity.x < 0.0f || l.intensity.y < 0.0f || l.intensity.z < 0.0f)
            return jfail(p, PK_ERR_PARSE, f[0], fp, "intensity must not be negative");
        return scene_light_mapped(p->ctx, p->s, l.position, l.intensity, l.map_kind, r.tex, l.to_light, l.proj_tan,
                                  l.proj_sx, l.proj_sy, -1.0f);
    }
    if (l.spot_falloff < SPOT_FALLOFF_SMOOTHSTEP || l.spot_falloff > SPOT_FALLOFF_SQUARED)
        return jfail(p, PK_ERR_PARSE, f[0], fp, "spot_falloff must be 0, 1 or 2");
    if (l.intensity.x < 0.0f || l.intensity.y < 0.0f || l.intensity.z < 0.0f)
        return jfail(p, PK_ERR_PARSE, f[0], fp, "intensity must not be negative");
    const bool spot = l.spot_dir.x != 0.0f || l.spot_dir.y != 0.0f || l.spot_dir.z != 0.0f;
    if ((l.distant || spot) && !(fabsf(v3_len2(l.distant ? l.position : l.spot_dir) - 1.0f) < 1e-3f))
        return jfail(p, PK_ERR_PARSE, f[0], fp, "%s must be a unit vector", l.distant ? "position" : "spot_dir");
    if (spot && !(l.cos_outer >= -1.0f && l.cos_outer <= l.cos_inner && l.cos_inner <= 1.0f))
        return jfail(p, PK_ERR_PARSE, f[0], fp, "cos_outer <= cos_inner must lie in [-1, 1]");
    if (l.distant) return scene_light_distant(p->ctx, p->s, l.position, l.intensity);
    if (spot)
        return scene_light_spot(p->ctx, p->s, l.position, l.spot_dir, l.cos_inner, l.cos_outer, l.spot_falloff,
                                l.intensity);
    return scene_light_point(p->ctx, p->s, l.position, l.intensity);
}

/* {"record": {...}} as "environment": the surroundings as the scene holds
 * them, the map as raw linear RGB floats ("map": {"file", "size"}), a
 * portal as its four corners ("portal": 12 numbers; absent: none). */
static pk_status parse_environment_record(jp *p, const cJSON *it)
{
    static const char *const outer[] = {"record"};
    static const char *const extra[] = {"map", "portal", NULL};
    const cJSON *f[1];
    scene_environment *env = &p->s->env;
    pk_status st = object_fields(p, it, "environment", outer, 1, f);
    if (st) return st;
    if ((st = rec_read(p, f[0], "environment.record", rec_env, rec_nenv, extra, env))) return st;
    if (!(env->sun_angle > 0.0f && env->sun_angle <= 90.0f) || env->map_scale < 0.0f || env->sky_scale < 0.0f ||
        env->radiance.x < 0.0f || env->radiance.y < 0.0f || env->radiance.z < 0.0f || env->sun_radiance.x < 0.0f ||
        env->sun_radiance.y < 0.0f || env->sun_radiance.z < 0.0f)
        return jfail(p, PK_ERR_PARSE, f[0], "environment.record",
                     "sun_angle must be in (0, 90], scales and radiances not negative");
    const cJSON *portal = cJSON_GetObjectItemCaseSensitive(f[0], "portal");
    if (portal) {
        float c[12];
        if ((st = get_floats(p, portal, "environment.record.portal", c, 12))) return st;
        for (int k = 0; k < 4; k++) env->portal[k] = v3(c[3 * k], c[3 * k + 1], c[3 * k + 2]);
        if (!io_portal_is_rectangle(env->portal))
            return jfail(p, PK_ERR_PARSE, portal, "environment.record.portal", "must be four corners of a rectangle");
        env->has_portal = true;
    }
    const cJSON *map = cJSON_GetObjectItemCaseSensitive(f[0], "map");
    if (!map) return PK_OK;
    int wh[2];
    size_t count;
    if (!cJSON_IsObject(map)) return jfail(p, PK_ERR_PARSE, map, "environment.record.map", "must be an object");
    if ((st = rec_sizes(p, map, "environment.record.map", "size", 2, PK_MAX_TEXTURE_SIDE, PK_MAX_TEXTURE_PIXELS, wh,
                        &count)))
        return st;
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(map, "file");
    void *data;
    if ((st = rec_raw_file(p, file ? file : map, "environment.record.map.file", 3 * count, sizeof(float), &data)))
        return st;
    env->map = path_join(&p->ctx->alloc, p->base_dir, file->valuestring);
    if (!env->map) {
        mem_free(&p->ctx->alloc, data);
        return ctx_nomem(p->ctx);
    }
    env->map_rgb = data;
    env->map_w = wh[0], env->map_h = wh[1];
    return PK_OK;
}

/* A grid of a medium record: {"file", "size": [nx, ny, nz], "channels"}. */
static pk_status rec_grid(jp *p, const cJSON *obj, const char *path, const char *key, medium_grid *g)
{
    const cJSON *it = cJSON_GetObjectItemCaseSensitive(obj, key);
    if (!it) return PK_OK;
    char fp[JP_PATH_MAX], cp[JP_PATH_MAX];
    path_key(fp, path, key);
    if (!cJSON_IsObject(it)) return jfail(p, PK_ERR_PARSE, it, fp, "must be an object");
    int n[3], ch = 1;
    size_t count;
    pk_status st = rec_sizes(p, it, fp, "size", 3, INT32_MAX, MEDIUM_MAX_VOXELS, n, &count);
    if (st) return st;
    path_key(cp, fp, "channels");
    const cJSON *c = cJSON_GetObjectItemCaseSensitive(it, "channels");
    if ((st = get_int(p, c ? c : it, cp, 1, 3, &ch))) return st;
    if (ch == 2) return jfail(p, PK_ERR_PARSE, c, cp, "must be 1 or 3");
    path_key(cp, fp, "file");
    const cJSON *file = cJSON_GetObjectItemCaseSensitive(it, "file");
    void *data;
    if ((st = rec_raw_file(p, file ? file : it, cp, count * (size_t)ch, sizeof(float), &data))) return st;
    g->nx = n[0], g->ny = n[1], g->nz = n[2], g->channels = ch;
    g->data = data;
    return PK_OK;
}

/* {"name": ..., "record": {...}} in "media": a medium as the scene holds it. */
static pk_status parse_medium_record(jp *p, const cJSON *it, const char *path)
{
    static const char *const outer[] = {"name", "record"};
    static const char *const extra[] = {"density", "albedo_grid", "emission_grid", NULL};
    const cJSON *f[2];
    pk_status st = object_fields(p, it, path, outer, 2, f);
    if (st) return st;
    char fp[JP_PATH_MAX];
    path_key(fp, path, "name");
    if (!cJSON_IsString(f[0]) || !f[0]->valuestring[0])
        return jfail(p, PK_ERR_PARSE, f[0] ? f[0] : it, fp, "must be a non-empty string");
    if (scene_find_medium(p->s, f[0]->valuestring) >= 0)
        return jfail(p, PK_ERR_PARSE, f[0], fp, "a medium of this name is defined already");
    path_key(fp, path, "record");
    medium m;
    medium_init(&m);
    if ((st = rec_read(p, f[1], fp, rec_medium, rec_nmedium, extra, &m)) ||
        (st = rec_grid(p, f[1], fp, "density", &m.density)) ||
        (st = rec_grid(p, f[1], fp, "albedo_grid", &m.albedo_grid)) ||
        (st = rec_grid(p, f[1], fp, "emission_grid", &m.emission_grid)) ||
        (m.kind != MEDIUM_HOMOGENEOUS && m.kind != MEDIUM_GRID &&
         (st = jfail(p, PK_ERR_PARSE, f[1], fp, "kind must be 0 (homogeneous) or 1 (grid)")))) {
        medium_free(&p->s->alloc, &m);
        return st;
    }
    m.name = mem_strdup(&p->s->alloc, f[0]->valuestring);
    if (!m.name) {
        medium_free(&p->s->alloc, &m);
        return ctx_nomem(p->ctx);
    }
    uint32_t idx;
    return scene_add_medium(p->ctx, p->s, &m, &idx);
}

/* ---- the document ---------------------------------------------------------- */

static pk_status syntax_error(jp *p, const char *end)
{
    size_t first = 0, last = p->size;
    while (first < p->size && is_ws(p->text[first])) first++;
    if (first == p->size)
        return ctx_error(p->ctx, PK_ERR_PARSE, "%s:1: empty document (expected a JSON object)", p->name);
    while (last > 0 && is_ws(p->text[last - 1])) last--;
    /* cJSON points at the last byte when the text ends too early, and
     * sometimes just past the offending token: then back up to it. */
    size_t off = end && end >= p->text && end <= p->text + p->size ? (size_t)(end - p->text) : 0;
    if (off >= last)
        return ctx_error(p->ctx, PK_ERR_PARSE, "%s:%d: invalid JSON: unexpected end of file", p->name,
                         line_at(p->text, last - 1));
    while (off > first && is_ws(p->text[off])) off--;
    char near[24];
    size_t n = 0;
    while (n + 1 < sizeof near && off + n < p->size && p->text[off + n] >= 32 && p->text[off + n] < 127) {
        near[n] = p->text[off + n];
        n++;
    }
    near[n] = '\0';
    return ctx_error(p->ctx, PK_ERR_PARSE, "%s:%d: invalid JSON near '%s'", p->name, line_at(p->text, off), near);
}

pk_status scene_json_parse(pk_context *ctx, pk_scene *s, const char *data, size_t size, const char *name,
                           const char *base_dir)
{
    enum { K_MATERIALS, K_CAMERA, K_FILM, K_RENDER, K_AMBIENT, K_MESHES, K_SPHERES, K_LIGHTS, K_ENV, K_MEDIA,
           K_MEDIUM, K_COUNT };
    static const char *const keys[K_COUNT] = {"materials", "camera",  "film",   "render",      "ambient", "meshes",
                                              "spheres",   "lights",  "environment", "media",  "medium"};
    if (!ctx || !s) return PK_ERR_INVALID_ARGUMENT;
    if (!data && size) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "scene_json_parse: no data");
    if (size > PK_MAX_JSON_BYTES)
        return ctx_error(ctx, PK_ERR_LIMIT, "%s: a JSON scene may hold at most %zu bytes (meshes belong in OBJ files)",
                         name ? name : "scene.json", (size_t)PK_MAX_JSON_BYTES);
    jp *p = mem_calloc(&ctx->alloc, 1, sizeof *p);
    if (!p) return ctx_nomem(ctx);
    p->ctx = ctx;
    p->s = s;
    p->text = data ? data : "";
    p->size = size;
    p->name = name ? name : "scene.json";
    p->base_dir = base_dir;

    pk_status st;
    const char *end = NULL;
    cJSON *root = size ? cJSON_ParseWithLengthOpts(p->text, size, &end, 0) : NULL;
    if (!root) {
        st = syntax_error(p, end);
        goto out;
    }
    p->root = root;
    size_t rest = end && end >= p->text && end <= p->text + size ? (size_t)(end - p->text) : size;
    while (rest < size && is_ws(p->text[rest])) rest++;
    if (rest < size) {
        st = ctx_error(ctx, PK_ERR_PARSE, "%s:%d: unexpected text after the JSON document", p->name,
                       line_at(p->text, rest));
        goto out;
    }
    if (!cJSON_IsObject(root)) {
        st = jfail(p, PK_ERR_PARSE, root, "", "the top level must be a JSON object");
        goto out;
    }
    const cJSON *f[K_COUNT];
    if ((st = object_fields(p, root, "", keys, K_COUNT, f))) goto out;

    /* Media first (materials and the camera name them), then materials:
     * meshes (usemtl) and spheres refer to them by name. */
    if (f[K_MEDIA] && (st = each_element(p, f[K_MEDIA], "media", parse_medium))) goto out;
    if (f[K_MEDIUM]) {
        int32_t med;
        if ((st = get_medium_ref(p, f[K_MEDIUM], "medium", &med))) goto out;
        scene_set_camera_medium(s, med);
    }
    if (f[K_MATERIALS] && (st = parse_materials(p, f[K_MATERIALS]))) goto out;
    if (f[K_CAMERA] && (st = parse_camera(p, f[K_CAMERA]))) goto out;
    if (f[K_FILM] && (st = parse_film(p, f[K_FILM]))) goto out;
    if (f[K_RENDER] && (st = parse_render(p, f[K_RENDER]))) goto out;
    if (f[K_AMBIENT] && (st = get_color(p, f[K_AMBIENT], "ambient", &s->ambient))) goto out;
    if (f[K_MESHES] && (st = each_element(p, f[K_MESHES], "meshes", parse_mesh))) goto out;
    p->named_limit = s->nmaterials;
    if (f[K_SPHERES] && (st = each_element(p, f[K_SPHERES], "spheres", parse_sphere))) goto out;
    if (f[K_LIGHTS] && (st = each_element(p, f[K_LIGHTS], "lights", parse_light))) goto out;
    if (f[K_ENV] && (st = parse_environment(p, f[K_ENV]))) goto out;
    st = PK_OK;
out:
    cJSON_Delete(root);
    mem_free(&ctx->alloc, p);
    return st;
}
