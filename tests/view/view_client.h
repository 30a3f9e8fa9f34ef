/*
 * view_client.h - what the tests of `paprsek view` share: a server on a free
 * port over the built-in Cornell box, and a plain-socket HTTP/1.1 client
 * (one request per connection), so that the server is tested as a browser
 * or curl would talk to it.
 */
#ifndef PK_VIEW_CLIENT_H
#define PK_VIEW_CLIENT_H

#include "test.h"
#include "view_server.h"

#include <arpa/inet.h>
#include <errno.h>
#include <netinet/in.h>
#include <poll.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <strings.h>
#include <sys/socket.h>
#include <time.h>
#include <unistd.h>

static inline double vc_now(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (double)ts.tv_sec + (double)ts.tv_nsec * 1e-9;
}

typedef struct vc_server {
    pk_context *ctx;
    pk_scene *scene;
    view_server *srv;
    int port;
} vc_server;

/* The Cornell box at w x h, max_spp samples; require_token as view_config. */
static inline void vc_start(vc_server *v, int w, int h, int max_spp, int require_token)
{
    memset(v, 0, sizeof *v);
    REQUIRE(pk_context_create(NULL, &v->ctx) == PK_OK);
    REQUIRE(pk_scene_create_cornell_box(v->ctx, &v->scene) == PK_OK);
    view_config cfg;
    memset(&cfg, 0, sizeof cfg);
    cfg.ctx = v->ctx;
    cfg.scene = v->scene;
    cfg.scene_name = "cornell \"box\"";
    pk_scene_get_render_options(v->scene, &cfg.ro);
    cfg.ro.width = w;
    cfg.ro.height = h;
    cfg.ro.spp = 1;
    cfg.ro.threads = 2;
    cfg.max_spp = max_spp;
    cfg.port = 0;
    cfg.require_token = require_token;
    cfg.no_denoise_why = "no weights in this test";
    char err[256];
    const int rc = view_server_start(&cfg, &v->srv, err, sizeof err);
    if (rc) fprintf(stderr, "view_server_start: %s\n", err);
    REQUIRE(rc == 0);
    v->port = view_server_port(v->srv);
    REQUIRE(v->port > 0);
}

static inline void vc_stop(vc_server *v)
{
    view_server_stop(v->srv);
    pk_scene_destroy(v->scene);
    pk_context_destroy(v->ctx);
}

static inline int vc_connect(int port)
{
    const int fd = socket(AF_INET, SOCK_STREAM, 0);
    REQUIRE(fd >= 0);
    struct sockaddr_in a;
    memset(&a, 0, sizeof a);
    a.sin_family = AF_INET;
    a.sin_port = htons((uint16_t)port);
    a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    REQUIRE(connect(fd, (struct sockaddr *)&a, sizeof a) == 0);
    return fd;
}

static inline void vc_send_all(int fd, const char *p, size_t n)
{
    while (n) {
        const ssize_t k = send(fd, p, n, MSG_NOSIGNAL);
        if (k <= 0) return; /* the server may close early (413) */
        p += k;
        n -= (size_t)k;
    }
}

typedef struct vc_response {
    int code;
    char *head;          /* the status line and headers, NUL-terminated */
    unsigned char *body; /* NUL-terminated too */
    size_t len;
} vc_response;

static inline void vc_free(vc_response *r)
{
    free(r->head);
    free(r->body);
    memset(r, 0, sizeof *r);
}

/* The value of header name in r (static buffer), or NULL. */
static inline const char *vc_header(const vc_response *r, const char *name)
{
    static char val[512];
    const size_t n = strlen(name);
    for (const char *p = r->head; p && *p;) {
        const char *eol = strstr(p, "\r\n");
        if (!eol) break;
        if (strncasecmp(p, name, n) == 0 && p[n] == ':') {
            const char *v = p + n + 1;
            while (*v == ' ') v++;
            size_t k = (size_t)(eol - v);
            if (k >= sizeof val) k = sizeof val - 1;
            memcpy(val, v, k);
            val[k] = '\0';
            return val;
        }
        p = eol + 2;
    }
    return NULL;
}

/* One request: method, target, extra header lines ("Name: value\r\n"...,
 * may be NULL), a body (may be NULL). host NULL: 127.0.0.1:PORT. Reads the
 * whole response (the server closes: Connection: close). */
