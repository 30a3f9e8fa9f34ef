/*
 * view.c - `paprsek view`: loads a scene as `paprsek render` does (the same
 * options), starts the viewer's server (view_server.h), prints its address,
 * opens it in the desktop's browser when there is one, and serves until
 * SIGINT or SIGTERM.
 */
#include "cli.h"
#include "view_server.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <pthread.h>
#include <signal.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/wait.h>
#include <unistd.h>

enum { VIEW_PORT = 0, VIEW_BIND, VIEW_NO_OPEN };

static void add_view_options(void);

void cli_view_help(FILE *f)
{
    add_view_options();
    fputs("usage: paprsek view [SCENE] [options] [--port N] [--bind ADDR] [--no-open]\n"
          "\n"
          "Renders SCENE progressively and shows it in the browser: the program serves a\n"
          "page at http://127.0.0.1:PORT/ (the address is printed), opens it with the\n"
          "desktop's browser when there is one, and refines the image pass after pass (one\n"
          "sample per pixel each) until it has --spp samples per pixel (default 1024);\n"
          "it then waits for the next change. Any change starts again with a cheap pass\n"
          "(1 sample per pixel at a quarter of the size), then full-size passes.\n"
          "On the page: drag to orbit, shift-drag or right-drag to pan, the wheel to\n"
          "dolly, a click with Ctrl (or Alt) held to focus there; exposure, the tone\n"
          "curve, a transparent background (over a checkerboard), denoising, what is\n"
          "shown (colour, albedo, normal, depth, heat map), the integrator, and\n"
          "saving the image as PNG or EXR (docs/viewer.md).\n"
          "\n"
          "SCENE is a Wavefront .obj, a .json scene, a Mitsuba .xml scene, a pbrt-v4 .pbrt\n"
          "scene or a glTF 2.0 asset (.gltf, .glb); without it the built-in Cornell box.\n"
          "\n"
          "options (those of paprsek render that apply; --exposure, --tonemap,\n"
          "--transparent and --denoise set the\n"
          "page's first settings):\n",
          f);
    size_t n;
    const cli_option *opts = cli_render_options(&n);
    cli_option shown[64];
    size_t k = 0;
    static const char *const skip[] = {"output", "time", "aov", "stats", "stats-json"};
    for (size_t i = 0; i < n && k < 64; i++) {
        int drop = 0;
        for (size_t j = 0; j < sizeof skip / sizeof skip[0]; j++) drop |= strcmp(opts[i].name, skip[j]) == 0;
        if (strcmp(opts[i].name, "spp") == 0) {
            shown[k] = opts[i];
            shown[k].help = "the samples per pixel after which the image is left as it is (each pass adds one)";
            shown[k].default_value = VIEW_DEFAULT_MAX_SPP;
            k++;
            continue;
        }
        if (drop) continue;
        shown[k] = opts[i];
        if (strcmp(opts[i].name, "transparent") == 0)
            shown[k].help = "start with a transparent background: the environment the camera sees has alpha 0, "
                            "shown over a checkerboard (the page's checkbox turns it on and off)";
        if (strcmp(opts[i].name, "tonemap") == 0)
            shown[k].help = "the page's first tone curve of the PNG: clamp (default), agx, pbr-neutral, aces";
        if (strcmp(opts[i].name, "exposure") == 0)
            shown[k].help = "the page's first exposure: the linear values times 2^EV before the tone curve of the "
                            "PNG; a number in -20..20, default 0";
        k++;
    }
    cli_print_options(f, shown, k);
    fputs("\n"
          "Security: the server answers only requests that name it in their Host header\n"
          "and, for changes, come from its own page (Origin); with --bind other than a\n"
          "127.x.x.x address, every request needs the random token printed in the address.\n"
          "\n"
          "exit status: 0 after Ctrl-C (SIGINT) or SIGTERM, which end it within a second;\n"
          "1 a runtime failure (a scene that cannot be read, a port in use); 2 a usage\n"
          "error.\n",
          f);
}

