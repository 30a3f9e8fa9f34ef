/*
 * pdict.h - one parameter dictionary for the scene readers and the public
 * scene-building API (pbrt-v4's ParameterDictionary, Mitsuba's
 * Properties): the named values a front end found for one thing it
 * describes (a material, a light), read by that thing's creator through
 * typed getters that give the default when a name is absent and check
 * ranges. Every entry is marked when it is queried (or declared, see
 * pd_declare); pd_report_unused gives the one "ignored" warning for the
 * rest.
 *
 * The front end fills the dictionary (pd_from_cjson for JSON objects,
 * pd_set_* for the API's pk_params) and says, through a pd_source, where
 * an entry came from: the getters format "what is wrong" and the source
 * puts the location in front ("file:line: json.path: " for JSON, "material
 * 'white': kd: " for the API), latches the error in the context and
 * returns its status. Nothing is printed.
 */
#ifndef PK_PDICT_H
#define PK_PDICT_H

#include "../math/vec3.h"
#include "../paprsek_internal.h"
#include "../scene/texture.h"

typedef enum pd_kind {
    PD_NUMBER,  /* num */
    PD_NUMBERS, /* nums[0..n), a list; elements at or after first_other are not numbers */
    PD_BOOL,    /* b */
    PD_STRING,  /* str */
    PD_NULL,
    PD_OBJECT,  /* a nested object (a texture, a material): node, read through the source */
    PD_OTHER,   /* anything else the syntax allows */
} pd_kind;

/* Invariants: name is never NULL; for PD_NUMBERS, first_other <= n and
 * nums holds n values (those from first_other on are not meaningful). */
typedef struct pd_entry {
    const char *name;
    pd_kind kind;
    bool used;          /* queried or declared */
    bool b;
    double num;
    const double *nums;
    size_t n, first_other;
    const char *str;
    const void *node;   /* the front end's own node (a cJSON item), for locations */
    const char *type;   /* the front end's type of the value or NULL, never copied: pbrt's "rgb", "float";
                           Mitsuba's element, <float>, <rgb>, <ref> */
    size_t line;        /* where the front end read it (0: unknown) */
} pd_entry;

typedef struct pdict pdict;

/* What a front end does for its dictionaries. self is the front end's
 * state (pd_init's). Any member may be NULL: then messages read "WHAT:
 * NAME: what is wrong" (WHAT: the dictionary's what), and nested objects
 * are refused. */
typedef struct pd_source {
    /* Latches msg about entry e (NULL: the dictionary itself; elem >= 0:
     * that element of e's list; PD_AT_ENTRY: e's location, the
     * dictionary's name) at its location; returns st. */
    pk_status (*fail)(void *self, const pdict *d, const pd_entry *e, long elem, pk_status st, const char *msg);
    /* The "unknown key ignored" warning for e. */
    void (*warn_unused)(void *self, const pdict *d, const pd_entry *e);
    /* Reads the texture object e into *ref (colour: its pixels are sRGB
     * colours); an image that cannot be used is a warning and *loaded false. */
    pk_status (*texture)(void *self, const pdict *d, const pd_entry *e, bool colour, tex_ref *ref, bool *loaded);
    /* Fills sub (pd_init'ed by the caller) from the object e. */
    pk_status (*nested)(void *self, const pdict *d, const pd_entry *e, pdict *sub);
    /* The scene material that element elem of e's list names (a mix's
     * "materials"), defined before the one being read; NULL: materials
     * cannot be named here. */
    pk_status (*material)(void *self, const pdict *d, const pd_entry *e, long elem, uint32_t *index);
} pd_source;

/* Invariants: n <= cap; e[0..n) in the order the front end gave them;
 * names, strings and lists are owned by the dictionary when owns is set,
 * else borrowed from the front end's tree, which outlives the dictionary,
 * but for the lists pd_from_cjson makes (own_lists). */
struct pdict {
    pk_context *ctx;
    const pd_source *src;
    void *self;
    const char *what;   /* "material 'white'" for default messages */
    char path[192];     /* the front end's name of the dictionary (a JSON path) */
    const void *node;   /* the front end's node of the dictionary itself */
    pd_entry *e;
    size_t n, cap;
    bool owns;
    bool own_lists;
    bool dups;          /* a name may be given twice, the first read (Mitsuba): no "duplicate key" */
};

/* An empty dictionary; src NULL: the default messages. */
PK_HIDDEN void pd_init(pdict *d, pk_context *ctx, const pd_source *src, void *self, const char *what, bool owns);
PK_HIDDEN void pd_free(pdict *d);

