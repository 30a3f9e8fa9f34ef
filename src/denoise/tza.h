/*
 * tza.h - the tensor archive that Open Image Denoise stores its trained
 * weights in: a header (magic 0x41D7, version 2.x, the offset of the
 * table), the tensors' data, each aligned to 64 bytes, then the table (for
 * each tensor: its name, dimensions, layout letters such as "oihw", data
 * type and offset). Little-endian throughout.
 */
#ifndef PK_TZA_H
#define PK_TZA_H

#include "paprsek_internal.h"

#define TZA_MAX_DIMS 4
#define TZA_MAX_NAME 64
#define TZA_MAX_TENSORS 256

typedef struct tza_tensor {
    char name[TZA_MAX_NAME];
    int ndims;
    uint32_t dims[TZA_MAX_DIMS];
    char layout[TZA_MAX_DIMS + 1];
    char dtype;                /* 'h' binary16, 'f' binary32 */
    const unsigned char *data; /* inside the parsed buffer */
    size_t count;              /* elements */
} tza_tensor;

typedef struct tza_archive {
    size_t n;
    tza_tensor *t;
} tza_archive;

/* Parses data[0..size) (which must outlive the archive); name is what
 * errors are reported as ("name: byte N: what is wrong"). Every offset and
 * size is checked against the buffer; names are unique. */
PK_HIDDEN pk_status tza_parse(pk_context *ctx, const char *name, const void *data, size_t size, tza_archive *out);
PK_HIDDEN void tza_free(const pk_allocator *al, tza_archive *a);
/* The tensor called name, or NULL. */
PK_HIDDEN const tza_tensor *tza_find(const tza_archive *a, const char *name);
/* Element i of t as a float (binary16 widened exactly). */
PK_HIDDEN float tza_get(const tza_tensor *t, size_t i);

#endif
