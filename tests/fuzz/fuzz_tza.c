/* fuzz_tza.c - the denoiser's weights reader: the tensor archive parser
 * (tza.h), then the U-Net's shape checks and weight conversion (unet.h).
 * Oracle: a failure carries a message; a parsed archive's tensors lie
 * inside the buffer; every tensor element can be read. */
#include "fuzz.h"

#include "denoise/tza.h"
#include "denoise/unet.h"
#include "paprsek_internal.h"

#include <math.h>

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    pk_context *ctx = NULL;
    if (pk_context_create(NULL, &ctx) != PK_OK) return 0;
    tza_archive a;
    pk_status st = tza_parse(ctx, "fuzz.tza", data, size, &a);
    fuzz_check_error(ctx, st);
    if (st == PK_OK) {
        volatile float sink = 0.0f;
        for (size_t i = 0; i < a.n; i++) {
            const tza_tensor *t = &a.t[i];
            const size_t bytes = t->count * (t->dtype == 'h' ? 2u : 4u);
            if (t->data < data || t->data + bytes > data + size) {
                fprintf(stderr, "fuzz: tensor %s lies outside the buffer\n", t->name);
                abort();
            }
            if (t->count) sink += tza_get(t, 0) + tza_get(t, t->count - 1);
        }
        (void)sink;
        unet *u = NULL;
        st = unet_create(ctx, "fuzz.tza", &a, &u);
        fuzz_check_error(ctx, st);
        unet_destroy(u);
        tza_free(&ctx->alloc, &a);
    }
    pk_context_destroy(ctx);
    return 0;
}
