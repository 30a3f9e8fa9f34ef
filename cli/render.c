/*
 * render.c - `paprsek render`: loads a scene (or the built-in Cornell box),
 * applies the command-line overrides, checks that the outputs can be
 * written, renders with a progress bar on a terminal, writes the image and
 * prints the statistics table. SIGINT/SIGTERM stop the render cleanly.
 */
#include "cli.h"

#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static volatile sig_atomic_t g_stop; /* set by the signal handler only */
static volatile int g_cancel;        /* the render's cancel flag (an int in the API) */
_Static_assert(sizeof(sig_atomic_t) == sizeof(int), "the cancel flag is written by a signal handler");

static void on_signal(int sig)
{
    g_stop = sig;
    g_cancel = 1;
}

/* Warnings of the library, on a line of their own (the bar, if drawn, is
 * erased first and redrawn by its next report). */
static void print_warning(void *user, const char *message)
{
    cli_progress_clear(user);
    cli_print_warning(NULL, message);
}


/* --time: passes of ro->spp samples into one film until seconds have
 * passed; the bar shows the time spent and the passes done. */
static pk_status render_passes(pk_context *ctx, const pk_scene *scene, pk_render_options *ro, double seconds,
                               unsigned aovs, cli_progress *bar, pk_image **img, pk_film **film_out,
                               pk_stats *stats, uint32_t *passes)
{
    if (seconds > 0.0) ro->progress = NULL; /* the bar follows the passes, not the tiles */
    pk_renderer *r = NULL;
    pk_film *film = NULL;
    *img = NULL;
    pk_status st = pk_renderer_create(ctx, scene, ro, &r);
    if (st == PK_OK) st = pk_film_create_aovs(ctx, ro->width, ro->height, aovs, &film);
    const double t0 = cli_now();
    uint32_t k = 0;
    while (st == PK_OK) {
        pk_renderer_set_pass(r, k);
        st = pk_renderer_render(r, NULL, 0, film);
        if (st != PK_OK) break;
        k++;
        if (seconds <= 0.0) break; /* one pass */
        const double el = cli_now() - t0;
        snprintf(bar->note, sizeof bar->note, "pass %u", k);
        cli_progress_update(bar, (uint64_t)(el < seconds ? el * 1000.0 : seconds * 1000.0),
                            (uint64_t)(seconds * 1000.0), el);
        if (el >= seconds || k == UINT32_MAX / (uint32_t)ro->spp) break;
    }
    *passes = k;
    if ((st == PK_OK || st == PK_ERR_CANCELLED) && film) {
        pk_status rs = pk_film_resolve(ctx, film, img);
        if (rs != PK_OK) st = rs;
    }
    if (r) pk_renderer_get_stats(r, stats);
    *film_out = film;
    pk_renderer_destroy(r);
    return st;
}
/* --noise: adaptive sampling into a film of its own (passes of ro->spp,
 * until the tiles reach the target, --spp's maximum or --time). */
static pk_status render_adaptive(pk_context *ctx, const pk_scene *scene, const pk_render_options *ro,
                                 const pk_adaptive *a, unsigned aovs, pk_image **img, pk_film **film_out,
                                 pk_stats *stats, pk_adaptive_result *res)
{
    pk_renderer *r = NULL;
    pk_film *film = NULL;
    *img = NULL;
    pk_status st = pk_renderer_create(ctx, scene, ro, &r);
    if (st == PK_OK) st = pk_film_create_aovs(ctx, ro->width, ro->height, aovs, &film);
    if (st == PK_OK) st = pk_renderer_render_adaptive(r, a, film, res);
    if ((st == PK_OK || st == PK_ERR_CANCELLED) && film) {
        pk_status rs = pk_film_resolve(ctx, film, img);
        if (rs != PK_OK) st = rs;
    }
    if (r) pk_renderer_get_stats(r, stats);
    *film_out = film;
    pk_renderer_destroy(r);
    return st;
}

void cli_render_help(FILE *f) { cli_render_usage(f, "usage: paprsek render [SCENE] -o OUT [options]\n"); }

