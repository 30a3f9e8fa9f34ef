/*
 * cli.h - the pieces of the paprsek program, built on include/paprsek.h alone.
 *
 * Exit statuses, the same for every command: 0 success, 1 a runtime failure
 * (a file that cannot be read or written, a malformed scene, a scene beyond
 * the limits), 2 a usage error (unknown option, bad value, unknown image
 * format), 128 + the signal's number when a render is interrupted (130 for
 * SIGINT, 143 for SIGTERM).
 */
#ifndef PK_CLI_H
#define PK_CLI_H

#include "paprsek.h"

#include <stdint.h>
#include <stdio.h>

enum { CLI_EXIT_OK = 0, CLI_EXIT_FAILURE = 1, CLI_EXIT_USAGE = 2 };

/* `paprsek render ...` (cli/render.c). argv[0] is "render". Returns the exit status. */
int cli_render(int argc, char **argv);
void cli_render_help(FILE *f);
/* `paprsek bench rays|gen-rays|compare ...` (cli/bench.c). argv[0] is "bench". */
int cli_bench(int argc, char **argv);
void cli_bench_help(FILE *f);

/* `paprsek convert SCENE -o OUT.json` (cli/convert.c). argv[0] is "convert". */
int cli_convert(int argc, char **argv);
void cli_convert_help(FILE *f);

/* ---- options (cli/options.c) ----------------------------------------------
 * One table per command serves parsing (getopt_long: --name VALUE,
 * --name=VALUE, unique abbreviations, -o VALUE), the range checks of its
 * integer options and its --help text. */

typedef enum cli_kind {
    CLI_FLAG,   /* no value */
    CLI_STRING, /* a value, checked by the command */
    CLI_INT     /* a whole number in min..max, checked by the parser */
} cli_kind;

typedef struct cli_option {
    const char *name;  /* long name without "--" */
    int short_name;    /* 'o', or 0 */
    int id;            /* the command's own number for it */
    cli_kind kind;
    const char *arg;   /* the value's name in --help ("FILE"); NULL for flags */
    const char *help;  /* one sentence; --help wraps it */
    int min, max, default_value; /* CLI_INT: range and default, shown by --help */
    const pk_int_option *render; /* the library's entry when it is a render option */
} cli_option;

/* An integer render option of the library's table (pk_int_options) as a
 * command-line option: --light-samples for light_samples. name_buf holds
 * the name (at least 64 bytes) and must live as long as the option. */
cli_option cli_option_from_render(const pk_int_option *o, char *name_buf, size_t cap);

/* cli_next's answers */
enum { CLI_END = 0, CLI_OPTION, CLI_ARGUMENT, CLI_ERROR };

typedef struct cli_parser {
    const char *cmd; /* "render", "bench rays": in messages */
    const cli_option *opts;
    size_t n;
    int argc;
    char **argv;
    int rest;        /* after "--": the next argument to return */
    /* the answer of the last cli_next */
    int index;         /* CLI_OPTION: opts[index] */
    const char *value; /* CLI_OPTION: its value (NULL for flags); CLI_ARGUMENT: the argument */
    int int_value;     /* CLI_OPTION of kind CLI_INT: the checked number */
} cli_parser;

/* argv[0] is the command's own name and is skipped. At most 64 options. */
void cli_parser_init(cli_parser *p, const char *cmd, const cli_option *opts, size_t n, int argc, char **argv);
/* The next option or argument, in command-line order; CLI_ERROR after a
 * message on stderr (a usage error: exit status 2); CLI_END at the end. */
int cli_next(cli_parser *p);
/* The option list of --help: one entry per option, the help wrapped to 80
 * columns, the range and default of integer options appended. */
void cli_print_options(FILE *f, const cli_option *opts, size_t n);
/* The entry of names[0..n-1] nearest to word[0..len-1] by edit distance
 * (a swap of two neighbours counts one), or NULL when none is near enough
 * to be a likely typing mistake. */
const char *cli_nearest(const char *word, size_t len, const char *const *names, size_t n);

/* ---- the render options, checks and outputs (cli/render_common.c) --------
 * Shared by `paprsek render` and paprsek-mpi. */

#define CLI_RENDER_MAX_OPTIONS 64
#define CLI_RENDER_MAX_EXTRA 8
enum { CLI_RENDER_EXTRA = 100 }; /* ids of a program's own options: CLI_RENDER_EXTRA + k */

