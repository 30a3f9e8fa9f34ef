/*
 * test_textured_params.c - textures on the parameters that pbrt-v4 and
 * Mitsuba let a texture drive (a conductor's eta, k and reflectance, a
 * roughness, a transmittance): a texture of one constant value renders the
 * same pixels as that constant, and a checkerboard of two values renders,
 * pixel by pixel, what the two constants render in its squares. Small pbrt
 * scenes from memory: a textured square seen straight on by an orthographic
 * camera, lit by a point light and a spherical area light in front and a
 * point light behind (for transmission).
 */
#include "test.h"

#include "paprsek.h"

#include <math.h>
#include <stdbool.h>
#include <stdio.h>
#include <string.h>

enum { W = 32, H = 32, SPP = 8 };

static pk_image *render_text(pk_context *ctx, const char *format, const char *scene)
{
    pk_scene *s = NULL;
    if (pk_scene_load_memory(ctx, format, scene, strlen(scene), NULL, NULL, &s) != PK_OK) {
        fprintf(stderr, "%s\n%s\n", scene, pk_context_error(ctx));
        test_failures++;
        return NULL;
    }
    pk_render_options o;
    pk_scene_get_render_options(s, &o);
    o.width = W, o.height = H, o.spp = SPP, o.threads = 1, o.seed = 7;
    pk_image *img = NULL;
    if (pk_render(ctx, s, &o, &img, NULL) != PK_OK) {
        fprintf(stderr, "%s\n", pk_context_error(ctx));
        test_failures++;
    }
    pk_scene_destroy(s);
    return img;
}

/* The pbrt scene around a material (its directives). */
static pk_image *render(pk_context *ctx, const char *material)
{
    char scene[4096];
    snprintf(scene, sizeof scene,
             "LookAt 0 0 5  0 0 0  0 1 0\n"
             "Camera \"orthographic\" \"float screenwindow\" [-1 1 -1 1]\n"
             "Film \"rgb\" \"integer xresolution\" [%d] \"integer yresolution\" [%d] \"string filename\" \"x.exr\"\n"
             "Sampler \"independent\" \"integer pixelsamples\" [%d]\n"
             "Integrator \"path\" \"integer maxdepth\" [3]\n"
             "WorldBegin\n"
             "LightSource \"point\" \"point3 from\" [0.4 0.3 2] \"rgb I\" [4 4 4]\n"
             "LightSource \"point\" \"point3 from\" [0 0 -1] \"rgb I\" [2 2 2]\n"
             "AttributeBegin\n"
             "AreaLightSource \"diffuse\" \"rgb L\" [3 3 3]\n"
             "Translate -0.3 0.2 2.5\n"
             "Shape \"sphere\" \"float radius\" [0.4]\n"
             "AttributeEnd\n"
             "%s\n"
             "Shape \"trianglemesh\" \"point3 P\" [-1 -1 0  1 -1 0  1 1 0  -1 1 0] \"integer indices\" [0 1 2 0 2 3]\n"
             "  \"point2 uv\" [0 0 1 0 1 1 0 1]\n",
             W, H, SPP, material);
    return render_text(ctx, "pbrt", scene);
}

/* The same in a Mitsuba scene around a bsdf element on a rectangle. */
static pk_image *render_xml(pk_context *ctx, const char *bsdf)
{
    char scene[4096];
    snprintf(scene, sizeof scene,
             "<scene version=\"3.0.0\">\n"
             "<sensor type=\"orthographic\"><transform name=\"to_world\"><lookat origin=\"0,0,5\" target=\"0,0,0\" "
             "up=\"0,1,0\"/></transform>\n"
             "<film type=\"hdrfilm\"><integer name=\"width\" value=\"%d\"/><integer name=\"height\" value=\"%d\"/>"
             "</film></sensor>\n"
             "<emitter type=\"point\"><point name=\"position\" x=\"0.4\" y=\"0.3\" z=\"2\"/><rgb name=\"intensity\" "
             "value=\"4\"/></emitter>\n"
             "<emitter type=\"point\"><point name=\"position\" x=\"0\" y=\"0\" z=\"-1\"/><rgb name=\"intensity\" "
             "value=\"2\"/></emitter>\n"
             "<shape type=\"rectangle\">%s</shape>\n"
             "</scene>\n",
             W, H, bsdf);
    return render_text(ctx, "xml", scene);
}

