// app.cpp - paprsek.h from C++: the installed header compiles as C++ and the
// library links into a C++ program. Renders the built-in Cornell box at
// 32x32 and checks that the image is not black; prints nothing on success.
#include <paprsek.h>

#include <cstdio>
#include <memory>

namespace {

struct context_deleter {
    void operator()(pk_context *c) const { pk_context_destroy(c); }
};
struct scene_deleter {
    void operator()(pk_scene *s) const { pk_scene_destroy(s); }
};
struct image_deleter {
    void operator()(pk_image *i) const { pk_image_destroy(i); }
};

int fail(const char *what, pk_context *ctx)
{
    std::fprintf(stderr, "app.cpp: %s failed: %s\n", what, ctx ? pk_context_error(ctx) : "");
    return 1;
}

} // namespace

int main()
{
    pk_context *c = nullptr;
    if (pk_context_create(nullptr, &c) != PK_OK) return fail("pk_context_create", nullptr);
    std::unique_ptr<pk_context, context_deleter> ctx(c);

    pk_scene *s = nullptr;
    if (pk_scene_create_cornell_box(ctx.get(), &s) != PK_OK) return fail("pk_scene_create_cornell_box", ctx.get());
    std::unique_ptr<pk_scene, scene_deleter> scene(s);

    pk_render_options opt;
    pk_render_options_init(&opt);
    opt.width = 32;
    opt.height = 32;
    opt.light_samples = 4;
    opt.threads = 2;
    pk_image *i = nullptr;
    pk_status st = pk_render(ctx.get(), scene.get(), &opt, &i, nullptr);
    std::unique_ptr<pk_image, image_deleter> img(i);
    if (st != PK_OK) return fail("pk_render", ctx.get());

    const float *px = pk_image_pixels_const(img.get());
    const int n = 3 * pk_image_width(img.get()) * pk_image_height(img.get());
    bool lit = false;
    for (int k = 0; k < n; k++)
        if (px[k] > 0.0f) lit = true;
    if (n != 3 * 32 * 32 || !lit) {
        std::fprintf(stderr, "app.cpp: the image is %d values and %s\n", n, lit ? "lit" : "black");
        return 1;
    }
    return 0;
}
