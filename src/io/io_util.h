/*
 * io_util.h - what the OBJ and MTL parsers share: a line reader over a
 * (data, size) buffer that is not NUL-terminated (CRLF, backslash
 * continuation), blank/comment-aware tokens, a fast locale-independent float
 * parser, overflow-checked integers and "file:line: ..." messages.
 */
#ifndef PK_IO_UTIL_H
#define PK_IO_UTIL_H

#include "../paprsek_internal.h"
#include "../math/vec3.h"

#define IO_WARN_KINDS 16     /* distinct unknown statement kinds remembered */
#define IO_WARN_KIND_LEN 24  /* bytes of a kind that are compared */

/* Invariants:
 *  1. p <= end; every byte read lies in [start of data, end).
 *  2. line is the number (1-based) of the first physical line of the
 *     statement last returned by io_next_line; next_line that of the next one.
 *  3. nkinds <= IO_WARN_KINDS; kinds[i] holds kind_len[i] bytes. */
typedef struct io_reader {
    pk_context *ctx;
    const char *name;          /* file name for messages (borrowed) */
    const char *p, *end;       /* input not yet read */
    size_t line, next_line;
    char *scratch;             /* joined continuation lines (owned) */
    size_t scratch_cap;
    char kinds[IO_WARN_KINDS][IO_WARN_KIND_LEN];
    size_t kind_len[IO_WARN_KINDS];
    int nkinds;
    bool kinds_full;           /* the "no longer reported" point was passed */
} io_reader;

PK_HIDDEN void io_reader_init(io_reader *r, pk_context *ctx, const char *name, const char *data, size_t size);
PK_HIDDEN void io_reader_free(io_reader *r);

/* Next logical line as [*ls, *le): 1, or 0 at the end of the input, or -1
 * when joining continuation lines ran out of memory (latched in ctx). */
PK_HIDDEN int io_next_line(io_reader *r, const char **ls, const char **le);

static inline bool io_is_blank(char c)
{
    return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f';
}

static inline const char *io_skip_blanks(const char *p, const char *e)
{
    while (p < e && io_is_blank(*p)) p++;
    return p;
}

static inline const char *io_token_end(const char *p, const char *e)
{
    while (p < e && !io_is_blank(*p)) p++;
    return p;
}

/* True when only blanks or a '#' comment remain in [p, e). */
static inline bool io_at_end(const char *p, const char *e)
{
    p = io_skip_blanks(p, e);
    return p == e || *p == '#';
}

/* The rest of a statement (a name that may hold blanks): from the first
 * non-blank to the last non-blank before a comment ('#' after a blank). */
PK_HIDDEN void io_rest(const char *p, const char *e, const char **rs, const char **re);

/* Parses a float at p (no leading blanks): [+-]digits[.digits][(e|E)[+-]digits],
 * also ".5", "5." and nan/inf/infinity. Returns the end of what was read, or
 * NULL when no number starts at p. Overflow gives +-inf, underflow 0. */
PK_HIDDEN const char *io_parse_float(const char *p, const char *e, float *out);

/* Parses [+-]digits; values beyond +-1e15 saturate (*out stays beyond that
 * bound so range checks fail). NULL when no digits start at p. */
PK_HIDDEN const char *io_parse_int(const char *p, const char *e, int64_t *out);

/* Reads up to max blank-separated finite floats from *pp, stopping at the end
 * of the statement or after max. *n receives the count. Errors (latched):
 * "bad number 'x'" and "number 'x' is not a finite float". */
PK_HIDDEN pk_status io_read_floats(io_reader *r, const char **pp, const char *e, float *out, int max, int *n);

/* "name:line: " + fmt, latched in ctx; returns status. */
PK_HIDDEN pk_status io_error(io_reader *r, pk_status status, const char *fmt, ...) PK_PRINTF(3, 4);
/* "name:line: " + fmt as a warning. */
PK_HIDDEN void io_warn(io_reader *r, const char *fmt, ...) PK_PRINTF(2, 3);
/* Warns "name:line: unknown statement 'kw' ignored (further ones not
 * reported)" the first time a kind is seen. */
PK_HIDDEN void io_warn_unknown(io_reader *r, const char *kw, size_t len);
/* Same, with a caller's text after the kind: "name:line: <what> ..." once per kind. */
PK_HIDDEN void io_warn_once(io_reader *r, const char *kind, size_t len, const char *what);

/* A soft failure: something a reader can do without (a texture, a material
 * library) failed with st. When st is a failure other than PK_ERR_NOMEM and
 * the context held no error before the attempt (was_ok: ctx->status was
 * PK_OK), the latched message is moved into why (nwhy bytes; PK_ERRMSG_MAX
 * holds any), the error is cleared and true returned: the caller warns with
 * why, saying where and what is used instead, and goes on. Otherwise false:
 * st stands (out of memory, or an earlier error that is not the reader's to
 * clear). */
PK_HIDDEN bool io_demote_error(pk_context *ctx, pk_status st, bool was_ok, char *why, size_t nwhy);

/* A copy of ctx with no error latched (same allocator and warning handler),
 * for a call whose error the reader latches again itself with where it
 * came from: "scene.json:12: meshes[0].obj: " + the copy's message. */
static inline pk_context io_scratch_context(const pk_context *ctx)
{
    pk_context c = *ctx;
    c.status = PK_OK;
    c.message[0] = '\0';
    return c;
}

/* The file rel that a scene file in folder dir names (dir NULL: rel as it
 * or empty, or rel absolute: rel as it is), read whole through scratch (an io_scratch_context of ctx), whose
 * message the reader latches again with where the name stood. On success
 * *data, and *full when full is not NULL (the joined path), are the
 * caller's to mem_free; on failure nothing is left to free. A name ending
 * in ".gz" is inflated (io_gunzip): *data holds what it holds. Out of memory
 * is latched in ctx as well, so that it stands whatever the caller adds. */
PK_HIDDEN pk_status io_read_relative(pk_context *ctx, pk_context *scratch, const char *dir, const char *rel, char **full,
                                     char **data, size_t *size);

/* Whether name ends in ".gz" (a gzip file that io_read_relative inflates). */
PK_HIDDEN bool io_is_gzip_name(const char *name);
/* Inflates the gzip data (size bytes; several members are read one after
 * another, as gunzip does) into a new NUL-terminated buffer *out of *out_size
 * bytes (mem_free it); at most PK_MAX_FILE_BYTES. Errors (latched in ctx,
 * name in front): not gzip data, damaged or cut short (PK_ERR_PARSE), too
 * large (PK_ERR_LIMIT), out of memory. */
PK_HIDDEN pk_status io_gunzip(pk_context *ctx, const char *name, const char *data, size_t size, char **out,
                              size_t *out_size);

/* Printing width for a token in a message (long tokens are cut). */
static inline int io_tok_len(const char *s, const char *e)
{
    size_t n = (size_t)(e - s);
    return n > 40 ? 40 : (int)n;
}

/* Whether four points make a planar rectangle, as pbrt-v4 checks a portal:
 * opposite edges parallel and adjacent ones perpendicular, within 0.001 in
 * the cosine of their unit directions (finite, no edge of length zero). */
PK_HIDDEN bool io_portal_is_rectangle(const vec3 p[4]);

#endif