static bool same_px(const float *a, const float *b, int i)
{
    for (int c = 0; c < 3; c++)
        if (fabsf(a[3 * i + c] - b[3 * i + c]) > 1e-5f * fmaxf(1.0f, fabsf(b[3 * i + c]))) return false;
    return true;
}

/* A texture of one value renders what the constant renders. */
static void check_same_images(const char *what, pk_image *a, pk_image *b)
{
    if (a && b) {
        const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b);
        int differ = 0;
        double sum = 0.0;
        for (int i = 0; i < W * H; i++) {
            differ += !same_px(pa, pb, i);
            sum += (double)pa[3 * i] + (double)pa[3 * i + 1] + (double)pa[3 * i + 2];
        }
        CHECKF(differ == 0, "%s: %d of %d pixels differ from the constant's", what, differ, W * H);
        CHECKF(sum > 0.01 * W * H, "%s: the image is black (%g)", what, sum);
    }
    pk_image_destroy(a);
    pk_image_destroy(b);
}

static void check_same(pk_context *ctx, const char *what, const char *constant, const char *textured)
{
    check_same_images(what, render(ctx, constant), render(ctx, textured));
}

/* A checkerboard of two values renders, pixel by pixel, what one of the two
 * constants renders: the pixels that tell the two apart split between them
 * as the squares do (half each), and the rest (the squares' edges, where a
 * pixel's samples fall on both sides) is a thin share. */
static void check_checker(pk_context *ctx, const char *what, const char *mat_a, const char *mat_b,
                          const char *checker)
{
    pk_image *a = render(ctx, mat_a), *b = render(ctx, mat_b), *c = render(ctx, checker);
    if (a && b && c) {
        const float *pa = pk_image_pixels_const(a), *pb = pk_image_pixels_const(b), *pc = pk_image_pixels_const(c);
        int distinct = 0, as_a = 0, as_b = 0;
        for (int i = 0; i < W * H; i++) {
            if (same_px(pa, pb, i)) continue;
            distinct++;
            as_a += same_px(pc, pa, i);
            as_b += same_px(pc, pb, i);
        }
        CHECKF(distinct > W * H / 2, "%s: the two constants differ at only %d pixels", what, distinct);
        /* 4 x 4 squares over 32 x 32 pixels: the edges are at most 6 lines of pixels (6 x 32 of 1024) */
        CHECKF(as_a + as_b >= distinct - 6 * W, "%s: %d + %d of %d pixels are one of the two constants", what, as_a,
               as_b, distinct);
        CHECKF(as_a > distinct / 3 && as_b > distinct / 3, "%s: %d and %d of %d pixels (squares: half each)", what,
               as_a, as_b, distinct);
    }
    pk_image_destroy(a);
    pk_image_destroy(b);
    pk_image_destroy(c);
}

