/*
 * scene_write_json.c - `paprsek convert`: a loaded scene written as a Paprsek
 * JSON scene (pk_scene_write_json) that renders the same bytes.
 *
 * What is written is the committed scene, as the renderer sees it: the
 * readers' meaning (pbrt's ISO x exposure, Mitsuba's spectra, glTF's
 * mirrored textures, instances flattened into world triangles, emission
 * cloned onto materials) is already in it, so writing it needs no knowledge
 * of any format, and nothing has to be re-derived by the JSON reader (where
 * a second derivation could differ in a bit). Instances the commit kept are
 * written as a mesh and its placements, in order, and kept again. The JSON format's "record"
 * forms (scene_record.h) carry each material, light, medium and the
 * environment field by field; triangles go to binary PLY files beside the
 * JSON, three vertices a triangle (the renderer looks triangles up by
 * corner, never by shared vertex), one file per run of triangles that agree
 * on having normals and uvs, with a face property naming the material;
 * texture images named by a file are referenced by its absolute path, others
 * (glTF's embedded and derived images), the environment map and media grids
 * are raw files of the numbers in memory (little-endian on the machines
 * Paprsek builds for).
 *
 * Every float is printed with the fewest digits (at most 9) that read back
 * to the same float, checked here. Files are written under temporary names
 * (NAME.partial) and renamed into place, the JSON last; on any failure all
 * are removed.
 */
#include "io_util.h"
#include "readers.h"
#include "scene_record.h"
#include "../scene/scene.h"

#include <errno.h>
#include <limits.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>

typedef struct jw {
    pk_context *ctx;
    const pk_scene *s;
    const char *out;      /* the JSON's path */
    char *dir;            /* its folder */
    const char *stem;     /* its base name without .json */
    size_t stem_len;
    FILE *f;              /* the JSON's temporary file */
    char **final;         /* files to rename into place (the JSON is the last) */
    size_t nfiles, cap_files;
    char **mat_names;     /* unique names of the materials */
    char **med_names;     /* unique names of the media */
    size_t nside;         /* side files so far (their numbers) */
} jw;

/* ---- files --------------------------------------------------------------- */

static pk_status jw_io(jw *w, const char *path, const char *what)
{
    return ctx_error(w->ctx, PK_ERR_IO, "%s: cannot %s: %s", path, what, strerror(errno));
}

/* Adds final to the files to rename, and opens final.partial for writing.
 * rel receives the name relative to the JSON's folder. */
static pk_status jw_open(jw *w, const char *suffix, FILE **f, char *rel, size_t rel_size)
{
    const pk_allocator *a = &w->ctx->alloc;
    snprintf(rel, rel_size, "%.*s%s", (int)w->stem_len, w->stem, suffix);
    char *full = path_join(a, w->dir, rel);
    if (!full) return ctx_nomem(w->ctx);
    if (!mem_grow(a, (void **)&w->final, &w->cap_files, w->nfiles + 1, sizeof *w->final)) {
        mem_free(a, full);
        return ctx_nomem(w->ctx);
    }
    w->final[w->nfiles++] = full;
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s.partial", full);
    *f = fopen(tmp, "wb");
    if (!*f) return jw_io(w, tmp, "create");
    return PK_OK;
}

static pk_status jw_close(jw *w, FILE *f, const char *final)
{
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s.partial", final);
    const bool bad = ferror(f) != 0;
    if (fclose(f) != 0 || bad) return jw_io(w, tmp, "write");
    return PK_OK;
}

/* A side file holding n bytes of data. */
static pk_status jw_raw(jw *w, const char *what, const void *data, size_t n, char *rel, size_t rel_size)
{
    char suffix[96];
    snprintf(suffix, sizeof suffix, ".%s%zu.bin", what, w->nside++);
    FILE *f;
    pk_status st = jw_open(w, suffix, &f, rel, rel_size);
    if (st) return st;
    if (n && fwrite(data, 1, n, f) != n) {
        fclose(f);
        return jw_io(w, w->final[w->nfiles - 1], "write");
    }
    return jw_close(w, f, w->final[w->nfiles - 1]);
}

/* ---- numbers and strings ---------------------------------------------------- */

/* The shortest of %.6g .. %.9g that reads back (as the JSON reader reads:
 * to double, then to float) to the same float. */
static void fmt_float(char *buf, size_t n, float v)
{
    for (int prec = 6; prec <= 9; prec++) {
        snprintf(buf, n, "%.*g", prec, (double)v);
        float back = (float)strtod(buf, NULL);
        if (memcmp(&back, &v, sizeof v) == 0) return;
    }
    snprintf(buf, n, "%.17g", (double)v); /* the float's exact double: always reads back */
}

