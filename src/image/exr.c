/*
 * exr.c - OpenEXR output through OpenEXRCore, the library's C API.
 *
 * exr_write_channels writes any number of named 32-bit float channels of one
 * size into a single-part scanline file: the RGB image is three of them
 * (R, G, B); arbitrary output variables can be more ("albedo.R",
 * "normal.X", "depth.Z", ...), as layers of the same part. FLOAT rather than
 * HALF: a renderer's linear values are kept bit for bit (no rounding to 11
 * bits of mantissa, no overflow to infinity above 65504), as a PFM would
 * keep them, at twice the size of HALF before compression.
 *
 * The bytes go through a write callback to a file descriptor the caller
 * opened (image_write.c's temporary file), so OpenEXR never opens, renames
 * or removes files itself; its messages come back through an error callback
 * instead of being printed.
 */
#include "image_write.h"

#include <errno.h>
#include <limits.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include <openexr.h>

typedef struct exr_sink {
    int fd;
    char msg[200]; /* the first error, from this file or from OpenEXR */
    exr_result_t (*compress)(exr_encode_pipeline_t *); /* OpenEXR's own, wrapped by compress_chunk */
} exr_sink;

static void sink_note(exr_sink *s, const char *fmt, ...) PK_PRINTF(2, 3);
static void sink_note(exr_sink *s, const char *fmt, ...)
{
    if (s->msg[0]) return;
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(s->msg, sizeof s->msg, fmt, ap);
    va_end(ap);
}

static exr_sink *sink_of(exr_const_context_t e)
{
    void *user = NULL;
    exr_get_user_data(e, &user);
    return user;
}

/* OpenEXR's messages: kept, never printed. */
static void on_exr_error(exr_const_context_t e, exr_result_t code, const char *msg)
{
    exr_sink *s = sink_of(e);
    if (s) sink_note(s, "OpenEXR: %s", msg && msg[0] ? msg : exr_get_default_error_message(code));
}

/* pwrite semantics, as OpenEXR asks: all of buffer at offset, or -1. */
static int64_t on_exr_write(exr_const_context_t e, void *user, const void *buffer, uint64_t sz, uint64_t offset,
                            exr_stream_error_func_ptr_t error_cb)
{
    (void)e;
    (void)error_cb;
    exr_sink *s = user;
    const unsigned char *p = buffer;
    uint64_t done = 0;
    while (done < sz) {
        size_t chunk = sz - done > (uint64_t)(SIZE_MAX >> 2) ? (SIZE_MAX >> 2) : (size_t)(sz - done);
        if (offset + done > (uint64_t)INT64_MAX) {
            sink_note(s, "write error: offset beyond the largest file");
            return -1;
        }
        ssize_t w = pwrite(s->fd, p + done, chunk, (off_t)(offset + done));
        if (w < 0) {
            if (errno == EINTR) continue;
            sink_note(s, "write error: %s", strerror(errno));
            return -1;
        }
        if (w == 0) {
            sink_note(s, "write error: nothing written");
            return -1;
        }
        done += (uint64_t)w;
    }
    return (int64_t)done;
}

/* OpenEXR's compression of a chunk, then the rule of the file format that
 * a chunk whose compressed bytes are not fewer than its raw bytes is stored
 * raw: a reader takes a chunk of the raw size as raw. OpenEXR 3.1 (Debian
 * 12) keeps compressed bytes of exactly the raw size, which every reader
 * then takes as pixels (upstream issue 2306): it happens to a chunk of
 * noisy floats now and then, and the chunk comes back as garbage. */
static exr_result_t compress_chunk(exr_encode_pipeline_t *pipe)
{
    exr_sink *s = pipe->encoding_user_data;
    exr_result_t rv = s->compress(pipe);
    if (rv != EXR_ERR_SUCCESS || pipe->compressed_bytes < pipe->packed_bytes) return rv;
    if (!pipe->compressed_buffer || pipe->compressed_alloc_size < pipe->packed_bytes) {
        sink_note(s, "OpenEXR: a chunk that does not compress has no room to be stored raw");
        return EXR_ERR_OUT_OF_MEMORY;
    }
    memcpy(pipe->compressed_buffer, pipe->packed_buffer, (size_t)pipe->packed_bytes);
    pipe->compressed_bytes = (size_t)pipe->packed_bytes;
    return EXR_ERR_SUCCESS;
}

/* Fails with why from the sink's first message, or what. */
static int fail(exr_sink *s, exr_result_t rv, const char *what, char *why, size_t nwhy)
{
    if (s->msg[0])
        snprintf(why, nwhy, "%s", s->msg);
    else
        snprintf(why, nwhy, "OpenEXR: %s: %s", what, exr_get_default_error_message(rv));
    return -1;
}

