/*
 * test_media_readers_mj.c - participating media in the JSON and Mitsuba XML
 * readers, on small scenes written here: each medium's coefficients, grid
 * and placement, the media sides of materials (and the copies made for
 * Mitsuba's shapes), the camera's medium, the volpath integrator, the
 * messages of bad input with their file:line, and the fog scene of
 * tests/data/media given in both formats read into the same media and
 * materials.
 */
#include "test.h"
#include "warnings.h"

#include "io/readers.h"
#include "scene/scene.h"

#include <stdint.h>
#include <sys/stat.h>

static warning_log wl;
static pk_context *ctx;
static char tmpdir[256];

static bool warned(const char *part) { return warning_log_has(&wl, part); }

static void write_file(const char *rel, const void *data, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", tmpdir, rel);
    FILE *f = fopen(path, "wb");
    REQUIRE(f);
    REQUIRE(fwrite(data, 1, n, f) == n);
    fclose(f);
}

/* A .vol file: n[0] x n[1] x n[2] voxels of ch channels, box lo..hi. */
static void write_vol(const char *rel, const int n[3], int ch, const float lo[3], const float hi[3], const float *v)
{
    const size_t count = (size_t)n[0] * (size_t)n[1] * (size_t)n[2] * (size_t)ch;
    unsigned char *b = calloc(1, 48 + 4 * count);
    REQUIRE(b);
    memcpy(b, "VOL", 3);
    b[3] = 3;
    const int32_t head[5] = {1, n[0], n[1], n[2], ch};
    memcpy(b + 4, head, sizeof head); /* (the test machines are little endian, as the format) */
    memcpy(b + 24, lo, 12);
    memcpy(b + 36, hi, 12);
    memcpy(b + 48, v, 4 * count);
    write_file(rel, b, 48 + 4 * count);
    free(b);
}

static pk_scene *load_json(const char *json)
{
    pk_context_clear_error(ctx);
    warning_log_clear(&wl);
    pk_scene *s = NULL;
    if (pk_scene_load_json_memory(ctx, json, strlen(json), "scene.json", tmpdir, &s) != PK_OK) return NULL;
    return s;
}

/* load_json, reporting the error of a scene that should load. */
static pk_scene *load_json_ok(const char *json)
{
    pk_scene *s = load_json(json);
    CHECKF(s != NULL, "%s\n-> %s", json, pk_context_error(ctx));
    return s;
}

static pk_scene *load_xml(const char *xml, const char *version);

static pk_scene *load_xml_ok(const char *xml, const char *version)
{
    pk_scene *s = load_xml(xml, version);
    CHECKF(s != NULL, "%s\n-> %s", xml, pk_context_error(ctx));
    return s;
}

static pk_scene *load_xml(const char *xml, const char *version)
{
    char buf[16384];
    /* (a scene needs geometry: a sphere far away, after the test's shapes) */
    snprintf(buf, sizeof buf, "<scene version=\"%s\">\n%s\n<shape type=\"sphere\"><point name=\"center\" x=\"99\"/></shape>\n</scene>\n",
             version, xml);
    pk_context_clear_error(ctx);
    warning_log_clear(&wl);
    pk_scene *s = NULL;
    if (pk_scene_load_xml_memory(ctx, buf, strlen(buf), "scene.xml", tmpdir, &s) != PK_OK) return NULL;
    return s;
}

static void json_fails(const char *json, const char *want)
{
    pk_scene *s = load_json(json);
    CHECKF(s == NULL, "%s: loaded, expected '%s'", json, want);
    if (s) {
        pk_scene_destroy(s);
        return;
    }
    CHECKF(strstr(pk_context_error(ctx), want) != NULL, "got '%s', expected '%s'", pk_context_error(ctx), want);
}

static void xml_fails(const char *xml, const char *version, const char *want)
{
    pk_scene *s = load_xml(xml, version);
    CHECKF(s == NULL, "%s: loaded, expected '%s'", xml, want);
    if (s) {
        pk_scene_destroy(s);
        return;
    }
    CHECKF(strstr(pk_context_error(ctx), want) != NULL, "got '%s', expected '%s'", pk_context_error(ctx), want);
}

static bool near3(vec3 a, float x, float y, float z, float tol)
{
    return fabsf(a.x - x) <= tol * (1.0f + fabsf(x)) && fabsf(a.y - y) <= tol * (1.0f + fabsf(y)) &&
           fabsf(a.z - z) <= tol * (1.0f + fabsf(z));
}

static const medium *find_medium(const pk_scene *s, const char *name)
{
    int64_t i = scene_find_medium(s, name);
    return i < 0 ? NULL : &s->media[i];
}

static int32_t medium_index(const pk_scene *s, const char *name) { return (int32_t)scene_find_medium(s, name); }

static const material *find_mat(const pk_scene *s, const char *name)
{
    int64_t i = scene_find_material(s, name);
    return i < 0 ? NULL : &s->materials[i];
}

/* ---- JSON --------------------------------------------------------------------------- */

