/*
 * progress.c - the progress bar of `paprsek render`: one line on stderr,
 * redrawn in place with '\r', only when stderr is a terminal.
 *
 *   [##############..............]  48%  3.1 s, ETA 3.4 s
 */
#include "cli.h"

#include <stdio.h>
#include <string.h>
#include <sys/ioctl.h>
#include <unistd.h>

void cli_format_duration(char *buf, size_t cap, double s)
{
    if (!(s >= 0.0)) s = 0.0;
    if (s < 1.0) {
        snprintf(buf, cap, "%.2f s", s);
        return;
    }
    if (s < 60.0) {
        snprintf(buf, cap, "%.1f s", s);
        return;
    }
    unsigned long t = (unsigned long)(s + 0.5);
    if (t < 3600)
        snprintf(buf, cap, "%lu:%02lu", t / 60, t % 60);
    else
        snprintf(buf, cap, "%lu:%02lu:%02lu", t / 3600, t / 60 % 60, t % 60);
}

int cli_progress_format(char *buf, size_t cap, int cols, uint64_t done, uint64_t total, double elapsed_s)
{
    if (cap == 0) return 0;
    if (done > total) done = total;
    const double frac = total ? (double)done / (double)total : 1.0;
    const int percent = (int)(frac * 100.0);
    char el[32], eta[40];
    cli_format_duration(el, sizeof el, elapsed_s);
    if (done == total) {
        snprintf(eta, sizeof eta, "done");
    } else if (done == 0 || !(elapsed_s > 0.0)) {
        snprintf(eta, sizeof eta, "ETA --");
    } else {
        char t[32];
        cli_format_duration(t, sizeof t, elapsed_s * (double)(total - done) / (double)done);
        snprintf(eta, sizeof eta, "ETA %s", t);
    }
    char tail[96];
    int tl = snprintf(tail, sizeof tail, " %3d%%  %s, %s", percent, el, eta);
    if (tl < 0) tl = 0;
    /* The bar takes what the line leaves, between 10 and 40 cells; the last
     * column stays free so that the terminal never wraps. */
    int bar = cols - 1 - tl - 2;
    if (bar > 40) bar = 40;
    int len;
    if (bar < 10) {
        len = snprintf(buf, cap, "%s", tail + 1);
    } else {
        char cells[41];
        int full = (int)(frac * bar);
        for (int i = 0; i < bar; i++) cells[i] = i < full ? '#' : '.';
        cells[bar] = '\0';
        len = snprintf(buf, cap, "[%s]%s", cells, tail);
    }
    if (len < 0) len = 0;
    if ((size_t)len >= cap) len = (int)cap - 1;
    return len;
}

void cli_progress_init(cli_progress *p, FILE *f, int quiet)
{
    memset(p, 0, sizeof *p);
    p->f = f;
    p->enabled = !quiet && isatty(fileno(f));
    p->last_permille = -1;
    p->last_elapsed = -1.0;
}

static int terminal_columns(FILE *f)
{
    struct winsize ws;
    if (ioctl(fileno(f), TIOCGWINSZ, &ws) == 0 && ws.ws_col >= 20) return ws.ws_col;
    return 80;
}

int cli_progress_update(void *user, uint64_t done, uint64_t total, double elapsed_s)
{
    cli_progress *p = user;
    if (!p || !p->enabled) return 0;
    int permille = total ? (int)((double)(done > total ? total : done) * 1000.0 / (double)total) : 1000;
    /* Nothing to redraw: the same tenth of a percent within the same second. */
    if (permille == p->last_permille && elapsed_s - p->last_elapsed < 1.0) return 0;
    p->last_permille = permille;
    p->last_elapsed = elapsed_s;
    char line[256];
    const int cols = terminal_columns(p->f), nl = p->note[0] ? (int)strlen(p->note) + 2 : 0;
    int len = cli_progress_format(line, sizeof line, cols - nl, done, total, elapsed_s);
    if (nl && len + nl < (int)sizeof line) len += snprintf(line + len, sizeof line - (size_t)len, ", %s", p->note);
    /* Spaces cover what is left of a longer earlier line. */
    int pad = p->drawn > len ? p->drawn - len : 0;
    fprintf(p->f, "\r%s%*s", line, pad, "");
    if (pad) fprintf(p->f, "\r%s", line);
    fflush(p->f);
    p->drawn = len;
    return 0;
}

void cli_progress_clear(cli_progress *p)
{
    if (!p->enabled || p->drawn == 0) return;
    fprintf(p->f, "\r%*s\r", p->drawn, "");
    fflush(p->f);
    p->drawn = 0;
}
