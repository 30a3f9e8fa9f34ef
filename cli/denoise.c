/*
 * denoise.c - `paprsek denoise IN -o OUT`, and what `paprsek render` and
 * paprsek-mpi use to denoise a render: where the weights are, whether a
 * render is denoised, and the denoising of a film's image with its albedo
 * and normal.
 */
#include "cli.h"

#include <limits.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <unistd.h>

static int has_weights(const char *dir)
{
    char p[PATH_MAX + 64];
    snprintf(p, sizeof p, "%s/rt_hdr_alb_nrm.tza", dir);
    return access(p, R_OK) == 0;
}

const char *cli_weights_dir(void)
{
    static char dir[PATH_MAX + 32];
    static int done;
    if (done) return dir[0] ? dir : NULL;
    done = 1;
    char exe[PATH_MAX];
    ssize_t n = readlink("/proc/self/exe", exe, sizeof exe - 1);
    if (n <= 0) return NULL;
    exe[n] = '\0';
    char *slash = strrchr(exe, '/');
    if (!slash) return NULL;
    *slash = '\0';
    char cand[PATH_MAX + 32];
    snprintf(cand, sizeof cand, "%s/weights", exe);
    if (!has_weights(cand)) snprintf(cand, sizeof cand, "%s/../share/paprsek/weights", exe);
    if (!has_weights(cand)) return NULL;
    snprintf(dir, sizeof dir, "%s", cand);
    return dir;
}

static void fill_options(pk_denoise_options *d, const char *weights, int fast)
{
    pk_denoise_options_init(d);
    d->weights = weights ? weights : cli_weights_dir();
    d->quality = fast ? PK_DENOISE_FAST : PK_DENOISE_HIGH;
}

int cli_render_wants_denoise(pk_context *ctx, const cli_render_opts *o, const pk_scene *scene,
                             pk_denoise_options *dopt)
{
    fill_options(dopt, o->weights, o->denoise_fast);
    const int clean = cli_render_clean_default(o, scene);
    const int want = o->denoise == 1 || (o->denoise == -1 && clean);
    if (!want) return 0;
    pk_context *probe;
    if (pk_context_create(NULL, &probe) != PK_OK) return -1;
    pk_status st = pk_denoise_check(probe, dopt);
    if (st == PK_OK) {
        pk_context_destroy(probe);
        return 1;
    }
    if (o->denoise == 1) {
        cli_failure("%s", pk_context_error(probe));
        pk_context_destroy(probe);
        return -1;
    }
    char msg[1024];
    snprintf(msg, sizeof msg, "the image is not denoised (%d samples per pixel, raw): %s", CLI_CLEAN_SPP,
             pk_context_error(probe));
    pk_context_destroy(probe);
    if (!o->quiet) cli_print_warning(NULL, msg);
    (void)ctx;
    return 0;
}

pk_status cli_render_denoise(pk_context *ctx, const pk_denoise_options *dopt, const pk_film *film, pk_image *img,
                             double *seconds, size_t *bytes, double *flops)
{
    pk_image *alb = NULL, *nrm = NULL;
    pk_denoiser *d = NULL;
    pk_status st = pk_film_resolve_aov(ctx, film, PK_AOV_ALBEDO, &alb);
    if (st == PK_OK) st = pk_film_resolve_aov(ctx, film, PK_AOV_NORMAL, &nrm);
    if (st == PK_OK) st = pk_denoiser_create(ctx, dopt, &d);
    if (st == PK_OK) st = pk_denoiser_run(d, img, alb, nrm, img);
    if (st == PK_OK) pk_denoiser_last_run(d, seconds, bytes, flops);
    pk_denoiser_destroy(d);
    pk_image_destroy(alb);
    pk_image_destroy(nrm);
    return st;
}

/* ---- paprsek denoise ----------------------------------------------------- */

enum { D_OUTPUT = 1, D_ALBEDO, D_NORMAL, D_NO_AUX, D_WEIGHTS, D_QUALITY, D_CLEAN_AUX, D_THREADS, D_EXPOSURE,
       D_STATS, D_QUIET, D_HELP };