static bool jw_finite(jw *w, float v, const char *what)
{
    if (isfinite(v)) return true;
    ctx_error(w->ctx, PK_ERR_UNSUPPORTED, "%s: %s is not finite; the JSON format has no such number", w->out, what);
    return false;
}

static pk_status jw_floats(jw *w, const float *v, int n, const char *what)
{
    char b[40];
    if (n > 1) fputc('[', w->f);
    for (int i = 0; i < n; i++) {
        if (!jw_finite(w, v[i], what)) return w->ctx->status;
        fmt_float(b, sizeof b, v[i]);
        fprintf(w->f, "%s%s", i ? ", " : "", b);
    }
    if (n > 1) fputc(']', w->f);
    return PK_OK;
}

static void jw_string(FILE *f, const char *s)
{
    fputc('"', f);
    for (const unsigned char *c = (const unsigned char *)s; *c; c++) {
        if (*c == '"' || *c == '\\') fprintf(f, "\\%c", *c);
        else if (*c < 32) fprintf(f, "\\u%04x", *c);
        else fputc(*c, f);
    }
    fputc('"', f);
}

/* "key": (after a separator when not first) */
static void jw_key(jw *w, bool *first, const char *key)
{
    fprintf(w->f, "%s", *first ? "" : ", ");
    *first = false;
    jw_string(w->f, key);
    fputs(": ", w->f);
}

/* The fields of table t of src, as members of an open object. */
static pk_status jw_fields(jw *w, bool *first, const rec_field *t, size_t n, const void *src, const char *what)
{
    for (size_t i = 0; i < n; i++) {
        const void *at = (const char *)src + t[i].offset;
        char why[160];
        snprintf(why, sizeof why, "%s.%s", what, t[i].name);
        jw_key(w, first, t[i].name);
        pk_status st = PK_OK;
        switch (t[i].type) {
        case REC_FLOAT: st = jw_floats(w, (const float *)at, 1, why); break;
        case REC_VEC3: st = jw_floats(w, (const float *)at, 3, why); break;
        case REC_F2: st = jw_floats(w, (const float *)at, 2, why); break;
        case REC_F9: st = jw_floats(w, (const float *)at, 9, why); break;
        case REC_F16: st = jw_floats(w, (const float *)at, 16, why); break;
        case REC_INT: fprintf(w->f, "%d", *(const int *)at); break;
        case REC_U8: fprintf(w->f, "%d", (int)*(const uint8_t *)at); break;
        case REC_BOOL: fputs(*(const bool *)at ? "true" : "false", w->f); break;
        case REC_WRAP: {
            const uint8_t c = *(const uint8_t *)at & TEX_CLAMP;
            fputs(c == TEX_CLAMP ? "true" : c == TEX_CLAMP_U ? "\"u\"" : c == TEX_CLAMP_V ? "\"v\"" : "false", w->f);
            break;
        }
        }
        if (st) return st;
    }
    return PK_OK;
}

/* Unique names: names[i] stays when no other entry has it, else gets "#i";
 * with keep0, entry 0 (the default material, which every scene has under
 * its name) keeps its name whatever the others are called. */
static pk_status unique_names(jw *w, size_t n, const char *(*name_of)(const pk_scene *, size_t), const char *fallback,
                              bool keep0, char ***out)
{
    const pk_allocator *a = &w->ctx->alloc;
    char **names = mem_calloc(a, n ? n : 1, sizeof *names);
    if (!names) return ctx_nomem(w->ctx);
    *out = names;
    for (size_t i = 0; i < n; i++) {
        const char *nm = name_of(w->s, i);
        bool dup = !nm || !nm[0];
        for (size_t j = 0; j < n && !dup && !(keep0 && i == 0); j++) {
            const char *o = name_of(w->s, j);
            dup = j != i && o && strcmp(o, nm) == 0;
        }
        char buf[PK_ERRMSG_MAX];
        if (dup) snprintf(buf, sizeof buf, "%s#%zu", nm && nm[0] ? nm : fallback, i);
        names[i] = mem_strdup(a, dup ? buf : nm);
        if (!names[i]) return ctx_nomem(w->ctx);
    }
    return PK_OK;
}

static const char *material_name(const pk_scene *s, size_t i) { return s->materials[i].name; }
static const char *medium_name(const pk_scene *s, size_t i) { return s->media[i].name; }

/* ---- sections --------------------------------------------------------------- */

static pk_status write_medium_ref(jw *w, int32_t m)
{
    if (m == MEDIUM_NONE) fputs("null", w->f);
    else jw_string(w->f, w->med_names[m]);
    return PK_OK;
}

static bool is_file(const char *path)
{
    struct stat sb;
    return stat(path, &sb) == 0 && S_ISREG(sb.st_mode);
}

