/*
 * unet.h - Open Image Denoise's U-Net, run on the CPU through oneDNN
 * (loaded at run time, like Embree): 3x3 convolutions with ReLU, 2x2 max
 * pooling, nearest-neighbour upsampling and skip connections, over images
 * whose sides are multiples of 16. The layers and their channel counts are
 * read from the weights (tza.h); both of OIDN's base networks (the default
 * and "small") have this shape.
 *
 * Activations are stored as oneDNN's nChw16c (blocks of 16 channels, each
 * block a plane of pixels whose 16 channels are adjacent), so a block-aligned
 * channel range of a tensor is itself a dense tensor: concatenation costs
 * nothing, as each producer writes into its part of the concatenated tensor.
 */
#ifndef PK_UNET_H
#define PK_UNET_H

#include "tza.h"

enum { UNET_CONVS = 16 };

/* The convolution layers in order, as the weights name them. */
PK_HIDDEN extern const char *const unet_conv_names[UNET_CONVS];

typedef struct unet unet;

/* The weights of archive a checked against the U-Net's shape and converted
 * to float (binary16 widened at load); name is the file, for messages. */
PK_HIDDEN pk_status unet_create(pk_context *ctx, const char *name, const tza_archive *a, unet **out);
PK_HIDDEN void unet_destroy(unet *u);
/* Input channels the weights expect (3 colour, 6 + albedo, 9 + normal). */
PK_HIDDEN int unet_input_channels(const unet *u);
/* Floating-point operations of one pass over an h x w image (h, w multiples of 16). */
PK_HIDDEN double unet_flops(const unet *u, int h, int w);
/* Bytes of activations a pass over an h x w image needs. */
PK_HIDDEN size_t unet_activation_bytes(const unet *u, int h, int w);

/* Runs the network over one h x w image (multiples of 16) with threads
 * threads. in: the input channels, planar (channel c at in[c*h*w]); out:
 * 3 planar channels. layer (may be NULL) is called after every layer with
 * the layer's name and its output, planar (channels x hl x wl), for tests.
 * Bit-identical for every thread count. */
typedef void (*unet_layer_fn)(void *user, const char *name, int channels, int hl, int wl, const float *planar);
PK_HIDDEN pk_status unet_run(pk_context *ctx, unet *u, int h, int w, int threads, const float *in, float *out,
                             unet_layer_fn layer, void *user);

/* Layer k's input and output channels as the weights have them, and its
 * level (its image is the input's size divided by 2^level). */
PK_HIDDEN void unet_layer_shape(const unet *u, int k, int *ic, int *oc, int *level);
/* Seconds of the last unet_run: planning (0 when the plan of the previous
 * run was reused), each convolution, and the rest (pooling, upsampling,
 * layout changes). For bench/denoise_layers.sh. */
PK_HIDDEN void unet_last_times(const unet *u, double *plan, double conv[UNET_CONVS], double *rest);

/* Whether oneDNN can be loaded (why says otherwise, n bytes). */
PK_HIDDEN bool unet_backend_available(pk_context *ctx, char *why, size_t n);
/* What oneDNN chose for the convolutions of the last run ("brgconv:avx512_core" ...). */
PK_HIDDEN const char *unet_backend_impl(const unet *u);

#endif