static void test_json_homogeneous(void)
{
    pk_scene *s = load_json_ok(
        "{\"media\": [\n"
        "  {\"name\": \"fog\", \"type\": \"homogeneous\", \"sigma_a\": 0.05, \"sigma_s\": [0.1, 0.2, 0.3],\n"
        "   \"scale\": 2, \"g\": 0.3, \"emission\": [1, 2, 3]},\n"
        "  {\"name\": \"milk\", \"type\": \"homogeneous\", \"sigma_t\": [4, 5, 6], \"albedo\": 0.9},\n"
        "  {\"name\": \"plain\", \"type\": \"homogeneous\"}],\n"
        " \"medium\": \"fog\",\n"
        " \"camera\": {\"look_from\": [0, 0, 5], \"look_at\": [0, 0, 0], \"medium\": \"fog\"},\n"
        " \"render\": {\"integrator\": \"volpath\"},\n"
        " \"materials\": {\n"
        "   \"glass\": {\"type\": \"dielectric\", \"ior\": 1.3, \"interior\": \"milk\", \"exterior\": \"fog\"},\n"
        "   \"hole\": {\"type\": \"interface\", \"interior\": \"milk\", \"exterior\": null},\n"
        "   \"wall\": {\"kd\": [0.5, 0.5, 0.5], \"interior\": null},\n"
        "   \"plain\": {\"type\": \"diffuse\"}},\n"
        " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"glass\"},\n"
        "             {\"center\": [3, 0, 0], \"radius\": 1,\n"
        "              \"material\": {\"type\": \"conductor\", \"exterior\": \"milk\"}}]}\n");
    REQUIRE(s);
    CHECKF(wl.count == 0, "%s", wl.msg[0]);
    REQUIRE(s->nmedia == 3);
    const medium *fog = find_medium(s, "fog"), *milk = find_medium(s, "milk"), *plain = find_medium(s, "plain");
    REQUIRE(fog && milk && plain);
    CHECK(fog->kind == MEDIUM_HOMOGENEOUS);
    CHECK(near3(fog->sigma_t, 0.3f, 0.5f, 0.7f, 1e-6f)); /* (sigma_a + sigma_s) * scale */
    CHECK(near3(fog->albedo, 0.1f / 0.15f, 0.2f / 0.25f, 0.3f / 0.35f, 1e-6f));
    CHECK(near3(fog->le, 1, 2, 3, 0));
    CHECK(fog->g == 0.3f);
    CHECK(near3(milk->sigma_t, 4, 5, 6, 0) && near3(milk->albedo, 0.9f, 0.9f, 0.9f, 0) && milk->g == 0.0f);
    CHECK(near3(plain->sigma_t, 1, 1, 1, 0) && near3(plain->albedo, 1, 1, 1, 0)); /* the defaults */
    CHECK(s->camera_medium == medium_index(s, "fog"));
    CHECK(s->render.has_integrator && s->render.opt.integrator == PK_INTEGRATOR_VOLPATH);
    const material *glass = find_mat(s, "glass"), *hole = find_mat(s, "hole"), *wall = find_mat(s, "wall");
    const material *pm = find_mat(s, "plain");
    REQUIRE(glass && hole && wall && pm);
    CHECK(glass->type == MAT_DIELECTRIC && glass->ni == 1.3f);
    CHECK(glass->medium_in == medium_index(s, "milk") && glass->medium_out == medium_index(s, "fog"));
    CHECK(hole->type == MAT_INTERFACE && hole->medium_in == medium_index(s, "milk") && hole->medium_out == MEDIUM_NONE);
    CHECK(wall->medium_in == MEDIUM_NONE && wall->medium_out == MEDIUM_INHERIT);
    CHECK(pm->medium_in == MEDIUM_INHERIT && pm->medium_out == MEDIUM_INHERIT);
    REQUIRE(s->nspheres == 2);
    const material *inl = &s->materials[s->spheres[1].material];
    CHECK(inl->type == MAT_CONDUCTOR && inl->medium_in == MEDIUM_INHERIT && inl->medium_out == medium_index(s, "milk"));
    CHECK(scene_has_media(s));
    pk_scene_destroy(s);
}

