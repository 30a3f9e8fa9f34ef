/*
 * pbrt_tok.h - the tokenizer of pbrt-v4 scene files: words (directives,
 * bare true/false), quoted strings (with backslash escapes), numbers, the
 * brackets [ ], and '#' comments to the end of the line, over a (data,
 * size) buffer that need not end with a NUL. Every token carries the line
 * it starts on, for the "file:line: what" messages of the reader
 * (scene_pbrt.c).
 */
#ifndef PK_PBRT_TOK_H
#define PK_PBRT_TOK_H

#include "../paprsek_internal.h"

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

typedef enum pbrt_tok_kind {
    PBRT_TOK_END,     /* the end of the input */
    PBRT_TOK_WORD,    /* a bare word: a directive, true, false */
    PBRT_TOK_STRING,  /* "...": text is the raw bytes between the quotes */
    PBRT_TOK_NUMBER,  /* number holds its value */
    PBRT_TOK_LBRACK,  /* [ */
    PBRT_TOK_RBRACK,  /* ] */
    PBRT_TOK_ERROR    /* an unterminated string, a stray byte: message in the tokenizer */
} pbrt_tok_kind;

typedef struct pbrt_token {
    pbrt_tok_kind kind;
    const char *text;  /* the token's bytes (for a string: inside the quotes) */
    size_t len;
    size_t line;       /* 1-based line where it starts */
    double number;     /* PBRT_TOK_NUMBER: the value (integers exact to 2^53) */
    bool integer;      /* PBRT_TOK_NUMBER: written without '.', 'e' or inf/nan */
    bool escapes;      /* PBRT_TOK_STRING: holds a backslash */
} pbrt_token;

/* Invariants: start <= p <= end; line is the line of p. */
typedef struct pbrt_tokenizer {
    const char *start, *p, *end;
    size_t line;
    bool has_peek;
    pbrt_token peek;
    char why[96];      /* what a PBRT_TOK_ERROR token is */
} pbrt_tokenizer;

PK_HIDDEN void pbrt_tok_init(pbrt_tokenizer *t, const char *data, size_t size);
/* The next token (consumed). */
PK_HIDDEN pbrt_token pbrt_tok_next(pbrt_tokenizer *t);
/* The next token, left to be returned by pbrt_tok_next. */
PK_HIDDEN pbrt_token pbrt_tok_peek(pbrt_tokenizer *t);

/* A string token's text with its escapes decoded (\n \t \b \f \r \\ \" \'),
 * into out (cap bytes, NUL-terminated, cut to fit); returns the decoded
 * length (which may exceed cap - 1 when cut). */
PK_HIDDEN size_t pbrt_tok_string(const pbrt_token *tk, char *out, size_t cap);

/* True when the token is a word or string equal to w. */
PK_HIDDEN bool pbrt_tok_is(const pbrt_token *tk, const char *w);

#endif