static pk_status write_texref(jw *w, const tex_ref *r, const char *what)
{
    bool first = true;
    if (r->kind == TEX_EXPR)
        return ctx_error(w->ctx, PK_ERR_UNSUPPORTED,
                         "%s: %s: a procedural texture (pbrt-v4's) cannot be written in the JSON format", w->out, what);
    fputc('{', w->f);
    pk_status st = jw_fields(w, &first, rec_texref, rec_ntexref, r, what);
    if (st) return st;
    if (r->kind == TEX_IMAGE) {
        const texture *t = &w->s->textures[r->tex];
        const bool colour = t->key[0] == 'c';
        const char *key = t->key + 1;
        char abs[PATH_MAX];
        if (!strchr(key, '#') && is_file(key) && realpath(key, abs)) {
            jw_key(w, &first, "image");
            jw_string(w->f, abs);
            jw_key(w, &first, "colour");
            fputs(colour ? "true" : "false", w->f);
        } else { /* decoded by its reader (glTF): the level-0 pixels */
            const tex_level *l = &t->lv[0];
            const size_t n = (size_t)l->w * (size_t)l->h * (size_t)t->nc;
            char rel[PATH_MAX];
            if ((st = jw_raw(w, "texture", l->pxf ? (const void *)l->pxf : (const void *)l->px8,
                             n * (l->pxf ? sizeof(float) : 1), rel, sizeof rel)))
                return st;
            jw_key(w, &first, "pixels");
            fputs("{\"file\": ", w->f);
            jw_string(w->f, rel);
            fputs(", \"key\": ", w->f);
            jw_string(w->f, key);
            fprintf(w->f, ", \"size\": [%d, %d], \"channels\": %d, \"float\": %s, \"colour\": %s}", l->w, l->h, t->nc,
                    l->pxf ? "true" : "false", colour ? "true" : "false");
        }
    }
    fputc('}', w->f);
    return PK_OK;
}

static pk_status write_materials(jw *w)
{
    const pk_scene *s = w->s;
    /* material 0 is every scene's default: the JSON reader cannot change it */
    material d;
    material_init(&d);
    d.kd = v3s(0.5f);
    const material *m0 = &s->materials[0];
    bool same = m0->medium_in == d.medium_in && m0->medium_out == d.medium_out;
    for (size_t i = 0; i < rec_nmaterial && same; i++) {
        const size_t sz = rec_material[i].type == REC_VEC3 ? sizeof(vec3)
                          : rec_material[i].type == REC_BOOL ? sizeof(bool)
                                                             : sizeof(float);
        same = memcmp((const char *)m0 + rec_material[i].offset, (const char *)&d + rec_material[i].offset, sz) == 0;
    }
    for (int k = 0; k < MATERIAL_NMAPS && same; k++)
        same = material_map_c(m0, k)->kind == TEX_NONE;
    if (!same)
        return ctx_error(w->ctx, PK_ERR_UNSUPPORTED,
                         "%s: the scene changes the default material 0; the JSON format cannot express that", w->out);
    fputs("\n\"materials\": [", w->f);
    for (size_t i = 1; i < s->nmaterials; i++) {
        const material *m = &s->materials[i];
        char what[64];
        snprintf(what, sizeof what, "materials[%zu]", i - 1);
        fprintf(w->f, "%s\n  {\"name\": ", i > 1 ? "," : "");
        jw_string(w->f, w->mat_names[i]);
        fputs(", \"record\": {", w->f);
        bool first = true;
        pk_status st = jw_fields(w, &first, rec_material, rec_nmaterial, m, what);
        if (st) return st;
        for (int k = 0; k < MATERIAL_NMAPS; k++) {
            const tex_ref *r = material_map_c(m, k);
            if (r->kind == TEX_NONE) continue;
            jw_key(w, &first, material_map_names[k]);
            if ((st = write_texref(w, r, what))) return st;
        }
        if (m->medium_in != MEDIUM_INHERIT) {
            jw_key(w, &first, "interior");
            write_medium_ref(w, m->medium_in);
        }
        if (m->medium_out != MEDIUM_INHERIT) {
            jw_key(w, &first, "exterior");
            write_medium_ref(w, m->medium_out);
        }
        fputs("}}", w->f);
    }
    fputs("]", w->f);
    return PK_OK;
}

static pk_status write_grid(jw *w, bool *first, const char *key, const medium_grid *g)
{
    if (!g->data) return PK_OK;
    char rel[PATH_MAX];
    const size_t n = (size_t)g->nx * (size_t)g->ny * (size_t)g->nz * (size_t)g->channels;
    pk_status st = jw_raw(w, key, g->data, n * sizeof(float), rel, sizeof rel);
    if (st) return st;
    jw_key(w, first, key);
    fputs("{\"file\": ", w->f);
    jw_string(w->f, rel);
    fprintf(w->f, ", \"size\": [%d, %d, %d], \"channels\": %d}", g->nx, g->ny, g->nz, g->channels);
    return PK_OK;
}