static void test_json_grids(void)
{
    /* inline grids, bounds, transform, albedo and emission grids */
    pk_scene *s = load_json_ok(
        "{\"media\": [{\"name\": \"smoke\", \"type\": \"grid\", \"sigma_t\": 4, \"albedo\": 0.5, \"g\": -0.2,\n"
        "  \"density\": {\"size\": [2, 1, 3], \"data\": [0, 1, 2, 3, 4, 5]},\n"
        "  \"albedo_grid\": {\"size\": [1, 1, 1], \"channels\": 3, \"data\": [1, 0.5, 0.25]},\n"
        "  \"emission_grid\": {\"size\": [1, 1, 2], \"data\": [0, 7]},\n"
        "  \"bounds\": {\"min\": [-1, 0, 2], \"max\": [1, 4, 5]},\n"
        "  \"transform\": {\"translate\": [10, 0, 0]}}],\n"
        " \"medium\": \"smoke\", \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}\n");
    REQUIRE(s);
    CHECKF(wl.count == 0, "%s", wl.msg[0]);
    const medium *m = find_medium(s, "smoke");
    REQUIRE(m);
    CHECK(m->kind == MEDIUM_GRID);
    CHECK(m->density.nx == 2 && m->density.ny == 1 && m->density.nz == 3 && m->density.channels == 1);
    for (int i = 0; i < 6; i++) CHECK(m->density.data[i] == (float)i);
    CHECK(m->albedo_grid.channels == 3 && m->albedo_grid.data[1] == 0.5f);
    CHECK(m->emission_grid.nz == 2 && m->emission_grid.data[1] == 7.0f);
    CHECK(near3(m->le, 1, 1, 1, 0)); /* the emission grid is the radiance */
    CHECK(near3(m->sigma_t, 4, 4, 4, 0) && near3(m->albedo, 0.5f, 0.5f, 0.5f, 0) && m->g == -0.2f);
    /* the unit cube onto the bounds, then moved by the transform */
    CHECK(near3(xform_point(&m->grid_to_world, v3(0, 0, 0)), 9, 0, 2, 1e-6f));
    CHECK(near3(xform_point(&m->grid_to_world, v3(1, 1, 1)), 11, 4, 5, 1e-6f));
    /* the density at a voxel centre: 4 * voxel (1, 0, 2) = 4 * 5 */
    medium_point mp = medium_at(m, xform_point(&m->grid_to_world, v3(0.75f, 0.5f, 5.0f / 6.0f)));
    CHECK(near3(v3_add(mp.sigma_a, mp.sigma_s), 20, 20, 20, 1e-5f));
    pk_scene_destroy(s);

    /* a .vol file: its box places the grid unless bounds are given */
    const int n[3] = {2, 2, 1};
    const float lo[3] = {1, 2, 3}, hi[3] = {2, 4, 7}, v[4] = {0.5f, 1, 1.5f, 2};
    write_vol("g.vol", n, 1, lo, hi, v);
    s = load_json_ok("{\"media\": [{\"name\": \"a\", \"type\": \"grid\", \"file\": \"g.vol\", \"sigma_a\": 1, \"sigma_s\": 3},\n"
                  "  {\"name\": \"b\", \"type\": \"grid\", \"file\": \"g.vol\", \"bounds\": {\"min\": [0, 0, 0], "
                  "\"max\": [1, 1, 1]}}],\n"
                  " \"materials\": {\"box\": {\"type\": \"interface\", \"interior\": \"a\"}, \"box2\": {\"type\": "
                  "\"interface\", \"interior\": \"b\"}},\n"
                  " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1, \"material\": \"box\"}]}\n");
    REQUIRE(s);
    const medium *a = find_medium(s, "a"), *b = find_medium(s, "b");
    REQUIRE(a && b);
    CHECK(a->density.nx == 2 && a->density.ny == 2 && a->density.data[3] == 2.0f);
    CHECK(near3(a->sigma_t, 4, 4, 4, 0) && near3(a->albedo, 0.75f, 0.75f, 0.75f, 0));
    CHECK(near3(xform_point(&a->grid_to_world, v3(0, 0, 0)), 1, 2, 3, 0));
    CHECK(near3(xform_point(&a->grid_to_world, v3(1, 1, 1)), 2, 4, 7, 0));
    CHECK(near3(xform_point(&b->grid_to_world, v3(1, 1, 1)), 1, 1, 1, 0));
    pk_scene_destroy(s);

    /* albedo and emission files over the same box; a different box is refused */
    const float alb[12] = {1, 0.5f, 0.25f, 1, 1, 1, 0, 0, 0, 0.5f, 0.5f, 0.5f};
    write_vol("ga.vol", n, 3, lo, hi, alb);
    write_vol("ge.vol", n, 1, lo, hi, v);
    const float hi2[3] = {2, 4, 8};
    write_vol("gb.vol", n, 1, lo, hi2, v);
    s = load_json_ok("{\"media\": [{\"name\": \"a\", \"type\": \"grid\", \"file\": \"g.vol\",\n"
                     "  \"albedo_file\": \"ga.vol\", \"emission_file\": \"ge.vol\", \"emission\": 2}],\n"
                     " \"medium\": \"a\", \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}\n");
    REQUIRE(s);
    a = find_medium(s, "a");
    REQUIRE(a);
    CHECK(a->albedo_grid.channels == 3 && a->albedo_grid.data[1] == 0.5f && a->albedo_grid.data[9] == 0.5f);
    CHECK(a->emission_grid.channels == 1 && a->emission_grid.data[3] == 2.0f && near3(a->le, 2, 2, 2, 0));
    pk_scene_destroy(s);
    json_fails("{\"media\": [{\"name\": \"a\", \"type\": \"grid\", \"file\": \"g.vol\",\n"
               "  \"albedo_file\": \"gb.vol\"}]}",
               "scene.json:2: media[0].albedo_file: the file's box differs from the density file's");
    json_fails("{\"media\": [{\"name\": \"a\", \"type\": \"grid\", \"file\": \"g.vol\", \"emission_file\": \"ge.vol\",\n"
               "  \"emission_grid\": {\"size\": [1, 1, 1], \"data\": [1]}}]}",
               "scene.json:2: media[0].emission_grid: give \"emission_file\" or \"emission_grid\", not both");
}

