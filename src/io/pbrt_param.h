/*
 * pbrt_param.h - pbrt-v4 parameter lists ("type name" value...): read from
 * the tokenizer into a plist of typed values, offered as a pdict (one
 * borrowed entry per parameter, keeping its type name and line: the
 * reader's pd_source puts "file:line: " in front of every message), and
 * pbrt's typed getters with pbrt's messages. A getter finds its parameter
 * through pd_get, which marks it; pd_report_unused then warns about the rest.
 */
#ifndef PK_PBRT_PARAM_H
#define PK_PBRT_PARAM_H

#include "../math/vec3.h"
#include "../paprsek_internal.h"
#include "pbrt_tok.h"
#include "pdict.h"

typedef enum ptype {
    PT_INT, PT_FLOAT, PT_POINT2, PT_VECTOR2, PT_POINT3, PT_VECTOR3, PT_NORMAL, PT_RGB, PT_SPECTRUM,
    PT_BLACKBODY, PT_STRING, PT_TEXTURE, PT_BOOL
} ptype;
#define TB(t) (1u << (t)) /* a set of ptypes */

/* Invariants: the values are numbers (num) or strings (str), never both:
 * strings for string and texture, one name or none for spectrum; their
 * count is not 0 and a multiple of the type's arity (read_params checks). */
typedef struct pparam {
    ptype type;
    char tname[16];      /* the type as written ("point" or "point3") */
    char name[64];
    size_t line;
    double *num;
    size_t nnum, cap_num;
    char **str;
    size_t nstr, cap_str;
    bool from_attribute; /* a default of an Attribute directive */
} pparam;

typedef struct plist {
    pparam *p;
    size_t n, cap;
} plist;

PK_HIDDEN void pb_param_free(const pk_allocator *a, pparam *q);
/* A deep copy of q into out. */
PK_HIDDEN pk_status pb_param_copy(pk_context *ctx, const pparam *q, pparam *out);
/* Frees the list's parameters and empties d. */
PK_HIDDEN void pb_list_clear(pdict *d, plist *pl);

/* The parameter list that follows a directive's arguments, into *pl (the
 * previous one cleared) and d (pd_from_pbrt). Errors at their lines through
 * d's source: syntax, a duplicate name, a wrong count of values. */
PK_HIDDEN pk_status pb_read_params(pdict *d, plist *pl, pbrt_tokenizer *t);
/* d (pd_init'ed with the reader's source) as the list pl: one borrowed
 * entry per parameter, in order, with its type name and line, node the
 * parameter itself. The Attribute defaults are marked: they are not the
 * directive's own, and what it does not use of them is no news. Called again
 * whenever pl changes (its array may move). */
PK_HIDDEN pk_status pd_from_pbrt(pdict *d, const plist *pl);

/* A message at a line of the current file (through d's source). */
PK_HIDDEN pk_status pb_fail(pdict *d, size_t line, pk_status st, const char *fmt, ...) PK_PRINTF(4, 5);

/* The parameter named name, marked used; NULL when there is none. */
PK_HIDDEN pparam *pb_param(pdict *d, const char *name);
/* A parameter of one of the types (a TB set); a present parameter of
 * another type is an error ("parameter 'TYPE NAME' should be WANT"). */
PK_HIDDEN pk_status pb_typed(pdict *d, const char *name, unsigned types, const char *want, pparam **out);
/* The typed getters: absent, *v is left as it is (the caller's default). */
PK_HIDDEN pk_status pb_float(pdict *d, const char *name, float *v);
PK_HIDDEN pk_status pb_int(pdict *d, const char *name, int64_t lo, int64_t hi, int64_t *v);
PK_HIDDEN pk_status pb_bool(pdict *d, const char *name, bool *v);
PK_HIDDEN pk_status pb_string(pdict *d, const char *name, const char **v);
PK_HIDDEN pk_status pb_vec3(pdict *d, const char *name, vec3 *v);

#endif