static const cli_option d_opts[] = {
    {.name = "output", .short_name = 'o', .id = D_OUTPUT, .kind = CLI_STRING, .arg = "FILE",
     .help = "the denoised image to write (required): .exr, .pfm or .png"},
    {.name = "albedo", .id = D_ALBEDO, .kind = CLI_STRING, .arg = "FILE",
     .help = "the albedo image (default: IN's layer albedo.R/G/B when IN is an OpenEXR file that has it)"},
    {.name = "normal", .id = D_NORMAL, .kind = CLI_STRING, .arg = "FILE",
     .help = "the normal image, world space, in -1..1 (default: IN's layer normal.R/G/B); needs an albedo"},
    {.name = "no-aux", .id = D_NO_AUX, .kind = CLI_FLAG,
     .help = "use the colour alone, even where IN has albedo and normal layers"},
    {.name = "clean-aux", .id = D_CLEAN_AUX, .kind = CLI_FLAG,
     .help = "the albedo and normal are free of noise (many samples): the network made for clean "
             "auxiliary images"},
    {.name = "quality", .id = D_QUALITY, .kind = CLI_STRING, .arg = "high|fast",
     .help = "the network: high (default) or fast (the small one, about 1.6x faster)"},
    {.name = "weights", .id = D_WEIGHTS, .kind = CLI_STRING, .arg = "DIR",
     .help = "the folder of the weights (default: beside the program, or the installed "
             "share/paprsek/weights)"},
    {.name = "threads", .id = D_THREADS, .kind = CLI_INT, .arg = "N", .help = "threads (0: all processors)",
     .min = 0, .max = 1024, .default_value = 0},
    {.name = "exposure", .id = D_EXPOSURE, .kind = CLI_STRING, .arg = "EV",
     .help = "PNG only: multiply the values by 2^EV before the tone curve (as paprsek render)"},
    {.name = "stats", .id = D_STATS, .kind = CLI_FLAG,
     .help = "print the denoiser's time, memory and speed on standard output"},
    {.name = "quiet", .short_name = 'q', .id = D_QUIET, .kind = CLI_FLAG, .help = "no warnings"},
    {.name = "help", .short_name = 'h', .id = D_HELP, .kind = CLI_FLAG, .help = "this text"},
};
#define D_NOPTS (sizeof d_opts / sizeof d_opts[0])

void cli_denoise_help(FILE *f)
{
    fputs("usage: paprsek denoise IN -o OUT [options]\n"
          "\n"
          "Denoises a rendered image with Open Image Denoise's trained network (run\n"
          "here on the CPU through oneDNN). IN is a linear HDR image (.exr, .pfm,\n"
          ".hdr); an OpenEXR IN written by `paprsek render --aov albedo,normal` holds\n"
          "the albedo and normal the network also takes, which make it much sharper.\n"
          "Pixels that are negative or not finite are taken as 0 (with a warning).\n"
          "\n"
          "options:\n",
          f);
    cli_print_options(f, d_opts, D_NOPTS);
    fputs("\nexit status: 0 the image was written; 1 a runtime failure (a file that\n"
          "cannot be read or written, missing weights or oneDNN); 2 a usage error.\n",
          f);
}

static int is_exr(const char *path)
{
    size_t n = strlen(path);
    return n >= 4 && strcasecmp(path + n - 4, ".exr") == 0;
}