typedef struct cli_render_opts {
    const char *scene, *out, *stats_json;
    int has_exposure;
    float exposure;
    int tonemap;         /* --tonemap: PK_TONEMAP_* (0, clamp, when not given) */
    int transparent;     /* --transparent */
    int has_orbit;       /* --camera-orbit THETA,PHI,RADIUS (RADIUS 0: auto) */
    float orbit[3];
    int stats, quiet;
    int int_set[CLI_RENDER_MAX_OPTIONS]; /* per table entry: given on the command line */
    int int_value[CLI_RENDER_MAX_OPTIONS];
    int fresnel;         /* -1: not given */
    int energy;          /* --energy-compensation: -1 not given */
    int has_clamp_indirect;
    float clamp_indirect;
    int has_filter;
    pk_filter filter;
    int has_accel;
    pk_accel_kind accel;
    int has_device;
    pk_device_kind device;
    const char *config;  /* --config, NULL when not given */
    int has_integrator;
    pk_integrator_kind integrator;
    double time;         /* --time: seconds of passes, 0 when not given */
    double noise;        /* --noise: the adaptive sampling's target, 0 when not given */
    int min_spp;         /* --min-spp, 0 when not given */
    unsigned aovs;       /* --aov: PK_AOV_* */
    int has_from, has_at, has_up, has_fov;
    float from[3], at[3], up[3], fov;
    int has_lens_radius, has_focus_distance;
    float lens_radius, focus_distance;
    int projection;      /* pk_projection + 1, 0 when neither --orthographic nor --perspective is given */
    float ortho_width;   /* --orthographic WIDTH */
    const char *env;     /* --env, NULL when not given */
    const char *defines[64]; /* -D NAME=VALUE */
    size_t ndefines;
    int has_camera_pick; /* --camera N (passed on as the parameter camera=N) */
    int has_variant;     /* --variant NAME (passed on as the parameter variant=NAME) */
    int denoise;         /* --denoise 1, --no-denoise 0, -1 when neither is given */
    int denoise_fast;    /* --denoise-quality fast */
    const char *weights; /* --weights DIR, NULL when not given */
    /* a program's own options (cli_render_add_option): the value given ("" for
     * a flag), NULL when absent */
    const char *extra[CLI_RENDER_MAX_EXTRA];
} cli_render_opts;

/* Adds an option of a program's own (id CLI_RENDER_EXTRA + k) to the table,
 * before --help; only before the table is first used. */
void cli_render_add_option(cli_option o);
/* The table: -o, the library's integer options, the rest. */
const cli_option *cli_render_options(size_t *n);
/* The help of the render options after usage_line. */
void cli_render_usage(FILE *f, const char *usage_line);
/* Parses the arguments (argv[0] is the command's name). Returns 0 to go
 * on, -1 after --help was printed by help (exit 0), or an exit status after
 * a message. */
int cli_render_parse(int argc, char **argv, cli_render_opts *o, void (*help)(FILE *f));
/* What would fail only after the render: OUT's format and folder, files
 * written over the scene, --stats-json's file. Fills *wo (the exposure).
 * Returns 0 or an exit status after a message. */
int cli_render_check(const cli_render_opts *o, pk_write_options *wo);
/* The scene's render settings with the command line's over them (collect_stats
 * when statistics are asked for), checked; --env and the camera options
 * applied to scene (--env FILE reads the file through ctx). */
pk_status cli_render_settings(pk_context *ctx, const cli_render_opts *o, pk_scene *scene, pk_render_options *ro);
/* The samples per pixel of a render that names none (neither --spp nor
 * --time nor the scene file): enough for the denoiser to give a clean
 * image (docs/denoising.md says how it was chosen). */
#define CLI_CLEAN_SPP 16
/* Non-zero when --spp was given. */
int cli_render_spp_given(const cli_render_opts *o);
/* Non-zero when the render is the default one: no --spp, no --time, no
 * --noise, no sample count in the scene. It then takes CLI_CLEAN_SPP
 * samples and is denoised unless --no-denoise. */
int cli_render_clean_default(const cli_render_opts *o, const pk_scene *scene);

/* ---- denoising (cli/denoise.c) ------------------------------------------- */

/* `paprsek denoise IN -o OUT ...`. argv[0] is "denoise". */
int cli_denoise(int argc, char **argv);
void cli_denoise_help(FILE *f);
/* The folder of the weights when none is named: beside the program
 * (weights/, where the build puts them) or ../share/paprsek/weights from
 * it (an installed program); NULL when neither holds them (the library's
 * own default then applies). */
const char *cli_weights_dir(void);
/* What the render asks of the denoiser: 1 denoise, 0 not. When it should
 * but cannot (no weights, no oneDNN), an explicit --denoise is a failure
 * (returns -1 after the message); the default render warns and stays raw. */
int cli_render_wants_denoise(pk_context *ctx, const cli_render_opts *o, const pk_scene *scene,
                             pk_denoise_options *dopt);
/* img = img denoised with the albedo and normal of film; seconds, bytes and
 * flops of the denoiser for --stats. */
pk_status cli_render_denoise(pk_context *ctx, const pk_denoise_options *dopt, const pk_film *film, pk_image *img,
                             double *seconds, size_t *bytes, double *flops);
/* Writes OUT (through pk_image_write_ex: a temporary file renamed into place)
 * and the AOVs of --aov from film. */