static inline vc_response vc_request_host(int port, const char *method, const char *target, const char *host,
                                   const char *headers, const char *body, size_t body_len)
{
    const int fd = vc_connect(port);
    char req[2048];
    char hostbuf[128];
    if (!host) {
        snprintf(hostbuf, sizeof hostbuf, "127.0.0.1:%d", port);
        host = hostbuf;
    }
    const int n = snprintf(req, sizeof req, "%s %s HTTP/1.1\r\nHost: %s\r\nConnection: close\r\n%s", method, target,
                           host, headers ? headers : "");
    REQUIRE(n > 0 && (size_t)n < sizeof req - 64);
    size_t len = (size_t)n;
    if (body) len += (size_t)snprintf(req + len, sizeof req - len, "Content-Type: application/json\r\nContent-Length: %zu\r\n", body_len);
    len += (size_t)snprintf(req + len, sizeof req - len, "\r\n");
    vc_send_all(fd, req, len);
    if (body) vc_send_all(fd, body, body_len);
    size_t cap = 1 << 16, got = 0;
    char *buf = malloc(cap + 1);
    REQUIRE(buf);
    for (;;) {
        if (got == cap) {
            cap *= 2;
            buf = realloc(buf, cap + 1);
            REQUIRE(buf);
        }
        struct pollfd pf = {fd, POLLIN, 0};
        if (poll(&pf, 1, 20000) <= 0) break; /* 20 s without a byte: give up */
        const ssize_t k = recv(fd, buf + got, cap - got, 0);
        if (k <= 0) break;
        got += (size_t)k;
    }
    close(fd);
    buf[got] = '\0';
    vc_response r;
    memset(&r, 0, sizeof r);
    char *sep = strstr(buf, "\r\n\r\n");
    if (!sep || sscanf(buf, "HTTP/1.%*d %d", &r.code) != 1) {
        free(buf);
        return r;
    }
    const size_t hl = (size_t)(sep - buf) + 2;
    r.head = malloc(hl + 1);
    REQUIRE(r.head);
    memcpy(r.head, buf, hl);
    r.head[hl] = '\0';
    r.len = got - hl - 2;
    r.body = malloc(r.len + 1);
    REQUIRE(r.body);
    memcpy(r.body, sep + 4, r.len);
    r.body[r.len] = '\0';
    free(buf);
    return r;
}

static inline vc_response vc_get(int port, const char *target) { return vc_request_host(port, "GET", target, NULL, NULL, NULL, 0); }

static inline vc_response vc_post(int port, const char *target, const char *json)
{
    return vc_request_host(port, "POST", target, NULL, NULL, json, strlen(json));
}

/* A number after "key": in the JSON text (first occurrence), or NAN. */
static inline double vc_json_number(const char *json, const char *key)
{
    char pat[80];
    snprintf(pat, sizeof pat, "\"%s\":", key);
    const char *p = json ? strstr(json, pat) : NULL;
    if (!p) return -1e300;
    return strtod(p + strlen(pat), NULL);
}

/* The frame number of /api/status. */
static inline double vc_frame(int port)
{
    vc_response r = vc_get(port, "/api/status");
    const double f = r.code == 200 ? vc_json_number((const char *)r.body, "frame") : -1.0;
    vc_free(&r);
    return f;
}

/* Waits (up to seconds) until /api/status says what pred wants. */
static inline int vc_wait_status(int port, double seconds, int (*pred)(const char *json, void *user), void *user)
{
    const double t0 = vc_now();
    while (vc_now() - t0 < seconds) {
        vc_response r = vc_get(port, "/api/status");
        const int ok = r.code == 200 && pred((const char *)r.body, user);
        vc_free(&r);
        if (ok) return 1;
        usleep(20000);
    }
    return 0;
}

/* PNG: the signature and the size in IHDR. */
static inline int vc_png_size(const vc_response *r, int *w, int *h)
{
    static const unsigned char sig[8] = {0x89, 'P', 'N', 'G', '\r', '\n', 0x1a, '\n'};
    if (r->len < 24 || memcmp(r->body, sig, 8) != 0 || memcmp(r->body + 12, "IHDR", 4) != 0) return 0;
    const unsigned char *p = r->body + 16;
    *w = (int)((uint32_t)p[0] << 24 | (uint32_t)p[1] << 16 | (uint32_t)p[2] << 8 | p[3]);
    *h = (int)((uint32_t)p[4] << 24 | (uint32_t)p[5] << 16 | (uint32_t)p[6] << 8 | p[7]);
    return 1;
}

#endif