static void test_json_errors(void)
{
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"homogeneous\"}],\n"
               " \"materials\": {\"m\": {\"type\": \"diffuse\",\n \"interior\": \"smog\"}}}",
               "scene.json:3: materials.m.interior: unknown medium \"smog\"");
    json_fails("{\"medium\": \"fog\"}", "scene.json:1: medium: unknown medium \"fog\"");
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"homogeneous\",\n \"sigma_s\": -1}]}",
               "scene.json:2: media[0].sigma_s: must not be negative");
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"homogeneous\",\n \"g\": 1}]}",
               "scene.json:2: media[0].g: must lie strictly between -1 and 1");
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"homogeneous\", \"albedo\": 1.5}]}",
               "media[0].albedo: must lie in 0..1");
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"homogeneous\", \"sigma_a\": 1, \"sigma_t\": 2}]}",
               "media[0].sigma_t: give \"sigma_a\" and \"sigma_s\" or \"sigma_t\" and \"albedo\", not both");
    json_fails("{\"media\": [{\"name\": \"fog\", \"type\": \"cloud\"}]}",
               "media[0].type: must be \"homogeneous\" or \"grid\"");
    json_fails("{\"media\": [{\"type\": \"grid\"}]}", "media[0]: missing \"name\"");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\", \"file\": \"x.vol\"}]}",
               "media[0].file: belongs to a grid medium");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\"}]}",
               "media[0]: a grid medium needs \"file\" (a .vol, .nvdb or .vdb file) or \"density\", one of them");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\",\n"
               " \"density\": {\"size\": [2, 2, 2],\n \"data\": [1, 2, 3]}}]}",
               "scene.json:3: media[0].density.data: holds 3 numbers; a 2x2x2 grid of 1 channel needs 8");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"density\": {\"size\": [1, 1, 2], \"data\": [1, "
               "-2]}}]}",
               "media[0].density.data: value 1 must be a finite number, not negative");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"density\": {\"size\": [1024, 1024, 1024], "
               "\"data\": [1]}}]}",
               "media[0].density: 1024x1024x1024 voxels is over the limit");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"density\": {\"size\": [1, 1, 1], \"channels\": 2, "
               "\"data\": [1, 1]}}]}",
               "media[0].density.channels: must be 1 or 3");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"density\": {\"size\": [1, 1, 1], \"data\": [1]},\n"
               " \"bounds\": {\"min\": [0, 0, 0], \"max\": [1, 0, 1]}}]}",
               "scene.json:2: media[0].bounds.max: must exceed \"min\" on every axis");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"file\": \"missing.vol\"}]}",
               "media[0].file: ");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"grid\", \"file\": \"smoke.raw\"}]}",
               "media[0].file: grid files are Mitsuba .vol, NanoVDB .nvdb or OpenVDB .vdb files");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\"}, {\"name\": \"f\", \"type\": "
               "\"homogeneous\"}]}",
               "media[1]: a medium named \"f\" is defined already");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\"}], \"medium\": \"f\",\n"
               " \"camera\": {\"look_from\": [0, 0, 1], \"look_at\": [0, 0, 0], \"medium\": null}}",
               "scene.json:2: camera.medium: differs from the scene's \"medium\"");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\"}], \"materials\": {\"m\": {\"type\": "
               "\"emitter\",\n \"bsdf\": {\"type\": \"diffuse\", \"interior\": \"f\"}}}}",
               "scene.json:2: materials.m.bsdf.interior: media belong to the outer material");
    json_fails("{\"materials\": {\"m\": {\"type\": \"interface\", \"two_sided\": true}}}",
               "materials.m.two_sided: an interface has no surface to shade");
    json_fails("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\"}], \"materials\": {\"m\": {\"type\": "
               "\"diffuse\", \"interior\": 3}}}",
               "materials.m.interior: must be the name of a medium of \"media\", or null (vacuum)");
    json_fails("{\"render\": {\"integrator\": \"bdpt\"}}",
               "render.integrator: must be \"path\", \"volpath\", \"whitted\" or \"default\"");
    /* unknown keys are warned about, as elsewhere */
    pk_scene *s = load_json_ok("{\"media\": [{\"name\": \"f\", \"type\": \"homogeneous\",\n \"colour\": 1}],\n"
                            " \"spheres\": [{\"center\": [0, 0, 0], \"radius\": 1}]}");
    REQUIRE(s);
    CHECKF(warned("scene.json:2: media[0].colour: unknown key ignored"), "%s", wl.all);
    pk_scene_destroy(s);
}

/* ---- Mitsuba --------------------------------------------------------------------------- */