pk_status cli_render_write(pk_context *ctx, const cli_render_opts *o, const pk_write_options *wo,
                           const pk_image *img, const pk_film *film);
/* "dir/name.png" -> "dir/name.partial.png" (malloc'ed; NULL when out of memory) */
char *cli_partial_name(const char *out);
/* The statistics table of --stats on standard output (sc: its textures). */
void cli_print_stats(pk_context *ctx, const char *scene, const pk_scene *sc, const pk_render_options *ro,
                     const pk_stats *st);
/* What the denoiser of a render took (pk_denoiser_last_run). */
typedef struct cli_denoise_stats {
    int done;        /* the image was denoised */
    int fast;        /* with the small network */
    double seconds, flops;
    size_t bytes;
} cli_denoise_stats;
/* The denoise row of --stats (nothing when dn->done is 0). */
void cli_print_denoise_stats(const cli_denoise_stats *dn);
/* --stats-json: path "-" is standard output; dn NULL or not done: the image
 * was not denoised. Returns 0 or 1 after a message. */
/* The adaptive sampling rows of --stats (nothing when ad is NULL). */
void cli_print_adaptive_stats(const pk_adaptive_result *ad, const pk_adaptive *a, const pk_render_options *ro);
/* ad and a: an adaptive render's result and settings (NULL: none) */
int cli_write_stats_json(pk_context *ctx, const char *path, const char *scene, const pk_scene *sc,
                         const pk_render_options *ro, const pk_stats *st, const cli_denoise_stats *dn,
                         const pk_adaptive_result *ad, const pk_adaptive *a);

/* ---- the progress bar (cli/progress.c) --------------------------------- */

typedef struct cli_progress {
    FILE *f;          /* stderr */
    int enabled;      /* f is a terminal and --quiet is not given */
    int drawn;        /* characters of the bar now on the line (0: none) */
    int last_permille;
    double last_elapsed;
    char note[32];    /* shown after the times ("pass 12"), empty by default */
} cli_progress;

/* enabled when f is a terminal (isatty) and quiet is 0. */
void cli_progress_init(cli_progress *p, FILE *f, int quiet);
/* A pk_progress_fn (user is the cli_progress): redraws the bar in place. */
int cli_progress_update(void *user, uint64_t done, uint64_t total, double elapsed_s);
/* Erases the bar, so that the next message starts a clean line. */
void cli_progress_clear(cli_progress *p);
/* The bar's text for a line of cols columns, without '\r': for the
 * terminal and for tests. Returns its length. */
int cli_progress_format(char *buf, size_t cap, int cols, uint64_t done, uint64_t total, double elapsed_s);
/* "0.42 s", "12.3 s", "4:05", "1:02:03" */
void cli_format_duration(char *buf, size_t cap, double s);

/* ---- shared helpers (cli/util.c) ------------------------------------------ */

/* The name that begins messages: "paprsek" (paprsek-mpi sets its own). */
extern const char *cli_program;

/* Prints "<cli_program>: <ctx error>" to stderr and returns 1. */
int cli_fail_ctx(pk_context *ctx);
/* Prints "paprsek: <fmt>" to stderr and returns 2 (usage errors). */
int cli_usage_error(const char *fmt, ...);
/* Prints "paprsek: <fmt>" to stderr and returns 1 (runtime failures). */
int cli_failure(const char *fmt, ...);
/* Parses an int in [lo, hi]; false on junk or out of range. */
int cli_parse_int(const char *s, long lo, long hi, int *out);
/* Parses "x,y,z"; false on junk or non-finite values. */
int cli_parse_vec3(const char *s, float out[3]);
/* Prints warnings from the library to stderr as "paprsek: warning: ...". */
void cli_print_warning(void *user, const char *message);
/* Checks, before any work, that a file can be written at path: path is not
 * a folder, its folder exists and is one, and this process may create files
 * there (access W_OK). With replace_by_rename 0 (a file opened for writing
 * in place), an existing path that is writable is enough. Creates nothing.
 * Prints "paprsek: path: why" and returns 1 when it cannot; else 0. */
int cli_check_output(const char *path, int replace_by_rename);
/* Seconds on a monotonic clock. */
double cli_now(void);
/* The library's config for ctx (pk_context_set_config): the environment
 * variables the program has always read, passed on as their keys
 * (PAPRSEK_CPU_ISA=avx2: cpu.isa, PAPRSEK_BVH_QUALITY=fast: bvh.quality,
 * PAPRSEK_EMBREE_QUALITY: embree.quality, PAPRSEK_EMBREE_LIBRARY:
 * embree.library, PAPRSEK_CUDA_LIBRARY: cuda.library), then config (--config;
 * may be NULL), whose keys win. Returns 0, or 2 after a message naming the
 * variable or --config. */
int cli_configure(pk_context *ctx, const char *config);
/* cli_configure on a context of its own: for checking before any work. */
int cli_check_config(const char *config);

#endif