static pk_status write_media(jw *w)
{
    const pk_scene *s = w->s;
    fputs(",\n\"media\": [", w->f);
    for (size_t i = 0; i < s->nmedia; i++) {
        const medium *m = &s->media[i];
        char what[64];
        snprintf(what, sizeof what, "media[%zu]", i);
        fprintf(w->f, "%s\n  {\"name\": ", i ? "," : "");
        jw_string(w->f, w->med_names[i]);
        fputs(", \"record\": {", w->f);
        bool first = true;
        pk_status st = jw_fields(w, &first, rec_medium, rec_nmedium, m, what);
        if (st || (st = write_grid(w, &first, "density", &m->density)) ||
            (st = write_grid(w, &first, "albedo_grid", &m->albedo_grid)) ||
            (st = write_grid(w, &first, "emission_grid", &m->emission_grid)))
            return st;
        fputs("}}", w->f);
    }
    fputs("]", w->f);
    return PK_OK;
}

static pk_status write_camera(jw *w)
{
    const pk_camera *c = &w->s->camera;
    pk_status st;
    fputs(",\n\"camera\": {\"look_from\": ", w->f);
    if ((st = jw_floats(w, c->look_from, 3, "camera.look_from"))) return st;
    fputs(", \"look_at\": ", w->f);
    if ((st = jw_floats(w, c->look_at, 3, "camera.look_at"))) return st;
    fputs(", \"up\": ", w->f);
    if ((st = jw_floats(w, c->up, 3, "camera.up"))) return st;
    fputs(", \"fov\": ", w->f);
    if ((st = jw_floats(w, &c->fov_deg, 1, "camera.fov"))) return st;
    fputs(", \"lens_radius\": ", w->f);
    if ((st = jw_floats(w, &c->lens_radius, 1, "camera.lens_radius"))) return st;
    fputs(", \"focus_distance\": ", w->f);
    if ((st = jw_floats(w, &c->focus_distance, 1, "camera.focus_distance"))) return st;
    fputs(", \"ortho_width\": ", w->f);
    if ((st = jw_floats(w, &c->ortho_width, 1, "camera.ortho_width"))) return st;
    if (c->projection != PK_PROJECTION_PERSPECTIVE && c->projection != PK_PROJECTION_ORTHOGRAPHIC)
        return ctx_error(w->ctx, PK_ERR_UNSUPPORTED, "%s: camera projection %d has no JSON name", w->out,
                         c->projection);
    fprintf(w->f, ", \"projection\": \"%s\"}",
            c->projection == PK_PROJECTION_ORTHOGRAPHIC ? "orthographic" : "perspective");
    return PK_OK;
}

static pk_status write_render(jw *w)
{
    const scene_render_settings *r = &w->s->render;
    const pk_render_options *o = &r->opt;
    fputs(",\n\"render\": {", w->f);
    bool first = true;
    const struct {
        bool has;
        const char *key;
        int v;
    } ints[] = {{r->has_width, "width", o->width},
                {r->has_height, "height", o->height},
                {r->has_spp, "spp", o->spp},
                {r->has_light_samples, "light_samples", o->light_samples},
                {r->has_max_depth, "max_depth", o->max_depth},
                {r->has_threads, "threads", o->threads},
                {r->has_seed, "seed", o->seed},
                {r->has_regularize, "regularize", o->regularize},
                {r->has_light_tree, "light_tree", o->light_tree}};
    for (size_t i = 0; i < sizeof ints / sizeof ints[0]; i++)
        if (ints[i].has) {
            jw_key(w, &first, ints[i].key);
            fprintf(w->f, "%d", ints[i].v);
        }
    if (r->has_accel) {
        jw_key(w, &first, "accel");
        jw_string(w->f, pk_accel_kind_name(o->accel));
    }
    if (r->has_integrator) {
        jw_key(w, &first, "integrator");
        jw_string(w->f, pk_integrator_name(o->integrator));
    }
    if (r->has_fresnel) {
        jw_key(w, &first, "fresnel");
        fputs(o->fresnel ? "true" : "false", w->f);
    }
    if (r->has_energy_compensation) {
        jw_key(w, &first, "energy_compensation");
        fputs(o->energy_compensation ? "true" : "false", w->f);
    }
    if (r->has_clamp_indirect) {
        jw_key(w, &first, "clamp_indirect");
        pk_status st = jw_floats(w, &o->clamp_indirect, 1, "render.clamp_indirect");
        if (st) return st;
    }
    if (r->has_filter) {
        const pk_filter *fl = &o->filter;
        jw_key(w, &first, "filter");
        fputs("{\"type\": ", w->f);
        jw_string(w->f, pk_filter_name(fl->type));
        fputs(", \"radius\": ", w->f);
        const float rad[2] = {fl->radius_x, fl->radius_y};
        pk_status st = jw_floats(w, rad, 2, "render.filter.radius");
        const struct {
            pk_filter_type type;
            const char *key;
            const float *v;
        } params[] = {{PK_FILTER_GAUSSIAN, "sigma", &fl->sigma},
                      {PK_FILTER_MITCHELL, "b", &fl->b},
                      {PK_FILTER_MITCHELL, "c", &fl->c},
                      {PK_FILTER_LANCZOS, "tau", &fl->tau}};
        for (size_t i = 0; i < sizeof params / sizeof params[0] && st == PK_OK; i++)
            if (params[i].type == fl->type) {
                fprintf(w->f, ", \"%s\": ", params[i].key);
                st = jw_floats(w, params[i].v, 1, "render.filter");
            }
        if (st) return st;
        fputc('}', w->f);
    }
    fputc('}', w->f);
    return PK_OK;
}

