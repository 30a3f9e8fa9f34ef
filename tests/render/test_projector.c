/*
 * test_projector.c - Mitsuba 3's projector emitter (io/scene_xml.c, a
 * projection light with Mitsuba's normalisation) against the closed form.
 *
 * Mitsuba 3 scales the irradiance texture by pi * scale / cos^3 of the angle
 * from the projector's axis, so that a plane facing the projector at
 * distance D receives E = pi * scale * T / D^2 at every point of the
 * projected window, and a diffuse plane of albedo rho there shows the
 * radiance rho * scale * T / D^2, the same in every pixel. Seen from the
 * projector's own position, the plane is lit exactly where the camera's
 * pixel direction lies within the projector's field of view. Only direct
 * light reaches the camera (one plane, no environment), so the estimate has
 * no variance: the pixels must match to rounding.
 */
#include "test.h"

#include "paprsek.h"
#include "render/path.h"
#include "render/render.h"

#include <string.h>
#include <unistd.h>

#define W 40
#define PK_PI_D 3.14159265358979323846

static pk_context *ctx;

static void write_text(const char *path, const char *text)
{
    FILE *f = fopen(path, "w");
    REQUIRE(f);
    fputs(text, f);
    fclose(f);
}

/* Renders a plane at z = D (albedo rho) seen from the origin along +z
 * (horizontal fov cam_fov) and lit by a projector at the origin. */
static pk_image *render(const char *dir, const char *projector, float cam_fov, float D, float rho)
{
    char path[600], xml[4096];
    snprintf(path, sizeof path, "%s/projector.xml", dir);
    snprintf(xml, sizeof xml,
             "<scene version=\"3.0.0\">\n"
             "  <integrator type=\"path\"><integer name=\"max_depth\" value=\"3\"/></integrator>\n"
             "  <sensor type=\"perspective\">\n"
             "    <float name=\"fov\" value=\"%g\"/>\n"
             "    <transform name=\"to_world\"><lookat origin=\"0,0,0\" target=\"0,0,1\" up=\"0,1,0\"/></transform>\n"
             "    <film type=\"hdrfilm\"><integer name=\"width\" value=\"%d\"/><integer name=\"height\" value=\"%d\"/>\n"
             "      <rfilter type=\"box\"/></film>\n"
             "  </sensor>\n"
             "  <emitter type=\"projector\">\n%s"
             "    <transform name=\"to_world\"><lookat origin=\"0,0,0\" target=\"0,0,1\" up=\"0,1,0\"/></transform>\n"
             "  </emitter>\n"
             "  <shape type=\"rectangle\">\n"
             "    <transform name=\"to_world\"><scale value=\"20\"/><rotate y=\"1\" angle=\"180\"/>"
             "<translate z=\"%g\"/></transform>\n"
             "    <bsdf type=\"diffuse\"><rgb name=\"reflectance\" value=\"%g\"/></bsdf>\n"
             "  </shape>\n"
             "</scene>\n",
             (double)cam_fov, W, W, projector, (double)D, (double)rho);
    write_text(path, xml);
    pk_scene *s = NULL;
    REQUIRE(pk_scene_load_file(ctx, path, &s) == PK_OK);
    pk_render_options o;
    pk_render_options_init(&o);
    o.integrator = PK_INTEGRATOR_PATH;
    o.width = o.height = W;
    o.spp = 4;
    o.threads = 2;
    pk_renderer *r = NULL;
    pk_film *f = NULL;
    pk_image *img = NULL;
    REQUIRE(pk_renderer_create(ctx, s, &o, &r) == PK_OK);
    REQUIRE(pk_film_create(ctx, W, W, &f) == PK_OK);
    REQUIRE(pk_renderer_render(r, NULL, 0, f) == PK_OK);
    REQUIRE(pk_film_resolve(ctx, f, &img) == PK_OK);
    pk_film_destroy(f);
    pk_renderer_destroy(r);
    pk_scene_destroy(s);
    return img;
}

/* Every pixel whose direction lies inside the projector's window (tan of
 * the half fov t_x, t_y; the camera's t_cam) by a pixel's margin has the
 * radiance rho * scale * irr / D^2; every pixel outside it by a margin is black. */