/* Appends an entry (a copy of *e; its strings and list are copied when the
 * dictionary owns them). Errors: out of memory. */
PK_HIDDEN pk_status pd_add(pdict *d, const pd_entry *e);
/* Sets name to a value: the entry of that name is replaced, or added. */
PK_HIDDEN pk_status pd_set(pdict *d, const pd_entry *e);
/* Every entry unmarked again (a dictionary used for a second thing). */
PK_HIDDEN void pd_clear_marks(pdict *d);
/* Every entry marked: a thing that takes whatever it is given (an
 * unsupported type, rendered as a stand-in, warns once for all). */
PK_HIDDEN void pd_mark_all(pdict *d);

/* The first entry named name, marked; NULL when there is none. */
PK_HIDDEN const pd_entry *pd_get(pdict *d, const char *name);
static inline bool pd_has(pdict *d, const char *name) { return pd_get(d, name) != NULL; }
/* Marks the entries named names[0..n) as read without reading them: a
 * creator declares its parameters first so that the unknown ones are
 * reported before any value is checked (the JSON reader's order). */
PK_HIDDEN void pd_declare(pdict *d, const char *const *names, size_t n);
/* The one "ignored" warning (the source's, or "WHAT: NAME: unknown
 * parameter ignored"), for each unmarked entry, in the order given; a
 * marked name given twice is an error ("duplicate key", unless dups),
 * which stops the walk. */
PK_HIDDEN pk_status pd_report_unused(pdict *d);

/* A message about e (NULL: the dictionary; elem >= 0: an element of its
 * list; PD_AT_ENTRY: at e's location but about the whole dictionary, as
 * "a distant light has no position"), latched in the context; returns st. */
#define PD_AT_ENTRY (-2L)
PK_HIDDEN pk_status pd_fail(const pdict *d, const pd_entry *e, long elem, pk_status st, const char *fmt, ...)
    PK_PRINTF(5, 6);

/* The ranges of the numeric getters, each with its message. */
typedef enum pd_range {
    PD_ANY,       /* finite */
    PD_UNIT,      /* 0..1: "must be in 0..1" */
    PD_POSITIVE,  /* > 0: "must be a positive number" */
    PD_NONNEG,    /* >= 0: "must not be negative" */
} pd_range;
typedef enum pd_vrange {
    PD_V_ANY,          /* finite */
    PD_V_COLOUR,       /* >= 0: "colour components must not be negative" */
    PD_V_REFLECTANCE,  /* 0..1: "components must be in 0..1" */
    PD_V_POSITIVE,     /* > 0: "components must be positive" */
    PD_V_NONNEG,       /* >= 0: "components must not be negative" */
} pd_vrange;

/* The typed getters: absent, *out = def and PK_OK; present, the value
 * checked ("must be a number", "must be a finite number", the range's
 * message). The entry is marked. */
PK_HIDDEN pk_status pd_float(pdict *d, const char *name, float def, pd_range r, float *out);
/* n numbers, finite ("must be an array of N numbers", "numbers must be finite"). */
PK_HIDDEN pk_status pd_floats(pdict *d, const char *name, int n, float *out);
PK_HIDDEN pk_status pd_vec3(pdict *d, const char *name, vec3 def, pd_vrange r, vec3 *out);
/* An integer in lo..hi ("must be an integer", "must be an integer in
 * LO..HI"; above hi is PK_ERR_LIMIT). */
PK_HIDDEN pk_status pd_int(pdict *d, const char *name, int def, int lo, int hi, int *out);
PK_HIDDEN pk_status pd_bool(pdict *d, const char *name, bool def, bool *out);  /* "must be true or false" */
/* A non-empty string ("must be a non-empty string"); absent: *out = def. */
PK_HIDDEN pk_status pd_string(pdict *d, const char *name, const char *def, const char **out);
/* A texture object through the source (pd_source.texture). */
PK_HIDDEN pk_status pd_texture(pdict *d, const pd_entry *e, bool colour, tex_ref *ref, bool *loaded);
/* A nested object as a dictionary (pd_free it); path and node are the
 * entry's, its source the parent's. */
PK_HIDDEN pk_status pd_nested(pdict *d, const pd_entry *e, pdict *sub);

/* ---- the cJSON adapter (JSON scenes; glTF later) ---- */

struct cJSON;
/* Fills d with the members of the object obj (whose path is path), in
 * order, duplicates kept (pd_report_unused finds them). Numbers are kept
 * as the doubles cJSON read; nested objects as PD_OBJECT with their node.
 * Borrowed: obj must outlive d. */
PK_HIDDEN pk_status pd_from_cjson(pdict *d, const struct cJSON *obj, const char *path);

#endif
