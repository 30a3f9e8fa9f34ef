/*
 * test_view_http.c - the HTTP interface of `paprsek view` (docs/viewer.md)
 * against a server started here on a free port: status, frames, camera and
 * settings, pick, and every refusal (400, 403, 404, 405, 413) leaving the
 * state as it was.
 */
#include "view_client.h"

enum { W = 96, H = 64 };

static int has_frame(const char *json, void *user)
{
    const double want = *(const double *)user;
    return vc_json_number(json, "frame") >= want;
}

static int converged(const char *json, void *user)
{
    (void)user;
    return strstr(json, "\"rendering\":false") != NULL && vc_json_number(json, "passes") >= 1;
}

/* The body of a GET, NUL-terminated (malloc'ed). */
static char *get_text(int port, const char *target, int *code)
{
    vc_response r = vc_get(port, target);
    *code = r.code;
    char *t = (char *)r.body;
    r.body = NULL;
    vc_free(&r);
    return t ? t : strdup("");
}

/* The camera part of /api/status (between "camera": and ,"settings"). */
static char *camera_of(int port)
{
    int code;
    char *s = get_text(port, "/api/status", &code);
    char *a = strstr(s, "\"camera\":"), *b = a ? strstr(a, ",\"settings\"") : NULL;
    char *out = strdup(a && b ? a : "");
    if (a && b) out[b - a] = '\0';
    free(s);
    return out;
}

static char *settings_of(int port)
{
    int code;
    char *s = get_text(port, "/api/status", &code);
    char *a = strstr(s, "\"settings\":"), *b = a ? strchr(a, '}') : NULL;
    char *out = strdup(a && b ? a : "");
    if (a && b) out[b - a] = '\0';
    free(s);
    return out;
}

static void expect_refused(int port, const char *method, const char *target, const char *host, const char *headers,
                           const char *body, int code, const char *what)
{
    char *cam0 = camera_of(port), *set0 = settings_of(port);
    vc_response r = vc_request_host(port, method, target, host, headers, body, body ? strlen(body) : 0);
    CHECKF(r.code == code, "%s: got %d, not %d (%s)", what, r.code, code, r.body ? (char *)r.body : "");
    if (code != 405 || r.len) CHECKF(r.body && strstr((char *)r.body, "\"error\":"), "%s: no error message", what);
    const char *ct = vc_header(&r, "Content-Type");
    CHECKF(ct && strstr(ct, "application/json"), "%s: Content-Type %s", what, ct ? ct : "(none)");
    vc_free(&r);
    char *cam1 = camera_of(port), *set1 = settings_of(port);
    CHECKF(strcmp(cam0, cam1) == 0, "%s changed the camera: %s -> %s", what, cam0, cam1);
    CHECKF(strcmp(set0, set1) == 0, "%s changed the settings: %s -> %s", what, set0, set1);
    free(cam0);
    free(cam1);
    free(set0);
    free(set1);
}

/* The ray of the Cornell box's camera through the point (x, y) of a w x h
 * image (the pinhole's: render/camera.h), in double; the unit view
 * direction in view[]. */
static void camera_ray(const pk_scene *scene, double x, double y, int w, int h, double org[3], double dir[3],
                       double view[3])
{
    pk_camera cam;
    pk_scene_get_camera(scene, &cam);
    double f[3], up[3], u[3], v[3], len = 0.0;
    for (int i = 0; i < 3; i++) {
        org[i] = cam.look_from[i];
        f[i] = (double)cam.look_at[i] - (double)cam.look_from[i];
        up[i] = cam.up[i];
        len += f[i] * f[i];
    }
    for (int i = 0; i < 3; i++) view[i] = f[i] / sqrt(len);
    /* u = up x w (w = -view), v = w x u */
    const double wv[3] = {-view[0], -view[1], -view[2]};
    u[0] = up[1] * wv[2] - up[2] * wv[1], u[1] = up[2] * wv[0] - up[0] * wv[2], u[2] = up[0] * wv[1] - up[1] * wv[0];
    const double ul = sqrt(u[0] * u[0] + u[1] * u[1] + u[2] * u[2]);
    for (int i = 0; i < 3; i++) u[i] /= ul;
    v[0] = wv[1] * u[2] - wv[2] * u[1], v[1] = wv[2] * u[0] - wv[0] * u[2], v[2] = wv[0] * u[1] - wv[1] * u[0];
    const double hh = tan(0.5 * (double)cam.fov_deg * M_PI / 180.0), hw = hh * w / h;
    const double sx = (2.0 * x / w - 1.0) * hw, sy = (1.0 - 2.0 * y / h) * hh;
    double dl = 0.0;
    for (int i = 0; i < 3; i++) {
        dir[i] = u[i] * sx + v[i] * sy + view[i];
        dl += dir[i] * dir[i];
    }
    for (int i = 0; i < 3; i++) dir[i] /= sqrt(dl);
}