int cli_denoise(int argc, char **argv)
{
    const char *in = NULL, *out = NULL, *albedo = NULL, *normal = NULL, *weights = NULL;
    int no_aux = 0, clean_aux = 0, fast = 0, threads = 0, stats = 0, quiet = 0, has_ev = 0;
    double ev = 0.0;
    cli_parser p;
    cli_parser_init(&p, "denoise", d_opts, D_NOPTS, argc, argv);
    int r;
    while ((r = cli_next(&p)) != CLI_END) {
        if (r == CLI_ERROR) return 2;
        if (r == CLI_ARGUMENT) {
            if (in) return cli_usage_error("denoise: more than one input ('%s' and '%s')", in, p.value);
            in = p.value;
            continue;
        }
        const char *v = p.value;
        switch (d_opts[p.index].id) {
        case D_OUTPUT: out = v; break;
        case D_ALBEDO: albedo = v; break;
        case D_NORMAL: normal = v; break;
        case D_NO_AUX: no_aux = 1; break;
        case D_CLEAN_AUX: clean_aux = 1; break;
        case D_WEIGHTS: weights = v; break;
        case D_QUALITY:
            if (strcmp(v, "high") && strcmp(v, "fast"))
                return cli_usage_error("--quality: expected high or fast, not '%s'", v);
            fast = strcmp(v, "fast") == 0;
            break;
        case D_THREADS: threads = p.int_value; break;
        case D_EXPOSURE: {
            char *end;
            ev = strtod(v, &end);
            if (*end || end == v || !(ev >= -PK_MAX_EXPOSURE_EV && ev <= PK_MAX_EXPOSURE_EV))
                return cli_usage_error("--exposure: '%s' must be a number of stops in %d..%d", v,
                                       -PK_MAX_EXPOSURE_EV, PK_MAX_EXPOSURE_EV);
            has_ev = 1;
            break;
        }
        case D_STATS: stats = 1; break;
        case D_QUIET: quiet = 1; break;
        case D_HELP: cli_denoise_help(stdout); return 0;
        }
    }
    if (!in) return cli_usage_error("denoise: no input image (paprsek denoise IN.exr -o OUT.exr)");
    if (!out) return cli_usage_error("denoise: no output file (-o OUT.exr)");
    if (normal && !albedo && (no_aux || !is_exr(in)))
        return cli_usage_error("denoise: --normal needs an albedo image too (--albedo FILE)");
    pk_write_options wo;
    pk_write_options_init(&wo);
    if (has_ev) wo.exposure_ev = (float)ev;
    if (cli_check_output(out, 1)) return 1;

    pk_context *ctx;
    if (pk_context_create(NULL, &ctx) != PK_OK) return cli_failure("out of memory");
    if (!quiet) pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    int rc = 1;
    pk_image *color = NULL, *alb = NULL, *nrm = NULL, *res = NULL;
    pk_denoiser *d = NULL;
    pk_denoise_options dopt;
    fill_options(&dopt, weights, fast);
    dopt.threads = threads;
    dopt.clean_aux = clean_aux;
    if (pk_image_read(ctx, in, NULL, &color) != PK_OK) goto fail;
    if (!no_aux) {
        if (albedo ? pk_image_read(ctx, albedo, NULL, &alb) != PK_OK
                   : is_exr(in) && pk_image_read(ctx, in, "albedo", &alb) != PK_OK) {
            if (albedo) goto fail;
            pk_context_clear_error(ctx); /* no layer: the colour alone */
        }
        if (alb && (normal ? pk_image_read(ctx, normal, NULL, &nrm) != PK_OK
                           : is_exr(in) && pk_image_read(ctx, in, "normal", &nrm) != PK_OK)) {
            if (normal) goto fail;
            pk_context_clear_error(ctx);
        }
    }
    if (pk_denoiser_create(ctx, &dopt, &d) != PK_OK) goto fail;
    if (pk_image_create(ctx, pk_image_width(color), pk_image_height(color), &res) != PK_OK) goto fail;
    if (pk_denoiser_run(d, color, alb, nrm, res) != PK_OK) goto fail;
    if (pk_image_write_ex(ctx, res, out, &wo) != PK_OK) goto fail;
    if (stats) {
        double s, fl;
        size_t bytes;
        pk_denoiser_last_run(d, &s, &bytes, &fl);
        printf("%-28s %s\n", "input", in);
        printf("%-28s %dx%d, %s%s, %s network\n", "denoised", pk_image_width(color), pk_image_height(color),
               alb ? "colour + albedo" : "colour alone", nrm ? " + normal" : "", fast ? "fast" : "high-quality");
        printf("%-28s %.3f\n", "denoise [s]", s);
        printf("%-28s %.1f\n", "denoise memory [MiB]", (double)bytes / (1024.0 * 1024.0));
        printf("%-28s %.1f\n", "GFLOP/s", s > 0 ? fl / s * 1e-9 : 0.0);
    }
    rc = 0;
    goto out;
fail:
    rc = cli_fail_ctx(ctx);
out:
    pk_denoiser_destroy(d);
    pk_image_destroy(color);
    pk_image_destroy(alb);
    pk_image_destroy(nrm);
    pk_image_destroy(res);
    pk_context_destroy(ctx);
    return rc;
}