static void test_xml_homogeneous(void)
{
    pk_scene *s = load_xml_ok(
        "<medium type=\"homogeneous\" id=\"fog\">\n"
        "  <float name=\"sigma_t\" value=\"0.5\"/>\n"
        "  <rgb name=\"albedo\" value=\"0.9, 0.8, 0.7\"/>\n"
        "  <float name=\"scale\" value=\"2\"/>\n"
        "  <phase type=\"hg\"><float name=\"g\" value=\"0.4\"/></phase>\n"
        "</medium>\n"
        "<medium type=\"homogeneous\" id=\"dflt\"/>\n"
        "<medium type=\"homogeneous\" id=\"hg\"><phase type=\"hg\"/></medium>\n"
        "<sensor type=\"perspective\"><ref id=\"fog\"/></sensor>\n"
        "<integrator type=\"volpath\"><integer name=\"max_depth\" value=\"9\"/>"
        "<integer name=\"rr_depth\" value=\"3\"/></integrator>\n"
        "<bsdf type=\"dielectric\" id=\"glass\"/>\n"
        "<shape type=\"sphere\" id=\"a\"><ref id=\"glass\"/><ref name=\"interior\" id=\"fog\"/></shape>\n"
        "<shape type=\"sphere\"><ref id=\"glass\"/><ref name=\"exterior\" id=\"fog\"/>"
        "<ref name=\"interior\" id=\"dflt\"/></shape>\n"
        "<shape type=\"sphere\"><ref id=\"glass\"/></shape>\n"
        "<shape type=\"cube\"><bsdf type=\"null\"/>\n"
        "  <medium type=\"homogeneous\" name=\"interior\"><float name=\"sigma_t\" value=\"3\"/></medium></shape>\n"
        "<shape type=\"sphere\"><ref id=\"glass\"/><ref name=\"interior\" id=\"fog\"/></shape>\n",
        "3.0.0");
    REQUIRE(s);
    CHECKF(wl.count == 0, "%s", wl.all);
    REQUIRE(s->nmedia == 4);
    const medium *fog = find_medium(s, "fog"), *d = find_medium(s, "dflt"), *hg = find_medium(s, "hg");
    REQUIRE(fog && d && hg);
    CHECK(fog->kind == MEDIUM_HOMOGENEOUS && near3(fog->sigma_t, 1, 1, 1, 1e-6f));
    CHECK(near3(fog->albedo, 0.9f, 0.8f, 0.7f, 1e-6f) && fog->g == 0.4f);
    CHECK(near3(d->sigma_t, 1, 1, 1, 0) && near3(d->albedo, 0.75f, 0.75f, 0.75f, 1e-6f) && d->g == 0.0f);
    CHECK(hg->g == 0.8f); /* Mitsuba's default g */
    const medium *inl = &s->media[3];
    CHECK(strstr(inl->name, "medium@") != NULL && near3(inl->sigma_t, 3, 3, 3, 0));
    CHECK(s->camera_medium == medium_index(s, "fog"));
    CHECK(s->render.opt.integrator == PK_INTEGRATOR_VOLPATH && s->render.opt.max_depth == 8);
    /* the shapes' materials: copies of glass with the media, once per pair */
    REQUIRE(s->nspheres == 5);
    const int32_t f = medium_index(s, "fog"), df = medium_index(s, "dflt");
    const material *m0 = &s->materials[s->spheres[0].material], *m1 = &s->materials[s->spheres[1].material];
    const material *m2 = &s->materials[s->spheres[2].material];
    CHECK(m0->type == MAT_DIELECTRIC && m0->medium_in == f && m0->medium_out == MEDIUM_NONE); /* left out: vacuum */
    CHECK(m1->medium_in == df && m1->medium_out == f);
    CHECK(m2->medium_in == MEDIUM_INHERIT && m2->medium_out == MEDIUM_INHERIT); /* no media: no transition */
    CHECK(strcmp(m2->name, "glass") == 0 && strstr(m0->name, "glass@") == m0->name);
    CHECK(s->spheres[3].material == s->spheres[0].material);
    bool iface = false;
    for (size_t t = 0; t < s->ntris; t++) {
        const material *mt = &s->materials[s->tris[t].material];
        iface = mt->type == MAT_INTERFACE && mt->medium_in == 3 && mt->medium_out == MEDIUM_NONE;
        if (!iface) break;
    }
    CHECK(iface && s->ntris == 12);
    pk_scene_destroy(s);

    /* Mitsuba 0.6: sigmaA/sigmaS, densityMultiplier, g reducing sigma_s, a
     * shape with media and no bsdf is index-matched */
    s = load_xml_ok("<medium type=\"homogeneous\" id=\"m\">\n"
                 "  <spectrum name=\"sigmaA\" value=\"0.1\"/>\n"
                 "  <rgb name=\"sigmaS\" value=\"1, 2, 3\"/>\n"
                 "  <float name=\"densityMultiplier\" value=\"2\"/>\n"
                 "  <float name=\"g\" value=\"0.5\"/>\n"
                 "</medium>\n"
                 "<shape type=\"cube\"><ref name=\"exterior\" id=\"m\"/></shape>\n",
                 "0.6.0");
    REQUIRE(s);
    CHECKF(warned("densityMultiplier is the old name of scale"), "%s", wl.all);
    const medium *m = find_medium(s, "m");
    REQUIRE(m);
    /* sigma_s = 2 (1, 2, 3) (1 - 0.5), sigma_a = 0.2 */
    CHECK(near3(m->sigma_t, 1.2f, 2.2f, 3.2f, 1e-6f) && m->g == 0.0f);
    CHECK(near3(m->albedo, 1.0f / 1.2f, 2.0f / 2.2f, 3.0f / 3.2f, 1e-6f));
    REQUIRE(s->ntris == 12);
    const material *b = &s->materials[s->tris[0].material];
    CHECK(b->type == MAT_INTERFACE && b->medium_out == 0 && b->medium_in == MEDIUM_NONE);
    pk_scene_destroy(s);

    /* Mitsuba 3: a shape with media and no bsdf is diffuse, as Mitsuba 3 makes it */
    s = load_xml_ok("<medium type=\"homogeneous\" id=\"m\"/>\n<shape type=\"cube\"><ref name=\"interior\" id=\"m\"/></shape>",
                 "3.0.0");
    REQUIRE(s);
    CHECK(s->materials[s->tris[0].material].type == MAT_DIFFUSE && s->materials[s->tris[0].material].medium_in == 0);
    pk_scene_destroy(s);

    /* a medium without a side is warned about */
    s = load_xml_ok("<medium type=\"homogeneous\" id=\"m\"/>\n<shape type=\"cube\">\n<ref id=\"m\"/>\n"
                    "<medium type=\"homogeneous\" name=\"inside\"/></shape>",
                    "3.0.0");
    REQUIRE(s);
    CHECKF(warned("scene.xml:4: a shape's medium needs name=\"interior\" or name=\"exterior\"; ignored") &&
               warned("scene.xml:5: a shape's medium needs"),
           "%s", wl.all);
    CHECK(s->materials[s->tris[0].material].medium_in == MEDIUM_INHERIT);
    pk_scene_destroy(s);

    /* unsupported phase functions: warned, isotropic */
    s = load_xml_ok("<medium type=\"homogeneous\" id=\"m\">\n<phase type=\"rayleigh\"/></medium>", "3.0.0");
    REQUIRE(s);
    CHECKF(warned("scene.xml:3: phase function \"rayleigh\" is not supported"), "%s", wl.all);
    CHECK(s->media[0].g == 0.0f);
    pk_scene_destroy(s);
}