/* The distance along the view to the plane through a and b (points of the
 * floor plan, x and z) that stands upright, hit by the ray through (x, y). */
static double distance_to_wall(const pk_scene *scene, double x, double y, int w, int h, const double a[2],
                               const double b[2])
{
    double o[3], d[3], view[3];
    camera_ray(scene, x, y, w, h, o, d, view);
    /* the plane's normal in the floor plan: perpendicular to b - a */
    const double nx = -(b[1] - a[1]), nz = b[0] - a[0];
    const double t = (nx * (a[0] - o[0]) + nz * (a[1] - o[2])) / (nx * d[0] + nz * d[2]);
    return t * (d[0] * view[0] + d[1] * view[1] + d[2] * view[2]);
}

/* The same through the accelerator API, independent of the pick. */
static double distance_by_accel(const vc_server *v, double x, double y, int w, int h)
{
    pk_accel *a = NULL;
    REQUIRE(pk_accel_create(v->ctx, v->scene, PK_ACCEL_BVH, 1, &a) == PK_OK);
    double o[3], d[3], view[3];
    camera_ray(v->scene, x, y, w, h, o, d, view);
    pk_ray ray = {{(float)o[0], (float)o[1], (float)o[2]}, 0.0f, {(float)d[0], (float)d[1], (float)d[2]}, INFINITY};
    pk_hit hit;
    pk_accel_trace(a, &ray, &hit, 1, 1, 0, NULL);
    pk_accel_destroy(a);
    return (double)hit.t * (d[0] * view[0] + d[1] * view[1] + d[2] * view[2]);
}