static void check(const char *what, const pk_image *img, double t_cam, double t_x, double t_y, vec3 expected)
{
    const float *px = pk_image_pixels_const(img);
    int inside = 0, outside = 0, bad = 0;
    const double margin = 1.5 * 2.0 * t_cam / W;
    for (int j = 0; j < W; j++)
        for (int i = 0; i < W; i++) {
            const double x = (2.0 * (i + 0.5) / W - 1.0) * t_cam, y = (2.0 * (j + 0.5) / W - 1.0) * t_cam;
            const float *c = &px[3 * (j * W + i)];
            const bool in = fabs(x) < t_x - margin && fabs(y) < t_y - margin;
            const bool out = fabs(x) > t_x + margin || fabs(y) > t_y + margin;
            if (in) {
                inside++;
                const float e[3] = {expected.x, expected.y, expected.z};
                for (int k = 0; k < 3; k++)
                    if (!(fabsf(c[k] - e[k]) <= 1e-4f * e[k])) bad++;
            } else if (out) {
                outside++;
                if (c[0] != 0.0f || c[1] != 0.0f || c[2] != 0.0f) bad++;
            }
        }
    const float *m = &px[3 * ((W / 2) * W + W / 2)];
    printf("%s: centre %.6f %.6f %.6f, expected %.6f %.6f %.6f; %d pixels inside, %d outside, %d wrong\n", what,
           (double)m[0], (double)m[1], (double)m[2], (double)expected.x, (double)expected.y, (double)expected.z,
           inside, outside, bad);
    CHECK(inside > 0);
    CHECKF(bad == 0, "%s: %d pixel values wrong", what, bad);
}

int main(void)
{
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);
    char dir[] = "/tmp/pk_test_projector_XXXXXX";
    REQUIRE(mkdtemp(dir));
    const float D = 2.0f, rho = 0.5f, scale = 3.0f;
    const vec3 irr = v3(0.5f, 1.0f, 2.0f);
    const vec3 expect = v3_scale(irr, rho * scale / (D * D));
    /* a projector wider than the camera: every pixel lit */
    pk_image *img = render(dir,
                           "    <rgb name=\"irradiance\" value=\"0.5, 1.0, 2.0\"/>\n"
                           "    <float name=\"scale\" value=\"3\"/>\n    <float name=\"fov\" value=\"50\"/>\n",
                           30.0f, D, rho);
    const double t30 = tan(15.0 * PK_PI_D / 180.0), t50 = tan(25.0 * PK_PI_D / 180.0);
    check("projector, fov 50 seen at fov 30", img, t30, t50, t50, expect);
    pk_image_destroy(img);
    /* a narrower projector: its window's edges, at tan(fov / 2) */
    const double t60 = tan(30.0 * PK_PI_D / 180.0), t20 = tan(10.0 * PK_PI_D / 180.0);
    img = render(dir,
                 "    <rgb name=\"irradiance\" value=\"0.5, 1.0, 2.0\"/>\n"
                 "    <float name=\"scale\" value=\"3\"/>\n    <float name=\"fov\" value=\"20\"/>\n",
                 60.0f, D, rho);
    check("projector, fov 20 seen at fov 60", img, t60, t20, t20, expect);
    pk_image_destroy(img);
    /* focal_length (50mm by default): the diagonal of 36 x 24 mm, over a square window */
    img = render(dir, "    <rgb name=\"irradiance\" value=\"0.5, 1.0, 2.0\"/>\n    <float name=\"scale\" value=\"3\"/>\n",
                 60.0f, D, rho);
    const double half_diag = sqrt(36.0 * 36.0 + 24.0 * 24.0) / (2.0 * 50.0), tf = half_diag / sqrt(2.0);
    check("projector, 50mm", img, t60, tf, tf, expect);
    pk_image_destroy(img);
    char cmd[600];
    snprintf(cmd, sizeof cmd, "rm -rf '%s'", dir);
    CHECK(system(cmd) == 0);
    pk_context_destroy(ctx);
    return test_done("test_projector");
}
