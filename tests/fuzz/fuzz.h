/*
 * fuzz.h - the libFuzzer entry point every harness defines. Harnesses are
 * linked either with libFuzzer (make fuzz) or with replay.c, which runs a
 * corpus through them as an ordinary test.
 */
#ifndef PK_FUZZ_H
#define PK_FUZZ_H

#include <stddef.h>
#include <stdint.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#endif