int main(void)
{
    vc_server v;
    vc_start(&v, W, H, 4, 0);
    const int port = v.port;
    char buf[512];

    /* the page */
    vc_response r = vc_get(port, "/");
    CHECK(r.code == 200);
    CHECK(r.body && strstr((char *)r.body, "<html") != NULL);
    CHECK(vc_header(&r, "Content-Type") && strstr(vc_header(&r, "Content-Type"), "text/html"));
    vc_free(&r);

    /* status: the fields of the contract */
    r = vc_get(port, "/api/status");
    CHECK(r.code == 200);
    const char *j = (const char *)r.body;
    CHECK(vc_json_number(j, "width") == W && vc_json_number(j, "height") == H);
    static const char *const fields[] = {"\"frame\":", "\"spp\":", "\"passes\":", "\"elapsed_s\":", "\"rays_per_s\":",
                                         "\"rendering\":", "\"scene\":\"cornell \\\"box\\\"\"", "\"camera\":{\"look_from\":[",
                                         "\"settings\":{\"exposure\":0,\"denoise\":false,\"aov\":\"color\",\"integrator\":\"path\"",
                                         "\"initial_camera\":{", "\"lens_radius\":", "\"focus_distance\":", "\"fov\":"};
    for (size_t i = 0; i < sizeof fields / sizeof fields[0]; i++)
        CHECKF(j && strstr(j, fields[i]), "status lacks %s: %s", fields[i], j ? j : "");
    CHECK(vc_header(&r, "Cache-Control") && strcmp(vc_header(&r, "Cache-Control"), "no-store") == 0);
    vc_free(&r);

    /* frames: PNG of the full size (also the first, cheap pass), EXR, downloads */
    double want = 1;
    CHECK(vc_wait_status(port, 20, has_frame, &want));
    r = vc_get(port, "/api/frame.png");
    int w = 0, h = 0;
    CHECK(r.code == 200);
    CHECK(vc_png_size(&r, &w, &h) && w == W && h == H);
    CHECK(vc_header(&r, "X-Paprsek-Frame") && atoi(vc_header(&r, "X-Paprsek-Frame")) >= 1);
    CHECK(vc_header(&r, "Cache-Control") && strcmp(vc_header(&r, "Cache-Control"), "no-store") == 0);
    CHECK(vc_header(&r, "Content-Disposition") == NULL);
    vc_free(&r);
    r = vc_get(port, "/api/frame.png?download=1");
    CHECK(r.code == 200 && vc_header(&r, "Content-Disposition") &&
          strstr(vc_header(&r, "Content-Disposition"), "attachment; filename=\"paprsek.png\""));
    vc_free(&r);
    r = vc_get(port, "/api/frame.exr?download=1");
    CHECK(r.code == 200 && r.len > 4 && r.body[0] == 0x76 && r.body[1] == 0x2f && r.body[2] == 0x31 && r.body[3] == 0x01);
    CHECK(vc_header(&r, "Content-Disposition") &&
          strstr(vc_header(&r, "Content-Disposition"), "filename=\"paprsek.exr\""));
    CHECK(vc_header(&r, "X-Paprsek-Frame") != NULL);
    vc_free(&r);

    /* the render converges to max_spp and stops */
    CHECK(vc_wait_status(port, 30, converged, NULL));
    r = vc_get(port, "/api/status");
    CHECK(vc_json_number((char *)r.body, "spp") == 4 && vc_json_number((char *)r.body, "passes") == 4);
    CHECK(vc_json_number((char *)r.body, "rays_per_s") > 0);
    vc_free(&r);
    vc_response before = vc_get(port, "/api/frame.png");
    const double frame0 = vc_frame(port);

    /* a camera change: the reply has it, accumulation restarts, the image differs */
    r = vc_post(port, "/api/camera", "{\"look_from\":[0.5,0.3,-0.7],\"fov\":50}");
    CHECK(r.code == 200);
    CHECK(r.body && strstr((char *)r.body, "\"look_from\":[0.5,0.3,-0.7]"));
    CHECK(vc_json_number((char *)r.body, "fov") == 50);
    CHECK(vc_json_number((char *)r.body, "passes") == 0 && vc_json_number((char *)r.body, "spp") == 0);
    vc_free(&r);
    want = frame0 + 1;
    CHECK(vc_wait_status(port, 20, has_frame, &want));
    CHECK(vc_wait_status(port, 30, converged, NULL));
    vc_response after = vc_get(port, "/api/frame.png");
    CHECK(after.code == 200 && before.code == 200);
    CHECK(after.len != before.len || memcmp(after.body, before.body, after.len) != 0);
    CHECK(atoi(vc_header(&after, "X-Paprsek-Frame") ? vc_header(&after, "X-Paprsek-Frame") : "0") > (int)frame0);
    vc_free(&before);
    vc_free(&after);

    /* reset: back to the scene's camera */
    r = vc_post(port, "/api/camera", "{\"reset\":true}");
    CHECK(r.code == 200);
    {
        const char *b = (const char *)r.body;
        const char *c1 = b ? strstr(b, "\"camera\":") : NULL, *c2 = b ? strstr(b, "\"initial_camera\":") : NULL;
        CHECK(c1 && c2 && strncmp(c1 + 9, c2 + 17, 60) == 0);
    }
    vc_free(&r);

    /* settings: exposure does not restart accumulation, a new frame comes */
    CHECK(vc_wait_status(port, 30, converged, NULL));
    const double frame1 = vc_frame(port);
    r = vc_post(port, "/api/settings", "{\"exposure\":1.5,\"aov\":\"normal\"}");
    CHECK(r.code == 200);
    CHECK(r.body && strstr((char *)r.body, "\"exposure\":1.5") && strstr((char *)r.body, "\"aov\":\"normal\""));
    CHECK(vc_json_number((char *)r.body, "passes") == 4);
    vc_free(&r);
    want = frame1 + 1;
    CHECK(vc_wait_status(port, 20, has_frame, &want));
    r = vc_get(port, "/api/status");
    CHECK(vc_json_number((char *)r.body, "passes") == 4);
    vc_free(&r);
    /* the integrator restarts */
    r = vc_post(port, "/api/settings", "{\"integrator\":\"whitted\",\"max_depth\":5,\"aov\":\"color\"}");
    CHECK(r.code == 200);
    CHECK(r.body && strstr((char *)r.body, "\"integrator\":\"whitted\",\"max_depth\":5"));
    CHECK(vc_json_number((char *)r.body, "passes") == 0);
    vc_free(&r);
    CHECK(vc_wait_status(port, 30, converged, NULL));
    /* a tone curve and a transparent background: the background restarts
     * (a renderer option), the frame becomes RGBA (PNG colour type 6), then back */
    r = vc_post(port, "/api/settings", "{\"tonemap\":\"agx\",\"transparent\":true}");
    CHECK(r.code == 200);
    CHECK(r.body && strstr((char *)r.body, "\"tonemap\":\"agx\",\"transparent\":true"));
    CHECK(vc_json_number((char *)r.body, "passes") == 0);
    vc_free(&r);
    CHECK(vc_wait_status(port, 30, converged, NULL));
    r = vc_get(port, "/api/frame.png");
    CHECK(r.code == 200 && r.len > 26 && r.body[25] == 6);
    vc_free(&r);
    r = vc_post(port, "/api/settings", "{\"tonemap\":\"clamp\",\"transparent\":false}");
    CHECK(r.code == 200);
    vc_free(&r);
    CHECK(vc_wait_status(port, 30, converged, NULL));
    r = vc_get(port, "/api/frame.png");
    CHECK(r.code == 200 && r.len > 26 && r.body[25] == 2);
    vc_free(&r);

    /* pick: the centre of the image hits the front face of the tall block
     * (x, z from 0.265, 0.296 to 0.423, 0.247), a row near the top the back
     * wall (z = 0.5592, 1.3592 from the eye along the view) */
    {
        static const double front_a[2] = {0.265, 0.296}, front_b[2] = {0.423, 0.247};
        static const double back_a[2] = {0.0, 0.5592}, back_b[2] = {0.5496, 0.5592};
        snprintf(buf, sizeof buf, "/api/pick?x=%d&y=%d", W / 2, H / 2); /* whole numbers: the pixel's centre */
        const double wd = distance_to_wall(v.scene, W / 2 + 0.5, H / 2 + 0.5, W, H, front_a, front_b);
        CHECK_NEAR(wd, distance_by_accel(&v, W / 2 + 0.5, H / 2 + 0.5, W, H), 1e-4);
        CHECK(wd > 1.08 && wd < 1.10);
        r = vc_get(port, buf);
        CHECK(r.code == 200);
        CHECK(r.body && strstr((char *)r.body, "\"hit\":true"));
        CHECK_NEAR(vc_json_number((char *)r.body, "distance"), wd, 1e-4);
        CHECK(vc_json_number((char *)r.body, "t") > vc_json_number((char *)r.body, "distance"));
        CHECK(r.body && strstr((char *)r.body, "\"material\":\""));
        vc_free(&r);
        /* fractional coordinates are taken as they are */
        r = vc_get(port, "/api/pick?x=47.25&y=20.75");
        CHECK(r.code == 200);
        CHECK_NEAR(vc_json_number((char *)r.body, "distance"), distance_to_wall(v.scene, 47.25, 20.75, W, H, back_a, back_b),
                   1e-4);
        CHECK_NEAR(vc_json_number((char *)r.body, "distance"), 0.8 + 0.5592, 1e-4);
        const char *nrm = r.body ? strstr((char *)r.body, "\"normal\":[") : NULL;
        double n[3] = {0, 0, 0};
        CHECK(nrm && sscanf(nrm, "\"normal\":[%lf,%lf,%lf]", &n[0], &n[1], &n[2]) == 3);
        CHECK_NEAR(n[0], 0.0, 1e-5);
        CHECK_NEAR(n[1], 0.0, 1e-5);
        CHECK_NEAR(n[2], -1.0, 1e-5);
        vc_free(&r);
    }

    /* bad input: 400, nothing changes */
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"look_from\":[1,2", 400, "malformed JSON");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "[1,2,3]", 400, "not an object");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"zoom\":2}", 400, "unknown camera field");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"fov\":200}", 400, "fov out of range");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"fov\":\"wide\"}", 400, "fov not a number");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"lens_radius\":-1}", 400, "negative lens");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"look_from\":[1,2]}", 400, "two coordinates");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"look_from\":[1,2,1e39]}", 400, "beyond float");
    expect_refused(port, "POST", "/api/camera", NULL, NULL,
                   "{\"look_from\":[0.278,0.273,0],\"look_at\":[0.278,0.273,0]}", 400, "same point");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"up\":[0,0,1]}", 400, "up along the view");
    expect_refused(port, "POST", "/api/camera", NULL, NULL, "{\"fov\":30,\"reset\":1}", 400, "reset not a boolean");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"exposure\":21}", 400, "exposure out of range");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"exposure\":1,\"aov\":\"beauty\"}", 400, "unknown aov");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"integrator\":\"bdpt\"}", 400, "unknown integrator");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"max_depth\":2.5}", 400, "fractional depth");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"max_depth\":100000}", 400, "depth out of range");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"denoise\":\"yes\"}", 400, "denoise not a boolean");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"denoise\":true}", 400, "no denoiser here");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"gamma\":2.2}", 400, "unknown setting");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"tonemap\":\"filmic\"}", 400, "unknown tone curve");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "{\"transparent\":1}", 400, "transparent not a boolean");
    expect_refused(port, "POST", "/api/settings", NULL, NULL, "", 400, "empty body");
    expect_refused(port, "GET", "/api/pick?x=10", NULL, NULL, NULL, 400, "pick without y");
    expect_refused(port, "GET", "/api/pick?x=10&y=abc", NULL, NULL, NULL, 400, "pick y not a number");
    snprintf(buf, sizeof buf, "/api/pick?x=%d&y=0", W);
    expect_refused(port, "GET", buf, NULL, NULL, NULL, 400, "pick outside the image");
    expect_refused(port, "GET", "/api/pick?x=-1&y=0", NULL, NULL, NULL, 400, "pick left of the image");

    /* security: 403 for a foreign Host or Origin */
    snprintf(buf, sizeof buf, "evil.example:%d", port);
    expect_refused(port, "GET", "/api/status", buf, NULL, NULL, 403, "foreign Host (DNS rebinding)");
    expect_refused(port, "GET", "/", buf, NULL, NULL, 403, "foreign Host on the page");
    expect_refused(port, "GET", "/api/status", "127.0.0.1", NULL, NULL, 403, "Host without the port");
    expect_refused(port, "POST", "/api/camera", NULL, "Origin: http://evil.example\r\n", "{\"fov\":30}", 403,
                   "foreign Origin");
    snprintf(buf, sizeof buf, "Origin: http://127.0.0.1:%d0\r\n", port);
    expect_refused(port, "POST", "/api/settings", NULL, buf, "{\"exposure\":2}", 403, "Origin of another port");
    expect_refused(port, "POST", "/api/settings", NULL, "Origin: null\r\n", "{\"exposure\":2}", 403, "Origin null");
    /* the server's own origin, and localhost, are fine */
    snprintf(buf, sizeof buf, "Origin: http://127.0.0.1:%d\r\n", port);
    r = vc_request_host(port, "POST", "/api/settings", NULL, buf, "{\"exposure\":0.5}", 16);
    CHECKF(r.code == 200, "own Origin: %d %s", r.code, r.body ? (char *)r.body : "");
    vc_free(&r);
    snprintf(buf, sizeof buf, "localhost:%d", port);
    char origin[128];
    snprintf(origin, sizeof origin, "Origin: http://localhost:%d\r\n", port);
    r = vc_request_host(port, "POST", "/api/settings", buf, origin, "{\"exposure\":0}", 14);
    CHECKF(r.code == 200, "localhost: %d %s", r.code, r.body ? (char *)r.body : "");
    vc_free(&r);

    /* 413: a body beyond 64 KiB, announced or sent */
    {
        const size_t n = VIEW_MAX_BODY + 100;
        char *big = malloc(n + 1);
        REQUIRE(big);
        memset(big, ' ', n);
        big[0] = '{';
        big[n - 1] = '}';
        big[n] = '\0';
        free(big);
        /* announced: refused before the body is read */
        char *cam0 = camera_of(port);
        const int fd0 = vc_connect(port);
        char head0[256];
        snprintf(head0, sizeof head0,
                 "POST /api/camera HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\n"
                 "Content-Type: application/json\r\nContent-Length: %zu\r\n\r\n",
                 port, n);
        vc_send_all(fd0, head0, strlen(head0));
        char resp0[512] = "";
        size_t got0 = 0;
        struct pollfd pf0 = {fd0, POLLIN, 0};
        while (got0 < sizeof resp0 - 1 && poll(&pf0, 1, 5000) > 0) {
            const ssize_t k = recv(fd0, resp0 + got0, sizeof resp0 - 1 - got0, 0);
            if (k <= 0) break;
            got0 += (size_t)k;
        }
        resp0[got0] = '\0';
        close(fd0);
        CHECKF(strncmp(resp0, "HTTP/1.1 413", 12) == 0 && strstr(resp0, "\"error\":"), "announced big body: %.60s", resp0);
        char *cam1 = camera_of(port);
        CHECK(strcmp(cam0, cam1) == 0);
        free(cam0);
        free(cam1);
        /* chunked, so that no Content-Length announces it */
        const int fd = vc_connect(port);
        char head[256];
        snprintf(head, sizeof head,
                 "POST /api/settings HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nConnection: close\r\nTransfer-Encoding: chunked\r\n\r\n",
                 port);
        vc_send_all(fd, head, strlen(head));
        char chunk[8192 + 16];
        for (int k = 0; k < 10; k++) {
            const int hl = snprintf(chunk, sizeof chunk, "2000\r\n");
            memset(chunk + hl, ' ', 8192);
            memcpy(chunk + hl + 8192, "\r\n", 2);
            vc_send_all(fd, chunk, (size_t)hl + 8194);
        }
        vc_send_all(fd, "0\r\n\r\n", 5);
        char resp[256] = "";
        size_t got = 0;
        struct pollfd pf = {fd, POLLIN, 0};
        while (got < sizeof resp - 1 && poll(&pf, 1, 5000) > 0) {
            const ssize_t k = recv(fd, resp + got, sizeof resp - 1 - got, 0);
            if (k <= 0) break;
            got += (size_t)k;
        }
        resp[got] = '\0';
        CHECKF(strncmp(resp, "HTTP/1.1 413", 12) == 0, "chunked big body: %.40s", resp);
        close(fd);
    }

    /* 404 and 405 */
    expect_refused(port, "GET", "/etc/passwd", NULL, NULL, NULL, 404, "a file");
    expect_refused(port, "GET", "/../../../../etc/passwd", NULL, NULL, NULL, 404, "a file outside");
    expect_refused(port, "GET", "/api/frame.pfm", NULL, NULL, NULL, 404, "another format");
    expect_refused(port, "GET", "/api/camera", NULL, NULL, NULL, 405, "GET of the camera");
    expect_refused(port, "POST", "/api/status", NULL, NULL, "{}", 405, "POST of the status");
    expect_refused(port, "DELETE", "/api/settings", NULL, NULL, NULL, 405, "DELETE");

    vc_stop(&v);
    return test_done("test_view_http");
}