/* Triangles with their vertex arrays: the world's, or a mesh's (whose
 * triangles index its own ranges). */
typedef struct tri_src {
    const triangle *tris;
    size_t ntris;
    const vec3 *pos, *nrm;
    const uv2 *uv;
    const rgba *col;        /* by position, NULL: none */
    const vtangent *tan;    /* by position, NULL: none */
    const uv2 *uv1;         /* the second texture-coordinate set by position, NULL: none */
} tri_src;

static bool tri_has_n(const triangle *t) { return t->n[0] >= 0 && t->n[1] >= 0 && t->n[2] >= 0; }
static bool tri_has_t(const triangle *t) { return t->t[0] >= 0 && t->t[1] >= 0 && t->t[2] >= 0; }

/* Material numbering of one "ply" entry: local[m] is material m's number + 1
 * in the entry's "materials" list, used[] the list. */
typedef struct mat_list {
    uint32_t *local, *used;
    size_t nused;
} mat_list;

/* The triangles [t0, t1) of src (all with or all without normals and uvs, as
 * the renderer reads them: all three corners or none) as one binary PLY file,
 * three vertices a triangle; rel receives its name. */
static pk_status write_run(jw *w, const tri_src *src, size_t t0, size_t t1, mat_list *ml, char *rel, size_t rel_size)
{
    const bool has_n = tri_has_n(&src->tris[t0]), has_t = tri_has_t(&src->tris[t0]);
    char suffix[64];
    snprintf(suffix, sizeof suffix, ".mesh%zu.ply", w->nside++);
    FILE *f;
    pk_status st = jw_open(w, suffix, &f, rel, rel_size);
    if (st) return st;
    const char *final = w->final[w->nfiles - 1];
    for (size_t t = t0; t < t1; t++) {
        const uint32_t m = src->tris[t].material;
        if (!ml->local[m]) {
            ml->used[ml->nused++] = m;
            ml->local[m] = (uint32_t)ml->nused;
        }
    }
    const size_t ntri = t1 - t0;
    const uint16_t one = 1; /* the numbers go out in this machine's order, which the header names */
    fprintf(f,
            "ply\nformat binary_%s_endian 1.0\ncomment written by paprsek convert\n"
            "element vertex %zu\nproperty float x\nproperty float y\nproperty float z\n",
            *(const uint8_t *)&one ? "little" : "big", 3 * ntri);
    if (has_n) fputs("property float nx\nproperty float ny\nproperty float nz\n", f);
    if (has_t) fputs("property float u\nproperty float v\n", f);
    if (src->col) fputs("property float color_r\nproperty float color_g\nproperty float color_b\nproperty float color_a\n", f);
    if (src->tan)
        fputs("property float tangent_x\nproperty float tangent_y\nproperty float tangent_z\nproperty float tangent_w\n", f);
    if (src->uv1) fputs("property float u1\nproperty float v1\n", f);
    fprintf(f, "element face %zu\nproperty list uchar uint vertex_indices\nproperty uint material\nend_header\n", ntri);
    for (size_t t = t0; t < t1; t++) {
        const triangle *tr = &src->tris[t];
        for (int j = 0; j < 3; j++) {
            float v[20];
            int n = 0;
            const vec3 p = src->pos[tr->v[j]];
            v[n++] = p.x, v[n++] = p.y, v[n++] = p.z;
            if (has_n) {
                const vec3 q = src->nrm[tr->n[j]];
                v[n++] = q.x, v[n++] = q.y, v[n++] = q.z;
            }
            if (has_t) {
                const uv2 q = src->uv[tr->t[j]];
                v[n++] = q.u, v[n++] = q.v;
            }
            if (src->col) {
                const rgba c = src->col[tr->v[j]];
                v[n++] = c.r, v[n++] = c.g, v[n++] = c.b, v[n++] = c.a;
            }
            if (src->tan) {
                const vtangent c = src->tan[tr->v[j]];
                v[n++] = c.t.x, v[n++] = c.t.y, v[n++] = c.t.z, v[n++] = c.w;
            }
            if (src->uv1) {
                const uv2 q = src->uv1[tr->v[j]];
                v[n++] = q.u, v[n++] = q.v;
            }
            fwrite(v, sizeof(float), (size_t)n, f);
        }
    }
    for (size_t t = t0; t < t1; t++) {
        const uint32_t base = (uint32_t)(3 * (t - t0));
        unsigned char three = 3;
        const uint32_t rec[4] = {base, base + 1, base + 2, ml->local[src->tris[t].material] - 1};
        fwrite(&three, 1, 1, f);
        fwrite(rec, sizeof(uint32_t), 4, f);
    }
    return jw_close(w, f, final);
}