static void test_xml_heterogeneous(void)
{
    const int n[3] = {2, 1, 1};
    const float lo[3] = {-1, -1, -1}, hi[3] = {1, 3, 5}, v[2] = {1, 3};
    write_vol("h.vol", n, 1, lo, hi, v);
    const float v3c[6] = {0.5f, 0.5f, 0.5f, 1, 1, 1};
    write_vol("alb.vol", n, 3, lo, hi, v3c);
    /* Mitsuba 3: the unit cube placed by the volume's to_world (and the
     * medium's), the file's box with use_grid_bbox */
    pk_scene *s = load_xml_ok(
        "<medium type=\"heterogeneous\" id=\"smoke\">\n"
        "  <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"h.vol\"/>\n"
        "    <transform name=\"to_world\"><scale value=\"2\"/></transform></volume>\n"
        "  <volume name=\"albedo\" type=\"constvolume\"><rgb name=\"value\" value=\"0.5, 0.6, 0.7\"/></volume>\n"
        "  <float name=\"scale\" value=\"10\"/>\n"
        "  <transform name=\"to_world\"><translate x=\"5\"/></transform>\n"
        "</medium>\n"
        "<medium type=\"heterogeneous\" id=\"boxed\">\n"
        "  <volume name=\"sigma_t\" type=\"gridvolume\"><string name=\"filename\" value=\"h.vol\"/>\n"
        "    <boolean name=\"use_grid_bbox\" value=\"true\"/></volume>\n"
        "  <volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"alb.vol\"/>\n"
        "    <boolean name=\"use_grid_bbox\" value=\"true\"/></volume>\n"
        "</medium>\n"
        "<medium type=\"heterogeneous\" id=\"const\"><float name=\"sigma_t\" value=\"2\"/></medium>\n"
        "<shape type=\"cube\"><bsdf type=\"null\"/><ref name=\"interior\" id=\"smoke\"/></shape>\n",
        "3.0.0");
    REQUIRE(s);
    CHECKF(wl.count == 0, "%s", wl.all);
    const medium *m = find_medium(s, "smoke"), *bx = find_medium(s, "boxed"), *c = find_medium(s, "const");
    REQUIRE(m && bx && c);
    CHECK(m->kind == MEDIUM_GRID && m->density.nx == 2 && m->density.data[1] == 3.0f);
    CHECK(near3(m->sigma_t, 10, 10, 10, 0) && near3(m->albedo, 0.5f, 0.6f, 0.7f, 1e-6f));
    CHECK(near3(xform_point(&m->grid_to_world, v3(0, 0, 0)), 5, 0, 0, 0));
    CHECK(near3(xform_point(&m->grid_to_world, v3(1, 1, 1)), 7, 2, 2, 0));
    CHECK(bx->kind == MEDIUM_GRID && bx->albedo_grid.channels == 3 && near3(bx->albedo, 1, 1, 1, 0));
    CHECK(near3(bx->sigma_t, 1, 1, 1, 0) && near3(bx->albedo, 1, 1, 1, 0));
    CHECK(near3(xform_point(&bx->grid_to_world, v3(0, 0, 0)), -1, -1, -1, 0));
    CHECK(near3(xform_point(&bx->grid_to_world, v3(1, 1, 1)), 1, 3, 5, 0));
    CHECK(c->kind == MEDIUM_HOMOGENEOUS && near3(c->sigma_t, 2, 2, 2, 0) && near3(c->albedo, 0.75f, 0.75f, 0.75f, 1e-6f));
    pk_scene_destroy(s);

    /* Mitsuba 0.6: density and albedo volumes, the file's box under toWorld */
    s = load_xml_ok("<medium type=\"heterogeneous\" id=\"smoke\">\n"
                 "  <volume name=\"density\" type=\"gridvolume\"><string name=\"filename\" value=\"h.vol\"/>\n"
                 "    <transform name=\"toWorld\"><translate y=\"1\"/></transform></volume>\n"
                 "  <volume name=\"albedo\" type=\"constvolume\"><spectrum name=\"value\" value=\"0.9\"/></volume>\n"
                 "  <float name=\"scale\" value=\"3\"/>\n"
                 "</medium>",
                 "0.6.0");
    REQUIRE(s);
    m = find_medium(s, "smoke");
    REQUIRE(m);
    CHECK(near3(m->sigma_t, 3, 3, 3, 0) && near3(m->albedo, 0.9f, 0.9f, 0.9f, 1e-6f));
    /* vertex-centred voxels: the x axis (2 voxels) grows by half its spacing
     * of 2 on each side; y and z (1 voxel) keep the file's box */
    CHECK(near3(xform_point(&m->grid_to_world, v3(0, 0, 0)), -2, 0, -1, 0));
    CHECK(near3(xform_point(&m->grid_to_world, v3(1, 1, 1)), 2, 4, 5, 0));
    /* the voxels' values at the file's box corners, as Mitsuba 0.6 reads them */
    medium_point c0 = medium_at(m, v3(-1, 1.5f, 2)), c1 = medium_at(m, v3(1, 1.5f, 2));
    CHECK_NEAR(c0.sigma_a.x + c0.sigma_s.x, 3.0f * 1.0f, 1e-5);
    CHECK_NEAR(c1.sigma_a.x + c1.sigma_s.x, 3.0f * 3.0f, 1e-5);
    pk_scene_destroy(s);
}