int main(void)
{
    pk_context *ctx = NULL;
    REQUIRE(pk_context_create(NULL, &ctx) == PK_OK);

    /* one value as a texture (a checkerboard of two equal squares) */
    check_same(ctx, "conductor reflectance",
               "Material \"conductor\" \"rgb reflectance\" [0.9 0.6 0.3] \"float roughness\" [0.2]",
               "Texture \"t\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [0.9 0.6 0.3] \"rgb tex2\" [0.9 0.6 0.3]\n"
               "Material \"conductor\" \"texture reflectance\" \"t\" \"float roughness\" [0.2]");
    check_same(ctx, "conductor eta and k",
               "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" "
               "\"float roughness\" [0.2]",
               "Texture \"e\" \"spectrum\" \"checkerboard\" \"spectrum tex1\" \"metal-Au-eta\" "
               "\"spectrum tex2\" \"metal-Au-eta\"\n"
               "Texture \"k\" \"spectrum\" \"checkerboard\" \"spectrum tex1\" \"metal-Au-k\" \"spectrum tex2\" "
               "\"metal-Au-k\"\n"
               "Material \"conductor\" \"texture eta\" \"e\" \"texture k\" \"k\" \"float roughness\" [0.2]");
    check_same(ctx, "transmittance",
               "Material \"diffusetransmission\" \"rgb transmittance\" [0.2 0.7 0.4]",
               "Texture \"t\" \"spectrum\" \"checkerboard\" \"rgb tex1\" [0.2 0.7 0.4] \"rgb tex2\" [0.2 0.7 0.4]\n"
               "Material \"diffusetransmission\" \"texture transmittance\" \"t\"");

    /* two values in a 4 x 4 checkerboard */
    check_checker(ctx, "roughness",
                  "Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\" "
                  "\"float roughness\" [0.05]",
                  "Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\" "
                  "\"float roughness\" [0.5]",
                  "Texture \"r\" \"float\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                  "\"float tex1\" [0.05] \"float tex2\" [0.5]\n"
                  "Material \"conductor\" \"spectrum eta\" \"metal-Ag-eta\" \"spectrum k\" \"metal-Ag-k\" "
                  "\"texture roughness\" \"r\"");
    check_checker(ctx, "conductor eta and k",
                  "Material \"conductor\" \"spectrum eta\" \"metal-Au-eta\" \"spectrum k\" \"metal-Au-k\" "
                  "\"float roughness\" [0.3]",
                  "Material \"conductor\" \"spectrum eta\" \"metal-CuZn-eta\" \"spectrum k\" \"metal-CuZn-k\" "
                  "\"float roughness\" [0.3]",
                  "Texture \"e\" \"spectrum\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                  "\"spectrum tex1\" \"metal-Au-eta\" \"spectrum tex2\" \"metal-CuZn-eta\"\n"
                  "Texture \"k\" \"spectrum\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                  "\"spectrum tex1\" \"metal-Au-k\" \"spectrum tex2\" \"metal-CuZn-k\"\n"
                  "Material \"conductor\" \"texture eta\" \"e\" \"texture k\" \"k\" \"float roughness\" [0.3]");
    check_checker(ctx, "transmittance", "Material \"diffusetransmission\" \"rgb transmittance\" [0.9 0.9 0.9]",
                  "Material \"diffusetransmission\" \"rgb transmittance\" [0.1 0.5 0.2]",
                  "Texture \"t\" \"spectrum\" \"checkerboard\" \"float uscale\" [2] \"float vscale\" [2] "
                  "\"rgb tex1\" [0.9 0.9 0.9] \"rgb tex2\" [0.1 0.5 0.2]\n"
                  "Material \"diffusetransmission\" \"texture transmittance\" \"t\"");

    /* Mitsuba: a conductor's eta and k, a dielectric's transmittance */
    check_same_images("Mitsuba conductor eta and k",
                      render_xml(ctx, "<bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0.3\"/>"
                                      "<rgb name=\"eta\" value=\"0.2, 0.9, 1.1\"/><rgb name=\"k\" value=\"3.9, 2.4, 2.1\"/>"
                                      "</bsdf>"),
                      render_xml(ctx, "<bsdf type=\"roughconductor\"><float name=\"alpha\" value=\"0.3\"/>"
                                      "<texture type=\"checkerboard\" name=\"eta\"><rgb name=\"color0\" value=\"0.2, 0.9, 1.1\"/>"
                                      "<rgb name=\"color1\" value=\"0.2, 0.9, 1.1\"/></texture>"
                                      "<texture type=\"checkerboard\" name=\"k\"><rgb name=\"color0\" value=\"3.9, 2.4, 2.1\"/>"
                                      "<rgb name=\"color1\" value=\"3.9, 2.4, 2.1\"/></texture></bsdf>"));
    check_same_images("Mitsuba transmittance",
                      render_xml(ctx, "<bsdf type=\"roughdielectric\"><float name=\"alpha\" value=\"0.3\"/>"
                                      "<rgb name=\"specular_transmittance\" value=\"0.3, 0.8, 0.5\"/></bsdf>"),
                      render_xml(ctx, "<bsdf type=\"roughdielectric\"><float name=\"alpha\" value=\"0.3\"/>"
                                      "<texture type=\"checkerboard\" name=\"specular_transmittance\">"
                                      "<rgb name=\"color0\" value=\"0.3, 0.8, 0.5\"/><rgb name=\"color1\" value=\"0.3, 0.8, 0.5\"/>"
                                      "</texture></bsdf>"));

    pk_context_destroy(ctx);
    return test_done("test_textured_params");
}
