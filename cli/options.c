/*
 * options.c - command-line options from one table per command: getopt_long
 * does the parsing (--name VALUE, --name=VALUE, unique abbreviations, short
 * options); this file turns its answers into messages a user can act on
 * ("did you mean --spp?"), checks integer ranges and prints --help.
 */
#include "cli.h"

#include <getopt.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define MAX_OPTIONS 64
#define LONG_VAL 0x100 /* getopt's val for options without a short name: LONG_VAL + index */

cli_option cli_option_from_render(const pk_int_option *o, char *name_buf, size_t cap)
{
    size_t i = 0;
    for (; o->name[i] && i + 1 < cap; i++) name_buf[i] = o->name[i] == '_' ? '-' : o->name[i];
    name_buf[i] = '\0';
    cli_option c = {.name = name_buf,
                    .kind = CLI_INT,
                    .arg = "N",
                    .help = o->help,
                    .min = o->min,
                    .max = o->max,
                    .default_value = o->default_value,
                    .render = o};
    return c;
}

/* ---- edit distance and suggestions --------------------------------------- */

/* Optimal string alignment distance: insertions, deletions, substitutions
 * and swaps of two neighbours each count one. */
static size_t edit_distance(const char *a, size_t la, const char *b, size_t lb)
{
    enum { M = 64 };
    if (la >= M || lb >= M) return (size_t)-1;
    size_t d[M][M];
    for (size_t i = 0; i <= la; i++) d[i][0] = i;
    for (size_t j = 0; j <= lb; j++) d[0][j] = j;
    for (size_t i = 1; i <= la; i++)
        for (size_t j = 1; j <= lb; j++) {
            size_t cost = a[i - 1] != b[j - 1];
            size_t v = d[i - 1][j] + 1;
            if (d[i][j - 1] + 1 < v) v = d[i][j - 1] + 1;
            if (d[i - 1][j - 1] + cost < v) v = d[i - 1][j - 1] + cost;
            if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1] && d[i - 2][j - 2] + 1 < v)
                v = d[i - 2][j - 2] + 1;
            d[i][j] = v;
        }
    return d[la][lb];
}

const char *cli_nearest(const char *word, size_t len, const char *const *names, size_t n)
{
    const char *best = NULL;
    size_t best_d = (size_t)-1;
    for (size_t i = 0; i < n; i++) {
        size_t d = edit_distance(word, len, names[i], strlen(names[i]));
        if (d < best_d) {
            best_d = d;
            best = names[i];
        }
    }
    if (!best) return NULL;
    /* One slip in a short name, two in a longer one; never more than half
     * of what was typed (so that "--x" suggests nothing). */
    size_t allowed = strlen(best) <= 4 ? 1 : 2;
    if (best_d > allowed || 2 * best_d > len) return NULL;
    return best;
}

/* ---- parsing ----------------------------------------------------------------- */

/* getopt_long keeps its state in globals; the tables live here between calls
 * of cli_next (one parser at a time, which is all a command needs). */
static struct option g_long[MAX_OPTIONS + 1];
static char g_short[2 * MAX_OPTIONS + 4];

void cli_parser_init(cli_parser *p, const char *cmd, const cli_option *opts, size_t n, int argc, char **argv)
{
    memset(p, 0, sizeof *p);
    if (n > MAX_OPTIONS) n = MAX_OPTIONS;
    p->cmd = cmd;
    p->opts = opts;
    p->n = n;
    p->argc = argc;
    p->argv = argv;
    p->rest = -1;
    /* "-": arguments come back in order (as option 1), whatever
     * POSIXLY_CORRECT says; ":": a missing value is reported as ':'. */
    size_t k = 0;
    g_short[k++] = '-';
    g_short[k++] = ':';
    for (size_t i = 0; i < n; i++) {
        g_long[i].name = opts[i].name;
        g_long[i].has_arg = opts[i].kind == CLI_FLAG ? no_argument : required_argument;
        g_long[i].flag = NULL;
        g_long[i].val = opts[i].short_name ? opts[i].short_name : LONG_VAL + (int)i;
        if (opts[i].short_name) {
            g_short[k++] = (char)opts[i].short_name;
            if (opts[i].kind != CLI_FLAG) g_short[k++] = ':';
        }
    }
    memset(&g_long[n], 0, sizeof g_long[n]);
    g_short[k] = '\0';
    optind = 0; /* glibc: start afresh (argv[0] is skipped) */
    opterr = 0; /* the messages are ours */
}