static void test_xml_errors(void)
{
    xml_fails("<medium type=\"homogeneous\" id=\"m\">\n<float name=\"sigma_t\" value=\"-1\"/></medium>", "3.0.0",
              "scene.xml:2: medium: the extinction (-1, -1, -1) must be finite and not negative");
    xml_fails("<medium type=\"homogeneous\" id=\"m\">\n<float name=\"albedo\" value=\"2\"/></medium>", "3.0.0",
              "scene.xml:2: medium: the albedo (2, 2, 2) must lie in 0..1");
    xml_fails("<medium type=\"homogeneous\">\n<phase type=\"hg\">\n<float name=\"g\" value=\"1\"/></phase></medium>",
              "3.0.0", "scene.xml:4: phase \"hg\": g = 1 must lie strictly between -1 and 1");
    xml_fails("<medium type=\"homogeneous\">\n<float name=\"sigma_a\" value=\"1\"/>\n"
              "<float name=\"sigma_t\" value=\"1\"/></medium>",
              "3.0.0", "scene.xml:4: medium: give sigma_a and sigma_s, or sigma_t and albedo, not both");
    xml_fails("<medium type=\"homogeneous\">\n<float name=\"sigma_s\" value=\"-1\"/></medium>", "3.0.0",
              "sigma_a and sigma_s must not be negative");
    xml_fails("\n<medium type=\"spectral\"/>", "3.0.0",
              "scene.xml:3: medium \"spectral\" is not supported (homogeneous and heterogeneous are)");
    xml_fails("<medium type=\"homogeneous\">\n<string name=\"material\" value=\"Skin1\"/></medium>", "0.6.0",
              "medium presets (\"material\") are not supported");
    xml_fails("<shape type=\"cube\">\n<ref name=\"interior\" id=\"nope\"/></shape>", "3.0.0",
              "scene.xml:3: no medium has the id \"nope\"");
    xml_fails("<medium type=\"heterogeneous\">\n<volume name=\"sigma_t\" type=\"gridvolume\">\n"
              "<string name=\"filename\" value=\"none.vol\"/></volume></medium>",
              "3.0.0", "scene.xml:4: ");
    xml_fails("<medium type=\"heterogeneous\">\n<volume name=\"sigma_t\" type=\"vdbvolume\"/></medium>", "3.0.0",
              "scene.xml:3: volume \"vdbvolume\" is not supported");
    xml_fails("<medium type=\"heterogeneous\"/>", "0.6.0", "a heterogeneous medium needs a density volume");
    const int n[3] = {1, 1, 1};
    const float lo[3] = {0, 0, 0}, hi[3] = {1, 1, 1}, lo2[3] = {0, 0, 0}, hi2[3] = {2, 2, 2}, v[1] = {1};
    write_vol("one.vol", n, 1, lo, hi, v);
    write_vol("two.vol", n, 1, lo2, hi2, v);
    xml_fails("<medium type=\"heterogeneous\">\n"
              "<volume name=\"density\" type=\"gridvolume\"><string name=\"filename\" value=\"one.vol\"/></volume>\n"
              "<volume name=\"albedo\" type=\"gridvolume\"><string name=\"filename\" value=\"two.vol\"/></volume>\n"
              "</medium>",
              "0.6.0", "scene.xml:4: the albedo grid must span the same box as the density grid");
    /* the sensor and shapes refer only to media defined before them */
    xml_fails("<sensor type=\"perspective\">\n<ref id=\"later\"/></sensor>\n<medium type=\"homogeneous\" id=\"later\"/>",
              "3.0.0", "scene.xml:3: no medium has the id \"later\"");
}

/* ---- the fog scene in both formats ---------------------------------------------------- */

static bool same_medium_side(const pk_scene *a, int32_t ia, const pk_scene *b, int32_t ib)
{
    if (ia < 0 || ib < 0) return ia == ib;
    return strcmp(a->media[ia].name, b->media[ib].name) == 0;
}

static bool same_material(const pk_scene *a, const material *x, const pk_scene *b, const material *y)
{
    const float t = 1e-6f;
    return x->type == y->type && near3(x->kd, y->kd.x, y->kd.y, y->kd.z, t) &&
           near3(x->ke, y->ke.x, y->ke.y, y->ke.z, t) && fabsf(x->ni - y->ni) <= t && x->alpha == y->alpha &&
           same_medium_side(a, x->medium_in, b, y->medium_in) && same_medium_side(a, x->medium_out, b, y->medium_out);
}