/* The end of the run that starts at t0: where normals or uvs start or stop. */
static size_t run_end(const tri_src *src, size_t t0)
{
    const bool hn = tri_has_n(&src->tris[t0]), ht = tri_has_t(&src->tris[t0]);
    size_t t1 = t0 + 1;
    while (t1 < src->ntris && t1 - t0 < ((size_t)1 << 28) && tri_has_n(&src->tris[t1]) == hn &&
           tri_has_t(&src->tris[t1]) == ht)
        t1++;
    return t1;
}

/* "materials": [...] of an entry, and the list emptied for the next. */
static void write_mat_list(jw *w, mat_list *ml)
{
    fputs(", \"materials\": [", w->f);
    for (size_t i = 0; i < ml->nused; i++) {
        if (i) fputs(", ", w->f);
        jw_string(w->f, w->mat_names[ml->used[i]]);
        ml->local[ml->used[i]] = 0;
    }
    fputs("]", w->f);
    ml->nused = 0;
}

/* {"mesh": K, "transform": T, "material": NAME} of an "instance" entry. */
static pk_status write_placement(jw *w, uint32_t mesh, const xform *x, uint32_t mat)
{
    fprintf(w->f, "{\"mesh\": %u, \"transform\": ", mesh);
    pk_status st = jw_floats(w, x->m, 16, "instance transform");
    if (st) return st;
    if (mat != SCENE_MESH_MATERIAL) {
        fputs(", \"material\": ", w->f);
        jw_string(w->f, w->mat_names[mat]);
    }
    fputc('}', w->f);
    return PK_OK;
}

static pk_status write_meshes(jw *w)
{
    const pk_scene *s = w->s;
    const pk_allocator *a = &w->ctx->alloc;
    mat_list ml = {mem_calloc(a, s->nmaterials, sizeof *ml.local), mem_calloc(a, s->nmaterials, sizeof *ml.used), 0};
    uint32_t *mesh_no = mem_calloc(a, s->nmeshes ? s->nmeshes : 1, sizeof *mesh_no); /* JSON mesh number + 1 */
    pk_status st = PK_OK;
    char rel[PATH_MAX];
    if (!ml.local || !ml.used || !mesh_no) {
        st = ctx_nomem(w->ctx);
        goto out;
    }
    fputs(",\n\"meshes\": [", w->f);
    /* the world's triangles, a file (and an entry) per run */
    const tri_src world = {s->tris, s->ntris, s->positions, s->normals, s->uvs, s->colors, s->tangents, s->uvs1};
    bool first = true;
    for (size_t t0 = 0; t0 < s->ntris && st == PK_OK;) {
        const size_t t1 = run_end(&world, t0);
        if ((st = write_run(w, &world, t0, t1, &ml, rel, sizeof rel))) break;
        fprintf(w->f, "%s\n  {\"ply\": ", first ? "" : ",");
        first = false;
        jw_string(w->f, rel);
        write_mat_list(w, &ml);
        fputc('}', w->f);
        t0 = t1;
    }
    /* the kept instances: each mesh once (its files, "instances": []), then
     * every instance in order, so that their hit numbers stay as they were */
    uint32_t nmesh = 0;
    for (size_t i = 0; i < s->nkept && st == PK_OK; i++) {
        const uint32_t mi = s->kept[i].mesh;
        if (mesh_no[mi]) continue;
        mesh_no[mi] = ++nmesh;
        const scene_mesh *m = &s->meshes[mi];
        const tri_src src = {s->mesh_tris + m->first_tri, m->ntris, s->mesh_positions + m->first_pos,
                             s->mesh_normals + m->first_nrm, s->mesh_uvs + m->first_uv,
                             s->mesh_colors ? s->mesh_colors + m->first_pos : NULL,
                             s->mesh_tangents ? s->mesh_tangents + m->first_pos : NULL,
                             s->mesh_uvs1 ? s->mesh_uvs1 + m->first_pos : NULL};
        fprintf(w->f, "%s\n  {\"ply\": [", first ? "" : ",");
        first = false;
        for (size_t t0 = 0; t0 < src.ntris && st == PK_OK;) {
            const size_t t1 = run_end(&src, t0);
            if ((st = write_run(w, &src, t0, t1, &ml, rel, sizeof rel))) break;
            if (t0) fputs(", ", w->f);
            jw_string(w->f, rel);
            t0 = t1;
        }
        fputc(']', w->f);
        write_mat_list(w, &ml);
        fputs(", \"instances\": []}", w->f);
    }
    for (size_t i = 0; i < s->nkept && st == PK_OK; i++) {
        fprintf(w->f, "%s\n  {\"instance\": ", first ? "" : ",");
        first = false;
        st = write_placement(w, mesh_no[s->kept[i].mesh] - 1, &s->kept[i].to_world, s->kept[i].material);
        fputc('}', w->f);
    }
    fputs("]", w->f);
out:
    mem_free(a, ml.local);
    mem_free(a, ml.used);
    mem_free(a, mesh_no);
    return st;
}