int cli_render(int argc, char **argv)
{
    const double t0 = cli_now();
    cli_render_opts o;
    int rc = cli_render_parse(argc, argv, &o, cli_render_help);
    if (rc) return rc < 0 ? 0 : rc;
    /* Everything that would only fail after the render is checked first. */
    pk_write_options wo;
    if ((rc = cli_render_check(&o, &wo)) != 0) return rc;

    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) {
        fprintf(stderr, "paprsek: out of memory\n");
        return 1;
    }
    pk_scene *scene = NULL;
    pk_image *img = NULL;
    pk_film *film = NULL; /* --time and --aov render into a film of their own */
    cli_progress bar;
    cli_progress_init(&bar, stderr, o.quiet);
    if (!o.quiet) pk_context_set_warning_handler(ctx, print_warning, &bar);
    rc = 1;
    /* the back ends' settings before the scene: scene.instances decides what loading keeps */
    if ((rc = cli_configure(ctx, o.config)) != 0) goto out;
    rc = 1;
    pk_status st = o.scene ? pk_scene_load_file_params(ctx, o.scene, o.defines, o.ndefines, &scene)
                           : pk_scene_create_cornell_box(ctx, &scene);
    if (st != PK_OK) goto fail;

    pk_render_options ro;
    if (cli_render_settings(ctx, &o, scene, &ro) != PK_OK) goto fail;
    ro.cancel = &g_cancel;
    ro.progress = cli_progress_update;
    ro.progress_user = &bar;

    struct sigaction sa;
    memset(&sa, 0, sizeof sa);
    sa.sa_handler = on_signal;
    sigaction(SIGINT, &sa, NULL);
    sigaction(SIGTERM, &sa, NULL);

    pk_denoise_options dopt;
    const int denoise = cli_render_wants_denoise(ctx, &o, scene, &dopt);
    if (denoise < 0) goto out;
    /* the denoiser takes the albedo and normal of the same render */
    const unsigned aovs =
        o.aovs | (denoise ? PK_AOV_ALBEDO | PK_AOV_NORMAL : 0u) | (o.transparent ? PK_AOV_ALPHA : 0u);

    pk_stats stats;
    uint32_t passes = 1;
    pk_adaptive ad;
    pk_adaptive_result adr;
    memset(&adr, 0, sizeof adr);
    pk_adaptive_init(&ad);
    if (o.noise > 0.0) {
        /* passes of one sample; --spp, when given, is the most a pixel gets */
        ad.noise = (float)o.noise;
        if (o.min_spp) ad.min_spp = o.min_spp;
        if (cli_render_spp_given(&o)) ad.max_spp = ro.spp;
        if (ad.max_spp < ad.min_spp) ad.min_spp = ad.max_spp;
        ad.seconds = o.time;
        ro.spp = 1;
        ro.progress = NULL; /* (the tiles of each pass are not the render's) */
        st = render_adaptive(ctx, scene, &ro, &ad, aovs, &img, &film, &stats, &adr);
        passes = adr.passes;
    } else if (o.time > 0.0 || aovs)
        st = render_passes(ctx, scene, &ro, o.time, aovs, &bar, &img, &film, &stats, &passes);
    else
        st = pk_render(ctx, scene, &ro, &img, &stats);
    cli_denoise_stats dn = {0, o.denoise_fast, 0.0, 0.0, 0};
    if (st == PK_OK && denoise) {
        snprintf(bar.note, sizeof bar.note, "denoising");
        cli_progress_update(&bar, 999, 1000, cli_now() - t0);
        st = cli_render_denoise(ctx, &dopt, film, img, &dn.seconds, &dn.bytes, &dn.flops);
        dn.done = st == PK_OK;
    }
    cli_progress_clear(&bar);
    if (st == PK_ERR_CANCELLED) {
        char *partial = cli_partial_name(o.out);
        if (partial && img && pk_image_write_ex(ctx, img, partial, &wo) == PK_OK)
            fprintf(stderr, "paprsek: interrupted; finished tiles written to %s\n", partial);
        else
            fprintf(stderr, "paprsek: interrupted\n");
        free(partial);
        /* 128 + the signal, as a shell reports a process the signal ended */
        rc = 128 + (g_stop ? (int)g_stop : SIGINT);
        goto out;
    }
    if (st != PK_OK) goto fail;
    if (cli_render_write(ctx, &o, &wo, img, film) != PK_OK) goto fail;
    if (bar.enabled) {
        char took[32];
        cli_format_duration(took, sizeof took, cli_now() - t0);
        if (o.noise > 0.0)
            fprintf(stderr, "wrote %s (%dx%d, adaptive: %.1f spp on average, %u to %u%s, %s)\n", o.out, ro.width,
                    ro.height, (double)adr.samples / ((double)ro.width * (double)ro.height), adr.min_spp, adr.max_spp,
                    denoise ? ", denoised" : "", took);
        else if (o.time > 0.0)
            fprintf(stderr, "wrote %s (%dx%d, %u passes of %d spp%s, %s)\n", o.out, ro.width, ro.height, passes,
                    ro.spp, denoise ? ", denoised" : "", took);
        else
            fprintf(stderr, "wrote %s (%dx%d, %d spp%s, %s)\n", o.out, ro.width, ro.height, ro.spp,
                    denoise ? ", denoised" : "", took);
    }
    const char *name = o.scene ? o.scene : "cornell-box (built in)";
    if (o.stats) {
        cli_print_stats(ctx, name, scene, &ro, &stats);
        if (o.noise > 0.0) cli_print_adaptive_stats(&adr, &ad, &ro);
        cli_print_denoise_stats(&dn);
    }
    if (o.stats_json && cli_write_stats_json(ctx, o.stats_json, name, scene, &ro, &stats, &dn,
                                                o.noise > 0.0 ? &adr : NULL, &ad) != 0)
        goto out;
    rc = 0;
    goto out;
fail:
    cli_progress_clear(&bar);
    rc = cli_fail_ctx(ctx);
out:
    pk_film_destroy(film);
    pk_image_destroy(img);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}