static void test_fog_scene(void)
{
    pk_scene *js = NULL, *xs = NULL;
    warning_log_clear(&wl);
    pk_status st = pk_scene_load_file(ctx, PK_TEST_DATA "/media/fog.json", &js);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECKF(wl.count == 0, "%s", wl.all);
    st = pk_scene_load_file(ctx, PK_TEST_DATA "/media/fog.xml", &xs);
    CHECKF(st == PK_OK, "%s", pk_context_error(ctx));
    CHECKF(wl.count == 0, "%s", wl.all);
    REQUIRE(js && xs);
    /* the media, by name */
    REQUIRE(js->nmedia == 3 && xs->nmedia == 3);
    for (size_t i = 0; i < js->nmedia; i++) {
        const medium *a = &js->media[i], *b = find_medium(xs, a->name);
        REQUIRE(b);
        CHECKF(a->kind == b->kind, "%s", a->name);
        CHECKF(near3(a->sigma_t, b->sigma_t.x, b->sigma_t.y, b->sigma_t.z, 1e-6f), "%s sigma_t", a->name);
        CHECKF(near3(a->albedo, b->albedo.x, b->albedo.y, b->albedo.z, 1e-6f), "%s albedo", a->name);
        CHECKF(near3(a->le, b->le.x, b->le.y, b->le.z, 0), "%s le", a->name);
        CHECKF(a->g == b->g, "%s g %g %g", a->name, (double)a->g, (double)b->g);
        CHECK(memcmp(a->grid_to_world.m, b->grid_to_world.m, sizeof a->grid_to_world.m) == 0);
        CHECK(a->density.nx == b->density.nx && a->density.channels == b->density.channels);
        if (a->density.data && b->density.data)
            CHECK(memcmp(a->density.data, b->density.data,
                         sizeof(float) * (size_t)a->density.nx * (size_t)a->density.ny * (size_t)a->density.nz) == 0);
    }
    const medium *smoke = find_medium(js, "smoke");
    REQUIRE(smoke && smoke->kind == MEDIUM_GRID);
    CHECK(near3(xform_point(&smoke->grid_to_world, v3(0, 0, 0)), 0.1f, 0.05f, -0.7f, 1e-6f));
    CHECK(near3(xform_point(&smoke->grid_to_world, v3(1, 1, 1)), 0.8f, 0.75f, 0.0f, 1e-6f));
    /* fog_smoke.vol: 4^3 voxels, 0.25 (4 - j) + 0.1 i + 0.05 k, denser toward the floor */
    REQUIRE(smoke->density.nx == 4 && smoke->density.ny == 4 && smoke->density.nz == 4);
    for (int k = 0; k < 4; k++)
        for (int j = 0; j < 4; j++)
            for (int i = 0; i < 4; i++)
                CHECK_NEAR(smoke->density.data[(k * 4 + j) * 4 + i], 0.25 * (4 - j) + 0.1 * i + 0.05 * k, 1e-6);
    CHECK(same_medium_side(js, js->camera_medium, xs, xs->camera_medium) && js->camera_medium >= 0);
    CHECK(strcmp(js->media[js->camera_medium].name, "fog") == 0);
    CHECK(js->render.opt.integrator == PK_INTEGRATOR_VOLPATH && xs->render.opt.integrator == PK_INTEGRATOR_VOLPATH);
    CHECK(js->render.opt.max_depth == xs->render.opt.max_depth);
    /* the same triangles and sphere, with the same materials */
    REQUIRE(js->ntris == xs->ntris && js->nspheres == 1 && xs->nspheres == 1);
    for (size_t t = 0; t < js->ntris; t++) {
        vec3 a[3], b[3];
        scene_tri_verts(js, t, &a[0], &a[1], &a[2]);
        scene_tri_verts(xs, t, &b[0], &b[1], &b[2]);
        for (int k = 0; k < 3; k++) CHECK(near3(a[k], b[k].x, b[k].y, b[k].z, 0));
        CHECKF(same_material(js, &js->materials[js->tris[t].material], xs, &xs->materials[xs->tris[t].material]),
               "triangle %zu: %s vs %s", t, js->materials[js->tris[t].material].name,
               xs->materials[xs->tris[t].material].name);
    }
    CHECK(near3(js->spheres[0].center, xs->spheres[0].center.x, xs->spheres[0].center.y, xs->spheres[0].center.z, 1e-6f));
    CHECK(js->spheres[0].radius == xs->spheres[0].radius);
    const material *jg = &js->materials[js->spheres[0].material], *xg = &xs->materials[xs->spheres[0].material];
    CHECK(same_material(js, jg, xs, xg));
    CHECK(jg->type == MAT_DIELECTRIC && strcmp(js->media[jg->medium_in].name, "milk") == 0);
    /* the cameras agree */
    for (int k = 0; k < 3; k++) {
        CHECK_NEAR(js->camera.look_from[k], xs->camera.look_from[k], 1e-5);
        CHECK_NEAR(js->camera.up[k], xs->camera.up[k], 1e-5);
    }
    CHECK_NEAR(js->camera.fov_deg, xs->camera.fov_deg, 1e-3);
    pk_scene_destroy(js);
    pk_scene_destroy(xs);
}

/* ---- allocation failures ---------------------------------------------------------- */

typedef struct failing {
    long calls, fail_at; /* the fail_at-th call fails (0: none) */
    long live;
} failing;

static void *failing_realloc(void *user, void *ptr, size_t size)
{
    failing *f = user;
    if (size == 0) {
        if (ptr) f->live--;
        free(ptr);
        return NULL;
    }
    if (++f->calls == f->fail_at) return NULL;
    void *q = realloc(ptr, size);
    if (q && !ptr) f->live++;
    return q;
}

/* Every allocation failing in turn while the fog scene loads: NOMEM back
 * and nothing left allocated. */
static void test_alloc_failures(const char *path)
{
    int failures_seen = 0;
    long n = 1;
    for (; n < 100000; n++) {
        failing f = {0, 0, 0};
        pk_allocator a = {failing_realloc, &f};
        pk_context *c = NULL;
        REQUIRE(pk_context_create(&a, &c) == PK_OK);
        f.fail_at = f.calls + n;
        pk_scene *s = NULL;
        pk_status st = pk_scene_load_file(c, path, &s);
        if (s) pk_scene_destroy(s);
        pk_context_destroy(c);
        CHECKF(f.live == 0, "%s: failing call %ld: %ld blocks leaked", path, n, f.live);
        if (st == PK_OK) break;
        CHECKF(st == PK_ERR_NOMEM, "%s: failing call %ld: status %d", path, n, (int)st);
        failures_seen++;
    }
    CHECKF(failures_seen > 20 && n < 100000, "%s: %d failures", path, failures_seen);
}

int main(void)
{
    snprintf(tmpdir, sizeof tmpdir, "%s", "/tmp/pk_test_media_mj_XXXXXX");
    REQUIRE(mkdtemp(tmpdir));
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    warning_log_attach(ctx, &wl);
    test_json_homogeneous();
    test_json_grids();
    test_json_errors();
    test_xml_homogeneous();
    test_xml_heterogeneous();
    test_xml_errors();
    test_fog_scene();
    test_alloc_failures(PK_TEST_DATA "/media/fog.json");
    test_alloc_failures(PK_TEST_DATA "/media/fog.xml");
    pk_context_destroy(ctx);
    char cmd[300];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", tmpdir);
    if (system(cmd) != 0) fprintf(stderr, "could not remove %s\n", tmpdir);
    return test_done("test_media_readers_mj");
}