static void add_view_options(void)
{
    static int done;
    if (done) return;
    done = 1;
    cli_render_add_option((cli_option){.name = "port", .id = CLI_RENDER_EXTRA + VIEW_PORT, .kind = CLI_STRING,
                                       .arg = "N",
                                       .help = "view: the port to listen on, 0..65535; 0 (default) takes a free one"});
    cli_render_add_option((cli_option){.name = "bind", .id = CLI_RENDER_EXTRA + VIEW_BIND, .kind = CLI_STRING,
                                       .arg = "ADDR",
                                       .help = "view: the IPv4 address to listen on (default 127.0.0.1, this machine "
                                               "only); another address makes every request need the printed token"});
    cli_render_add_option((cli_option){.name = "no-open", .id = CLI_RENDER_EXTRA + VIEW_NO_OPEN, .kind = CLI_FLAG,
                                       .help = "view: do not open the page in a browser"});
}

/* xdg-open URL, detached, its output dropped; when a desktop is there. */
static void open_browser(const char *url)
{
    const char *d = getenv("DISPLAY"), *w = getenv("WAYLAND_DISPLAY");
    if (!(d && *d) && !(w && *w)) return;
    pid_t pid = fork();
    if (pid == 0) {
        /* a grandchild runs it, so that nobody waits for the browser */
        if (fork() == 0) {
            const int fd = open("/dev/null", O_RDWR);
            if (fd >= 0) {
                dup2(fd, 0);
                dup2(fd, 1);
                dup2(fd, 2);
            }
            execlp("xdg-open", "xdg-open", url, (char *)NULL);
            _exit(127);
        }
        _exit(0);
    }
    if (pid > 0) waitpid(pid, NULL, 0);
}