int exr_write_channels(int fd, int width, int height, const exr_channel *ch, int n, char *why, size_t nwhy)
{
    if (width <= 0 || height <= 0 || n <= 0 || n > PK_EXR_MAX_CHANNELS) {
        snprintf(why, nwhy, "OpenEXR: cannot write %d channels of %dx%d pixels", n, width, height);
        return -1;
    }
    exr_sink sink = {.fd = fd, .msg = ""};
    exr_context_initializer_t init = EXR_DEFAULT_CONTEXT_INITIALIZER;
    init.error_handler_fn = on_exr_error;
    init.user_data = &sink;
    init.write_fn = on_exr_write;
    /* (the name is only for OpenEXR's messages: the write callback is used) */
    exr_context_t e = NULL;
    exr_result_t rv = exr_start_write(&e, "image.exr", EXR_WRITE_FILE_DIRECTLY, &init);
    if (rv != EXR_ERR_SUCCESS) {
        exr_finish(&e);
        return fail(&sink, rv, "cannot start the writer", why, nwhy);
    }
    int part = 0;
    int rc = -1;
    exr_encode_pipeline_t pipe;
    memset(&pipe, 0, sizeof pipe);
    int have_pipe = 0;
    const char *what = "cannot describe the image";
    rv = exr_add_part(e, NULL, EXR_STORAGE_SCANLINE, &part);
    if (rv == EXR_ERR_SUCCESS) rv = exr_initialize_required_attr_simple(e, part, width, height, PK_EXR_COMPRESSION);
    for (int c = 0; c < n && rv == EXR_ERR_SUCCESS; c++)
        rv = exr_add_channel(e, part, ch[c].name, EXR_PIXEL_FLOAT, EXR_PERCEPTUALLY_LOGARITHMIC, 1, 1);
    if (rv == EXR_ERR_SUCCESS) {
        what = "cannot write the header";
        rv = exr_write_header(e);
    }
    int32_t lines = 0;
    if (rv == EXR_ERR_SUCCESS) rv = exr_get_scanlines_per_chunk(e, part, &lines);
    if (rv == EXR_ERR_SUCCESS && lines <= 0) rv = EXR_ERR_INVALID_ARGUMENT;
    for (int y = 0; y < height && rv == EXR_ERR_SUCCESS; y += lines) {
        what = "cannot encode the pixels";
        exr_chunk_info_t cinfo;
        rv = exr_write_scanline_chunk_info(e, part, y, &cinfo);
        if (rv != EXR_ERR_SUCCESS) break;
        rv = have_pipe ? exr_encoding_update(e, part, &cinfo, &pipe) : exr_encoding_initialize(e, part, &cinfo, &pipe);
        if (rv != EXR_ERR_SUCCESS) break;
        have_pipe = 1;
        /* The file's channels are sorted by name: match ours to them. */
        for (int k = 0; k < pipe.channel_count && rv == EXR_ERR_SUCCESS; k++) {
            exr_coding_channel_info_t *out = &pipe.channels[k];
            const exr_channel *in = NULL;
            for (int c = 0; c < n && !in; c++)
                if (strcmp(ch[c].name, out->channel_name) == 0) in = &ch[c];
            if (!in) {
                rv = EXR_ERR_INVALID_ARGUMENT;
                break;
            }
            out->user_bytes_per_element = (int16_t)sizeof(float);
            out->user_data_type = EXR_PIXEL_FLOAT;
            out->user_pixel_stride = (int32_t)(in->pixel_stride * sizeof(float));
            out->user_line_stride = (int32_t)(in->row_stride * sizeof(float));
            out->encode_from_ptr = (const uint8_t *)(in->data + (size_t)cinfo.start_y * in->row_stride);
        }
        if (rv == EXR_ERR_SUCCESS && y == 0) {
            rv = exr_encoding_choose_default_routines(e, part, &pipe);
            if (rv == EXR_ERR_SUCCESS && pipe.compress_fn) {
                sink.compress = pipe.compress_fn;
                pipe.compress_fn = compress_chunk;
                pipe.encoding_user_data = &sink;
            }
        }
        if (rv == EXR_ERR_SUCCESS) rv = exr_encoding_run(e, part, &pipe);
    }
    if (have_pipe) {
        exr_result_t d = exr_encoding_destroy(e, &pipe);
        if (rv == EXR_ERR_SUCCESS) rv = d;
    }
    if (rv == EXR_ERR_SUCCESS) {
        /* exr_finish writes the table of chunk offsets */
        what = "cannot finish the file";
        rv = exr_finish(&e);
        if (rv == EXR_ERR_SUCCESS) rc = 0;
    } else {
        exr_finish(&e);
    }
    if (rc != 0) return fail(&sink, rv, what, why, nwhy);
    return 0;
}