/* The option getopt answered val for, or -1. */
static int index_of(const cli_parser *p, int val)
{
    if (val >= LONG_VAL && val < LONG_VAL + (int)p->n) return val - LONG_VAL;
    for (size_t i = 0; i < p->n; i++)
        if (p->opts[i].short_name && p->opts[i].short_name == val) return (int)i;
    return -1;
}

/* "--name" or "-o", as the user would type it. */
static void option_text(const cli_parser *p, int i, const char *typed, char *buf, size_t cap)
{
    if (p->opts[i].short_name && typed && typed[0] == '-' && typed[1] != '-')
        snprintf(buf, cap, "-%c", p->opts[i].short_name);
    else
        snprintf(buf, cap, "--%s", p->opts[i].name);
}

/* A usage error: the message, then CLI_ERROR (cli_usage_error's own 2 is a
 * valid answer of cli_next). */
#define FAIL(...) (cli_usage_error(__VA_ARGS__), CLI_ERROR)

static int unknown_long(const cli_parser *p, const char *typed)
{
    const char *name = typed + 2;
    size_t len = strcspn(name, "=");
    /* Prefixes of more than one option: getopt_long calls that ambiguous. */
    char list[512];
    size_t used = 0, matches = 0;
    list[0] = '\0';
    for (size_t i = 0; i < p->n; i++)
        if (len > 0 && strncmp(p->opts[i].name, name, len) == 0) {
            int w = snprintf(list + used, sizeof list - used, "%s--%s", matches ? ", " : "", p->opts[i].name);
            if (w > 0 && (size_t)w < sizeof list - used) used += (size_t)w;
            matches++;
        }
    if (matches > 1)
        return FAIL("%s: option '--%.*s' is ambiguous: %s", p->cmd, (int)len, name, list);
    const char *names[MAX_OPTIONS];
    for (size_t i = 0; i < p->n; i++) names[i] = p->opts[i].name;
    const char *near = cli_nearest(name, len, names, p->n);
    if (near)
        return FAIL("%s: unknown option '--%.*s'; did you mean --%s?", p->cmd, (int)len, name, near);
    return FAIL("%s: unknown option '--%.*s' (see paprsek %s --help)", p->cmd, (int)len, name, p->cmd);
}

static int unknown_short(const cli_parser *p, int c, const char *typed)
{
    /* "-spp" is read as -s -p -p: a long name typed with one dash? */
    if (typed && typed[0] == '-' && typed[1] && typed[1] != '-' && typed[2]) {
        const char *names[MAX_OPTIONS];
        for (size_t i = 0; i < p->n; i++) names[i] = p->opts[i].name;
        size_t len = strcspn(typed + 1, "=");
        const char *near = cli_nearest(typed + 1, len, names, p->n);
        if (near) return FAIL("%s: unknown option '%s'; did you mean --%s?", p->cmd, typed, near);
    }
    if (c > ' ' && c < 127)
        return FAIL("%s: unknown option '-%c' (see paprsek %s --help)", p->cmd, c, p->cmd);
    return FAIL("%s: unknown option '%s' (see paprsek %s --help)", p->cmd, typed ? typed : "?", p->cmd);
}

