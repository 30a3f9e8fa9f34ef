/*
 * sha256.h - SHA-256 (FIPS 180-4), for checking that a weights file is one
 * of the files the denoiser was made for.
 */
#ifndef PK_SHA256_H
#define PK_SHA256_H

#include <stddef.h>
#include <stdint.h>

/* The digest of data[0..size) as 64 lowercase hex digits and a NUL (with
 * the CPU's SHA instructions where it has them). */
void sha256_hex(const void *data, size_t size, char out[65]);
/* The same in plain C, whatever the CPU (for the tests). */
void sha256_hex_portable(const void *data, size_t size, char out[65]);

#endif
