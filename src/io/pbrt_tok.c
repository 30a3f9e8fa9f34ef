/*
 * pbrt_tok.c - the pbrt-v4 tokenizer (pbrt_tok.h).
 */
#include "pbrt_tok.h"

#include "io_util.h"

#include <stdio.h>
#include <string.h>

void pbrt_tok_init(pbrt_tokenizer *t, const char *data, size_t size)
{
    memset(t, 0, sizeof *t);
    t->start = t->p = data ? data : "";
    t->end = t->p + (data ? size : 0);
    t->line = 1;
    /* a UTF-8 byte order mark is not part of the scene */
    if (t->end - t->p >= 3 && (unsigned char)t->p[0] == 0xEF && (unsigned char)t->p[1] == 0xBB &&
        (unsigned char)t->p[2] == 0xBF)
        t->p += 3;
}

static bool is_space(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\v' || c == '\f'; }

/* Bytes that end a bare word or a number. */
static bool is_delim(char c) { return is_space(c) || c == '"' || c == '[' || c == ']' || c == '#'; }

static pbrt_token error_token(pbrt_tokenizer *t, const char *at, size_t line, const char *why)
{
    pbrt_token tk = {PBRT_TOK_ERROR, at, 1, line, 0.0, false, false};
    snprintf(t->why, sizeof t->why, "%s", why);
    t->p = t->end; /* nothing after an error is read */
    return tk;
}

static pbrt_token scan(pbrt_tokenizer *t)
{
    for (;;) {
        while (t->p < t->end && is_space(*t->p)) {
            if (*t->p == '\n') t->line++;
            t->p++;
        }
        if (t->p < t->end && *t->p == '#') {
            while (t->p < t->end && *t->p != '\n') t->p++;
            continue;
        }
        break;
    }
    pbrt_token tk = {PBRT_TOK_END, t->p, 0, t->line, 0.0, false, false};
    if (t->p == t->end) return tk;
    const char c = *t->p;
    if (c == '[' || c == ']') {
        tk.kind = c == '[' ? PBRT_TOK_LBRACK : PBRT_TOK_RBRACK;
        tk.len = 1;
        t->p++;
        return tk;
    }
    if (c == '"') {
        const char *s = ++t->p;
        while (t->p < t->end && *t->p != '"') {
            if (*t->p == '\n') return error_token(t, s - 1, tk.line, "a string runs past the end of its line");
            if (*t->p == '\\') {
                tk.escapes = true;
                if (++t->p == t->end) break;
                if (*t->p == '\n') return error_token(t, s - 1, tk.line, "a string runs past the end of its line");
            }
            t->p++;
        }
        if (t->p >= t->end) return error_token(t, s - 1, tk.line, "a string is not closed before the end of the file");
        tk.kind = PBRT_TOK_STRING;
        tk.text = s;
        tk.len = (size_t)(t->p - s);
        t->p++;
        return tk;
    }
    const char *s = t->p;
    while (t->p < t->end && !is_delim(*t->p)) t->p++;
    tk.text = s;
    tk.len = (size_t)(t->p - s);
    if ((c >= '0' && c <= '9') || c == '-' || c == '+' || c == '.') {
        bool integer = true;
        for (size_t i = 0; i < tk.len; i++)
            if (s[i] == '.' || s[i] == 'e' || s[i] == 'E') integer = false;
        if (integer) {
            int64_t v;
            const char *e = io_parse_int(s, t->p, &v);
            if (e == t->p && v > -((int64_t)1 << 53) && v < ((int64_t)1 << 53)) {
                tk.kind = PBRT_TOK_NUMBER;
                tk.number = (double)v;
                tk.integer = true;
                return tk;
            }
        }
        float f;
        const char *e = io_parse_float(s, t->p, &f);
        if (e != t->p) {
            char why[80];
            snprintf(why, sizeof why, "bad number '%.*s'", io_tok_len(s, t->p), s);
            return error_token(t, s, tk.line, why);
        }
        tk.kind = PBRT_TOK_NUMBER;
        tk.number = (double)f;
        return tk;
    }
    if ((unsigned char)c < 0x20 || (unsigned char)c >= 0x7f) {
        char why[64];
        snprintf(why, sizeof why, "unexpected byte 0x%02x", (unsigned)(unsigned char)c);
        return error_token(t, s, tk.line, why);
    }
    tk.kind = PBRT_TOK_WORD;
    return tk;
}

pbrt_token pbrt_tok_next(pbrt_tokenizer *t)
{
    if (t->has_peek) {
        t->has_peek = false;
        return t->peek;
    }
    return scan(t);
}

pbrt_token pbrt_tok_peek(pbrt_tokenizer *t)
{
    if (!t->has_peek) {
        t->peek = scan(t);
        t->has_peek = true;
    }
    return t->peek;
}

size_t pbrt_tok_string(const pbrt_token *tk, char *out, size_t cap)
{
    size_t n = 0;
    for (size_t i = 0; i < tk->len; i++) {
        char c = tk->text[i];
        if (c == '\\' && i + 1 < tk->len) {
            c = tk->text[++i];
            switch (c) {
            case 'n': c = '\n'; break;
            case 't': c = '\t'; break;
            case 'b': c = '\b'; break;
            case 'f': c = '\f'; break;
            case 'r': c = '\r'; break;
            default: break; /* \\ \" \' and any other: the byte itself */
            }
        }
        if (cap && n + 1 < cap) out[n] = c;
        n++;
    }
    if (cap) out[n < cap ? n : cap - 1] = '\0';
    return n;
}

bool pbrt_tok_is(const pbrt_token *tk, const char *w)
{
    if (tk->kind != PBRT_TOK_WORD && tk->kind != PBRT_TOK_STRING) return false;
    size_t n = strlen(w);
    return tk->len == n && memcmp(tk->text, w, n) == 0;
}
