/*
 * tza_build.h - writes small tensor archives in memory for the tests and
 * the fuzz seeds: synthetic tensors (not anyone's trained weights), laid
 * out as Open Image Denoise's format has them (tza.h).
 */
#ifndef PK_TZA_BUILD_H
#define PK_TZA_BUILD_H

#include <stdint.h>
#include <stdlib.h>
#include <string.h>

typedef struct tzab {
    unsigned char *p;
    size_t n, cap;
    /* the table, written at the end */
    unsigned char table[65536];
    size_t tn;
    uint32_t count;
} tzab;

static void tzab_put(tzab *b, const void *v, size_t n)
{
    if (b->n + n > b->cap) {
        b->cap = (b->n + n) * 2 + 1024;
        b->p = realloc(b->p, b->cap);
    }
    memcpy(b->p + b->n, v, n);
    b->n += n;
}

static void tzab_u(unsigned char *dst, uint64_t v, int bytes)
{
    for (int i = 0; i < bytes; i++) dst[i] = (unsigned char)(v >> (8 * i));
}

static void tzab_begin(tzab *b)
{
    memset(b, 0, sizeof *b);
    unsigned char h[12] = {0xD7, 0x41, 2, 0};
    tzab_put(b, h, 12);
}

/* A tensor of binary16 values (half[i] as given) named name. */
static void tzab_tensor(tzab *b, const char *name, int nd, const uint32_t *dims, const char *layout,
                        const uint16_t *half)
{
    static const unsigned char zero[64] = {0};
    tzab_put(b, zero, (64 - b->n % 64) % 64);
    uint64_t off = b->n, count = 1;
    for (int d = 0; d < nd; d++) count *= dims[d];
    for (uint64_t i = 0; i < count; i++) {
        unsigned char v[2];
        tzab_u(v, half[i], 2);
        tzab_put(b, v, 2);
    }
    unsigned char *t = b->table + b->tn;
    size_t len = strlen(name);
    tzab_u(t, len, 2);
    memcpy(t + 2, name, len);
    t += 2 + len;
    *t++ = (unsigned char)nd;
    for (int d = 0; d < nd; d++, t += 4) tzab_u(t, dims[d], 4);
    memcpy(t, layout, (size_t)nd);
    t += nd;
    *t++ = 'h';
    tzab_u(t, off, 8);
    t += 8;
    b->tn = (size_t)(t - b->table);
    b->count++;
}

/* Finishes the archive; returns its bytes (caller frees), *size its length. */
static unsigned char *tzab_end(tzab *b, size_t *size)
{
    static const unsigned char zero[64] = {0};
    tzab_put(b, zero, (64 - b->n % 64) % 64);
    uint64_t table = b->n;
    unsigned char c[4];
    tzab_u(c, b->count, 4);
    tzab_put(b, c, 4);
    tzab_put(b, b->table, b->tn);
    tzab_u(b->p + 4, table, 8);
    *size = b->n;
    return b->p;
}

/* A U-Net of OIDN's shape with every layer of 16 channels (ic inputs),
 * weights w(i) = small values from a fixed sequence. */
static unsigned char *tzab_unet(int ic, size_t *size)
{
    static const char *names[16] = {"enc_conv0", "enc_conv1", "enc_conv2", "enc_conv3", "enc_conv4", "enc_conv5a",
                                    "enc_conv5b", "dec_conv4a", "dec_conv4b", "dec_conv3a", "dec_conv3b",
                                    "dec_conv2a", "dec_conv2b", "dec_conv1a", "dec_conv1b", "dec_conv0"};
    const uint32_t in[16] = {(uint32_t)ic, 16, 16, 16, 16, 16, 16, 32, 16, 32, 16, 32, 16, (uint32_t)(16 + ic), 16, 16};
    tzab b;
    tzab_begin(&b);
    uint16_t *h = malloc(16 * 32 * 9 * sizeof *h);
    for (int k = 0; k < 16; k++) {
        uint32_t oc = k == 15 ? 3 : 16, wd[4] = {oc, in[k], 3, 3}, bd[1] = {oc};
        for (uint32_t i = 0; i < oc * in[k] * 9; i++) h[i] = (uint16_t)(0x2000 + (i * 2654435761u >> 22) % 0x800) | (i & 1 ? 0x8000 : 0);
        char n[64];
        strcpy(n, names[k]);
        strcat(n, ".weight");
        tzab_tensor(&b, n, 4, wd, "oihw", h);
        for (uint32_t i = 0; i < oc; i++) h[i] = 0x2400;
        strcpy(n, names[k]);
        strcat(n, ".bias");
        tzab_tensor(&b, n, 1, bd, "x", h);
    }
    free(h);
    return tzab_end(&b, size);
}

#endif