static pk_status write_spheres(jw *w)
{
    const pk_scene *s = w->s;
    fputs(",\n\"spheres\": [", w->f);
    for (size_t i = 0; i < s->nspheres; i++) {
        const sphere *sp = &s->spheres[i];
        pk_status st;
        fprintf(w->f, "%s\n  {\"center\": ", i ? "," : "");
        if ((st = jw_floats(w, &sp->center.x, 3, "spheres.center"))) return st;
        fputs(", \"radius\": ", w->f);
        if ((st = jw_floats(w, &sp->radius, 1, "spheres.radius"))) return st;
        fputs(", \"material\": ", w->f);
        jw_string(w->f, w->mat_names[sp->material]);
        fputc('}', w->f);
    }
    fputs("]", w->f);
    return PK_OK;
}

static pk_status write_lights(jw *w)
{
    const pk_scene *s = w->s;
    fputs(",\n\"lights\": [", w->f);
    for (size_t i = 0; i < s->nlights; i++) {
        bool first = true;
        fprintf(w->f, "%s\n  {\"record\": {", i ? "," : "");
        const point_light *l = &s->lights[i];
        pk_status st = jw_fields(w, &first, rec_light, rec_nlight, l, "lights");
        if (st) return st;
        if (l->map_kind != LIGHT_MAP_NONE) { /* the image, as a texture reference */
            tex_ref r;
            tex_ref_init(&r);
            r.kind = TEX_IMAGE;
            r.tex = l->map_tex;
            jw_key(w, &first, "map");
            if ((st = write_texref(w, &r, "lights"))) return st;
        }
        fputs("}}", w->f);
    }
    fputs("]", w->f);
    return PK_OK;
}

static pk_status write_environment(jw *w)
{
    const scene_environment *env = &w->s->env;
    bool first = true;
    fputs(",\n\"environment\": {\"record\": {", w->f);
    pk_status st = jw_fields(w, &first, rec_env, rec_nenv, env, "environment");
    if (st) return st;
    if (env->has_portal) {
        float c[12];
        for (int k = 0; k < 4; k++) {
            c[3 * k] = env->portal[k].x, c[3 * k + 1] = env->portal[k].y;
            c[3 * k + 2] = env->portal[k].z;
        }
        jw_key(w, &first, "portal");
        if ((st = jw_floats(w, c, 12, "environment.portal"))) return st;
    }
    if (env->map_rgb && env->map_w > 0 && env->map_h > 0) {
        char rel[PATH_MAX];
        const size_t n = 3 * (size_t)env->map_w * (size_t)env->map_h;
        if ((st = jw_raw(w, "environment", env->map_rgb, n * sizeof(float), rel, sizeof rel))) return st;
        jw_key(w, &first, "map");
        fputs("{\"file\": ", w->f);
        jw_string(w->f, rel);
        fprintf(w->f, ", \"size\": [%d, %d]}", env->map_w, env->map_h);
    } else if (env->map) {
        return ctx_error(w->ctx, PK_ERR_UNSUPPORTED, "%s: the environment map %s is not loaded", w->out, env->map);
    }
    fputs("}}", w->f);
    return PK_OK;
}