int cli_next(cli_parser *p)
{
    p->index = -1;
    p->value = NULL;
    p->int_value = 0;
    if (p->rest >= 0) { /* after "--" everything is an argument */
        if (p->rest >= p->argc) return CLI_END;
        p->value = p->argv[p->rest++];
        return CLI_ARGUMENT;
    }
    int at = optind > 0 ? optind : 1; /* the argument getopt is about to read */
    const char *typed = at < p->argc ? p->argv[at] : NULL;
    int c = getopt_long(p->argc, p->argv, g_short, g_long, NULL);
    if (c == -1) {
        /* "--" (or the end): what follows are arguments. */
        p->rest = optind;
        return cli_next(p);
    }
    if (c == 1) {
        p->value = optarg;
        return CLI_ARGUMENT;
    }
    if (c == ':') {
        int i = index_of(p, optopt);
        char name[80];
        if (i < 0) return FAIL("%s needs a value", typed ? typed : "an option");
        option_text(p, i, typed, name, sizeof name);
        return FAIL("%s needs a value", name);
    }
    if (c == '?') {
        int i = optopt ? index_of(p, optopt) : -1;
        if (i >= 0) { /* a flag given a value: --stats=yes */
            char name[80];
            option_text(p, i, typed, name, sizeof name);
            return FAIL("%s takes no value", name);
        }
        if (typed && typed[0] == '-' && typed[1] == '-') return unknown_long(p, typed);
        return unknown_short(p, optopt, typed);
    }
    int i = index_of(p, c);
    if (i < 0) return FAIL("%s: cannot read the options (see paprsek %s --help)", p->cmd, p->cmd);
    p->index = i;
    p->value = optarg;
    const cli_option *o = &p->opts[i];
    if (o->kind == CLI_INT && !cli_parse_int(optarg, o->min, o->max, &p->int_value)) {
        char name[80];
        option_text(p, i, typed, name, sizeof name);
        return FAIL("%s: '%s' is not a whole number in %d..%d", name, optarg, o->min, o->max);
    }
    return CLI_OPTION;
}

/* ---- --help ---------------------------------------------------------------- */

#define HELP_COLUMN 26
#define LINE_WIDTH 80

/* Prints text from column col (the cursor is there) wrapped at LINE_WIDTH,
 * later lines indented to indent. */
static void print_wrapped(FILE *f, const char *text, int col, int indent)
{
    const char *s = text;
    while (*s) {
        while (*s == ' ') s++;
        size_t w = strcspn(s, " ");
        if (w == 0) break;
        if (col > indent && col + 1 + (int)w > LINE_WIDTH) {
            fprintf(f, "\n%*s", indent, "");
            col = indent;
        } else if (col > indent) {
            fputc(' ', f);
            col++;
        }
        fwrite(s, 1, w, f);
        col += (int)w;
        s += w;
    }
    fputc('\n', f);
}

void cli_print_options(FILE *f, const cli_option *opts, size_t n)
{
    for (size_t i = 0; i < n; i++) {
        const cli_option *o = &opts[i];
        char head[96];
        int len;
        if (o->short_name)
            len = snprintf(head, sizeof head, "  -%c, --%s%s%s", o->short_name, o->name, o->arg ? " " : "",
                           o->arg ? o->arg : "");
        else
            len = snprintf(head, sizeof head, "      --%s%s%s", o->name, o->arg ? " " : "", o->arg ? o->arg : "");
        fputs(head, f);
        int col = len;
        if (col + 2 > HELP_COLUMN) {
            fputc('\n', f);
            col = 0;
        }
        fprintf(f, "%*s", HELP_COLUMN - col, "");
        char text[512];
        if (o->kind == CLI_INT)
            snprintf(text, sizeof text, "%s; %d..%d, default %d", o->help, o->min, o->max, o->default_value);
        else
            snprintf(text, sizeof text, "%s", o->help);
        print_wrapped(f, text, HELP_COLUMN, HELP_COLUMN);
    }
}
