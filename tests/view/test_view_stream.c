/*
 * test_view_stream.c - `paprsek view`'s update stream and its server's life:
 * server-sent events to two clients at once, a camera change reaching both,
 * frames fetched from several threads at once, the token mode, and a stop
 * that ends open streams promptly.
 */
#include "view_client.h"

#include <pthread.h>

/* An open event stream. */
typedef struct stream {
    int fd;
    char buf[1 << 16];
    size_t len;
} stream;

static void stream_open(stream *s, int port, const char *target)
{
    s->fd = vc_connect(port);
    s->len = 0;
    char req[256];
    snprintf(req, sizeof req, "GET %s HTTP/1.1\r\nHost: 127.0.0.1:%d\r\nAccept: text/event-stream\r\n\r\n", target, port);
    vc_send_all(s->fd, req, strlen(req));
}

/* Reads until the n-th "event: frame" has arrived or seconds pass; returns
 * how many have arrived. -1 once the server closed the stream. */
static int stream_wait(stream *s, int n, double seconds)
{
    const double t0 = vc_now();
    for (;;) {
        int count = 0;
        s->buf[s->len] = '\0';
        for (const char *p = s->buf; (p = strstr(p, "event: frame\ndata: {")); p++) count++;
        if (count >= n) return count;
        const double left = seconds - (vc_now() - t0);
        if (left <= 0 || s->len >= sizeof s->buf - 1) return count;
        struct pollfd pf = {s->fd, POLLIN, 0};
        if (poll(&pf, 1, (int)(left * 1000) + 1) <= 0) continue;
        const ssize_t k = recv(s->fd, s->buf + s->len, sizeof s->buf - 1 - s->len, 0);
        if (k <= 0) return -1;
        s->len += (size_t)k;
    }
}

/* The frame number of the last event received. */
static double stream_last_frame(const stream *s)
{
    const char *last = NULL;
    for (const char *p = s->buf; (p = strstr(p, "event: frame\ndata: {")); p++) last = p;
    return last ? vc_json_number(last, "frame") : -1;
}

typedef struct fetcher {
    int port, ok, n;
} fetcher;

static void *fetch_frames(void *arg)
{
    fetcher *f = arg;
    for (int i = 0; i < f->n; i++) {
        vc_response r = vc_get(f->port, i % 2 ? "/api/frame.png" : "/api/frame.exr");
        int w, h;
        if (r.code == 200 && (i % 2 == 0 || (vc_png_size(&r, &w, &h) && w == 64 && h == 40))) f->ok++;
        vc_free(&r);
    }
    return NULL;
}

int main(void)
{
    vc_server v;
    vc_start(&v, 64, 40, 64, 0);
    const int port = v.port;

    /* two streams at once: the current frame on connect, then every new one */
    stream *a = malloc(sizeof *a), *b = malloc(sizeof *b);
    REQUIRE(a && b);
    stream_open(a, port, "/api/events");
    stream_open(b, port, "/api/events");
    CHECK(stream_wait(a, 1, 10) >= 1);
    CHECK(stream_wait(b, 1, 10) >= 1);
    a->buf[a->len] = '\0';
    CHECK(strstr(a->buf, "HTTP/1.1 200") == a->buf);
    CHECK(strstr(a->buf, "Content-Type: text/event-stream") != NULL);
    CHECK(stream_wait(a, 3, 20) >= 3);
    CHECK(stream_wait(b, 3, 20) >= 3);
    const double fa = stream_last_frame(a);
    CHECK(fa >= 2);

    /* a camera change reaches both, with the new camera */
    vc_response r = vc_post(port, "/api/camera", "{\"look_at\":[0.3,0.25,0],\"lens_radius\":0.01,\"focus_distance\":1.2}");
    CHECK(r.code == 200);
    vc_free(&r);
    const double t0 = vc_now();
    int seen = 0;
    while (!seen && vc_now() - t0 < 10) {
        const int n = stream_wait(a, 1000, 0.05);
        if (n < 0) break;
        a->buf[a->len] = '\0';
        seen = strstr(a->buf, "\"look_at\":[0.3,0.25,0]") != NULL;
    }
    CHECK(seen);
    CHECK(stream_wait(b, 1000, 1.0) >= 0);
    b->buf[b->len] = '\0';
    CHECK(strstr(b->buf, "\"focus_distance\":1.2") != NULL);

    /* frames fetched from three threads while two streams are open */
    fetcher f[3];
    pthread_t th[3];
    for (int i = 0; i < 3; i++) {
        f[i] = (fetcher){port, 0, 6};
        REQUIRE(pthread_create(&th[i], NULL, fetch_frames, &f[i]) == 0);
    }
    for (int i = 0; i < 3; i++) {
        pthread_join(th[i], NULL);
        CHECKF(f[i].ok == f[i].n, "thread %d: %d of %d frames", i, f[i].ok, f[i].n);
    }

    /* stop while the streams are open: within a second, and the streams end */
    const double ts = vc_now();
    vc_stop(&v);
    const double took = vc_now() - ts;
    CHECKF(took < 1.0, "stop took %.3f s", took);
    const double te = vc_now();
    int ended = 0;
    while (!ended && vc_now() - te < 2) ended = stream_wait(a, 1 << 20, 0.1) < 0;
    CHECK(ended);
    close(a->fd);
    close(b->fd);

    /* the token mode: every request needs it */
    vc_start(&v, 32, 24, 2, 1);
    const char *token = view_server_token(v.srv);
    CHECK(strlen(token) == 32);
    char url[256];
    snprintf(url, sizeof url, "http://127.0.0.1:%d/?token=%s", v.port, token);
    CHECK(strcmp(view_server_url(v.srv), url) == 0);
    r = vc_get(v.port, "/api/status");
    CHECK(r.code == 403);
    vc_free(&r);
    r = vc_get(v.port, "/");
    CHECK(r.code == 403);
    vc_free(&r);
    r = vc_get(v.port, "/api/status?token=0123456789abcdef0123456789abcdef");
    CHECK(r.code == 403);
    vc_free(&r);
    char target[128];
    snprintf(target, sizeof target, "/api/status?token=%.31s", token);
    r = vc_get(v.port, target);
    CHECK(r.code == 403);
    vc_free(&r);
    snprintf(target, sizeof target, "/api/status?token=%s", token);
    r = vc_get(v.port, target);
    CHECK(r.code == 200);
    vc_free(&r);
    snprintf(target, sizeof target, "/?token=%s", token);
    r = vc_get(v.port, target);
    CHECK(r.code == 200);
    vc_free(&r);
    char hdr[128];
    snprintf(hdr, sizeof hdr, "X-Paprsek-Token: %s\r\n", token);
    r = vc_request_host(v.port, "POST", "/api/settings", NULL, hdr, "{\"exposure\":1}", 14);
    CHECK(r.code == 200);
    vc_free(&r);
    r = vc_post(v.port, "/api/settings", "{\"exposure\":2}");
    CHECK(r.code == 403);
    vc_free(&r);
    snprintf(target, sizeof target, "/api/status?token=%s", token);
    r = vc_get(v.port, target);
    CHECK(r.body && strstr((char *)r.body, "\"exposure\":1,"));
    vc_free(&r);
    vc_stop(&v);
    free(a);
    free(b);
    return test_done("test_view_stream");
}