static pk_status write_scene(jw *w)
{
    const pk_scene *s = w->s;
    pk_status st;
    /* (the reader takes the sections in its own order: materials first
     * here, as every scene has them, and each other section after a comma) */
    fputs("{", w->f);
    if ((st = write_materials(w))) return st;
    if (s->nmedia && (st = write_media(w))) return st;
    if (s->camera_medium != MEDIUM_NONE) {
        fputs(",\n\"medium\": ", w->f);
        write_medium_ref(w, s->camera_medium);
    }
    if (s->has_camera && (st = write_camera(w))) return st;
    if ((st = write_render(w))) return st;
    if (v3_len2(s->ambient) != 0.0f || signbit(s->ambient.x) || signbit(s->ambient.y) || signbit(s->ambient.z)) {
        fputs(",\n\"ambient\": ", w->f);
        if ((st = jw_floats(w, &s->ambient.x, 3, "ambient"))) return st;
    }
    if ((st = write_meshes(w))) return st;
    if ((st = write_spheres(w))) return st;
    if ((st = write_lights(w))) return st;
    if (s->env.set || s->env.map || s->env.has_sun || s->env.has_sky || v3_len2(s->env.radiance) != 0.0f) {
        if ((st = write_environment(w))) return st;
    }
    fputs("\n}\n", w->f);
    return PK_OK;
}

pk_status pk_scene_write_json(pk_context *ctx, const pk_scene *s, const char *path)
{
    if (!ctx || !s || !path) return PK_ERR_INVALID_ARGUMENT;
    if (!s->committed) return ctx_error(ctx, PK_ERR_INVALID_ARGUMENT, "%s: the scene is not committed", path);
    /* Kept instances are written as instances, and the renderer keeps them
     * again by the same rule (scene_commit), unless under scene.instances=auto
     * a mesh was kept for a placement that is no longer there to count
     * (placed twice, once as an emitter: flattened) */
    if (ctx->config.instances == 0)
        for (size_t i = 0; i < s->nkept; i++) {
            size_t n = 0;
            for (size_t j = 0; j < s->nkept && n < 2; j++) n += s->kept[j].mesh == s->kept[i].mesh;
            if (n < 2)
                return ctx_error(ctx, PK_ERR_UNSUPPORTED,
                                 "%s: mesh %u is kept as an instance for a placement that was flattened; its JSON "
                                 "scene would not be kept alike: convert with scene.instances=keep or flatten",
                                 path, s->kept[i].mesh);
        }
    const pk_allocator *a = &ctx->alloc;
    jw w = {.ctx = ctx, .s = s, .out = path};
    pk_status st = PK_OK;
    const char *base = strrchr(path, '/');
    base = base ? base + 1 : path;
    w.stem = base;
    w.stem_len = strlen(base);
    if (w.stem_len > 5 && strcmp(base + w.stem_len - 5, ".json") == 0) w.stem_len -= 5;
    if (!(w.dir = path_dirname(a, path))) {
        st = ctx_nomem(ctx);
        goto out;
    }
    if ((st = unique_names(&w, s->nmaterials, material_name, "material", true, &w.mat_names)) ||
        (st = unique_names(&w, s->nmedia, medium_name, "medium", false, &w.med_names)))
        goto out;
    /* the JSON's temporary name first, so that an unwritable folder fails
     * before any side file is written */
    char tmp[PATH_MAX];
    snprintf(tmp, sizeof tmp, "%s.partial", path);
    if (!(w.f = fopen(tmp, "wb"))) {
        st = jw_io(&w, tmp, "create");
        goto out;
    }
    st = write_scene(&w);
    const bool bad = ferror(w.f) != 0;
    if (fclose(w.f) != 0 || bad) {
        if (!st) st = jw_io(&w, tmp, "write");
    }
    w.f = NULL;
    if (!st) {
        for (size_t i = 0; i < w.nfiles && !st; i++) {
            char t[PATH_MAX];
            snprintf(t, sizeof t, "%s.partial", w.final[i]);
            if (rename(t, w.final[i]) != 0) st = jw_io(&w, w.final[i], "rename into place");
        }
        if (!st && rename(tmp, path) != 0) st = jw_io(&w, path, "rename into place");
    }
    if (st) {
        remove(tmp);
        for (size_t i = 0; i < w.nfiles; i++) {
            char t[PATH_MAX];
            snprintf(t, sizeof t, "%s.partial", w.final[i]);
            remove(t);
        }
    }
out:
    for (size_t i = 0; i < w.nfiles; i++) mem_free(a, w.final[i]);
    mem_free(a, w.final);
    for (size_t i = 0; w.mat_names && i < s->nmaterials; i++) mem_free(a, w.mat_names[i]);
    mem_free(a, w.mat_names);
    for (size_t i = 0; w.med_names && i < s->nmedia; i++) mem_free(a, w.med_names[i]);
    mem_free(a, w.med_names);
    mem_free(a, w.dir);
    return st;
}