int cli_view(int argc, char **argv)
{
    add_view_options();
    /* cli_render_parse wants an output: a stand-in, recognised by its address */
    static char stand_in[] = "view.png";
    char **args = calloc((size_t)argc + 3, sizeof *args);
    if (!args) return cli_failure("out of memory");
    args[0] = argv[0];
    args[1] = "-o";
    args[2] = stand_in;
    for (int i = 1; i < argc; i++) args[i + 2] = argv[i];
    cli_render_opts o;
    int rc = cli_render_parse(argc + 2, args, &o, cli_view_help);
    free(args);
    if (rc) return rc < 0 ? 0 : rc;
    if (o.out != stand_in) return cli_usage_error("view: --output does not apply (the page saves the image)");
    if (o.time > 0.0) return cli_usage_error("view: --time does not apply (the view refines until --spp)");
    if (o.aovs) return cli_usage_error("view: --aov does not apply (the page chooses what is shown)");
    if (o.stats || o.stats_json) return cli_usage_error("view: --stats and --stats-json do not apply");

    int port = 0;
    if (o.extra[VIEW_PORT] && !cli_parse_int(o.extra[VIEW_PORT], 0, 65535, &port))
        return cli_usage_error("--port: '%s' must be a port number in 0..65535", o.extra[VIEW_PORT]);
    const char *bind = o.extra[VIEW_BIND] ? o.extra[VIEW_BIND] : "127.0.0.1";
    struct in_addr ia;
    if (inet_pton(AF_INET, bind, &ia) != 1)
        return cli_usage_error("--bind: '%s' is not an IPv4 address (such as 127.0.0.1 or 0.0.0.0)", bind);
    if (o.has_camera_pick && (!o.scene || !pk_scene_format(o.scene) || strcmp(pk_scene_format(o.scene), "gltf") != 0))
        return cli_usage_error("--camera: picks a camera of a glTF asset (.gltf, .glb)");
    if (o.has_variant && (!o.scene || !pk_scene_format(o.scene) || strcmp(pk_scene_format(o.scene), "gltf") != 0))
        return cli_usage_error("--variant: picks a material variant of a glTF asset (.gltf, .glb)");

    /* SIGINT and SIGTERM are taken by sigwait below, in this thread only:
     * blocked before any thread starts (the library's too), as threads
     * inherit the mask */
    sigset_t set;
    sigemptyset(&set);
    sigaddset(&set, SIGINT);
    sigaddset(&set, SIGTERM);
    pthread_sigmask(SIG_BLOCK, &set, NULL);
    signal(SIGPIPE, SIG_IGN);

    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return cli_failure("out of memory");
    if (!o.quiet) pk_context_set_warning_handler(ctx, cli_print_warning, NULL);
    pk_scene *scene = NULL;
    view_server *srv = NULL;
    rc = 1;
    if ((rc = cli_configure(ctx, o.config)) != 0) goto out;
    rc = 1;
    pk_status st = o.scene ? pk_scene_load_file_params(ctx, o.scene, o.defines, o.ndefines, &scene)
                           : pk_scene_create_cornell_box(ctx, &scene);
    if (st != PK_OK) {
        rc = cli_fail_ctx(ctx);
        goto out;
    }
    /* the sample count names when to stop; every pass adds one sample */
    int max_spp = VIEW_DEFAULT_MAX_SPP;
    size_t nopts;
    const cli_option *opts = cli_render_options(&nopts);
    for (size_t i = 0; i < nopts; i++)
        if (o.int_set[i] && opts[i].render && strcmp(opts[i].render->name, "spp") == 0) {
            max_spp = o.int_value[i];
            o.int_set[i] = 0;
        }
    pk_render_options ro;
    if (cli_render_settings(ctx, &o, scene, &ro) != PK_OK) {
        rc = cli_fail_ctx(ctx);
        goto out;
    }
    ro.spp = 1;
    ro.collect_stats = 1;

    /* the denoiser, when its weights and oneDNN are here */
    pk_denoise_options dopt;
    pk_denoise_options_init(&dopt);
    dopt.weights = o.weights ? o.weights : cli_weights_dir();
    dopt.quality = o.denoise_fast ? PK_DENOISE_FAST : PK_DENOISE_HIGH;
    char why[512] = "";
    int have_denoiser = pk_denoise_check(ctx, &dopt) == PK_OK;
    if (!have_denoiser) {
        snprintf(why, sizeof why, "%s", pk_context_error(ctx));
        pk_context_clear_error(ctx);
        if (o.denoise == 1) {
            rc = cli_failure("--denoise: %s", why);
            goto out;
        }
    }

    view_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.ctx = ctx;
    cfg.scene = scene;
    const char *slash = o.scene ? strrchr(o.scene, '/') : NULL;
    cfg.scene_name = o.scene ? (slash ? slash + 1 : o.scene) : "cornell-box (built in)";
    cfg.ro = ro;
    cfg.max_spp = max_spp;
    cfg.bind = bind;
    cfg.port = port;
    cfg.exposure = o.has_exposure ? o.exposure : 0.0f;
    cfg.tonemap = o.tonemap;
    cfg.denoise = o.denoise == 1;
    cfg.dopt = have_denoiser ? &dopt : NULL;
    cfg.no_denoise_why = why;
    cfg.warn = o.quiet ? NULL : cli_print_warning;

    char err[512];
    if (view_server_start(&cfg, &srv, err, sizeof err) != 0) {
        rc = cli_failure("view: %s", err);
        goto out;
    }
    const int all = strcmp(bind, "0.0.0.0") == 0;
    printf("paprsek view: %s%s\n", view_server_url(srv),
           all ? " (every address of this machine: put one of them in place of 0.0.0.0)" : "");
    if (!o.quiet) printf("rendering %s at %dx%d; Ctrl-C to stop\n", cfg.scene_name, ro.width, ro.height);
    fflush(stdout);
    if (!o.extra[VIEW_NO_OPEN]) open_browser(view_server_url(srv));
    int sig = 0;
    sigwait(&set, &sig);
    if (view_server_stop_within(srv, 0.5) != 0) {
        /* in the middle of a denoising, which cannot be stopped: nothing is
         * being written, so the process may end without waiting for it */
        fflush(stdout);
        fflush(stderr);
        _exit(0);
    }
    srv = NULL;
    rc = 0;
out:
    view_server_stop(srv);
    pk_scene_destroy(scene);
    pk_context_destroy(ctx);
    return rc;
}
