/*
 * make_codec_seeds.c - writes the fuzz seeds of compressed glTF and WebP:
 * tests/fuzz/corpus/gltf/seed-meshopt.gltf (EXT_meshopt_compression: vertex
 * and triangle streams, a fallback buffer), seed-draco.gltf
 * (KHR_draco_mesh_compression), seed-webp.gltf (EXT_texture_webp) and
 * tests/fuzz/corpus/image/seed-lossless.webp, seed-lossy.webp. Not part of
 * the build:
 *   g++ -c tests/unit/draco_encode.cpp -o /tmp/de.o && \
 *   gcc -o /tmp/seeds tests/fuzz/make_codec_seeds.c /tmp/de.o -lmeshoptimizer -lwebp -ldraco -lstdc++ -lm && \
 *   /tmp/seeds tests/fuzz/corpus
 */
#include <meshoptimizer.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <webp/encode.h>

size_t draco_encode_mesh(const float *pos, const float *nrm, const float *uv, const uint8_t *col, size_t np,
                         const uint32_t *faces, size_t nf, int sequential, int qpos, int qother, int ids[4], uint8_t *out,
                         size_t cap);

static char *b64(const uint8_t *p, size_t n, const char *mime)
{
    static const char al[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    char *o = malloc(4 * (n / 3 + 1) + 64), *q = o;
    q += sprintf(q, "data:%s;base64,", mime);
    for (size_t i = 0; i < n; i += 3) {
        uint32_t w = (uint32_t)p[i] << 16 | (i + 1 < n ? (uint32_t)p[i + 1] << 8 : 0) | (i + 2 < n ? p[i + 2] : 0);
        *q++ = al[w >> 18 & 63];
        *q++ = al[w >> 12 & 63];
        *q++ = i + 1 < n ? al[w >> 6 & 63] : '=';
        *q++ = i + 2 < n ? al[w & 63] : '=';
    }
    *q = '\0';
    return o;
}

static void write(const char *dir, const char *name, const void *p, size_t n)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 1, n, f) != n || fclose(f)) {
        perror(path);
        exit(1);
    }
}

/* a 3 x 3 grid of two triangles a cell */
static float pos[9 * 3], uv[9 * 2], nrm[9 * 3];
static uint32_t tri[8 * 3];

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s tests/fuzz/corpus\n", argv[0]);
        return 2;
    }
    char gdir[512], idir[512];
    snprintf(gdir, sizeof gdir, "%s/gltf", argv[1]);
    snprintf(idir, sizeof idir, "%s/image", argv[1]);
    for (int i = 0; i < 9; i++) {
        pos[3 * i] = (float)(i % 3), pos[3 * i + 1] = (float)(i / 3), pos[3 * i + 2] = 0.25f * (float)(i % 2);
        uv[2 * i] = (float)(i % 3) / 2, uv[2 * i + 1] = (float)(i / 3) / 2;
        nrm[3 * i + 2] = 1;
    }
    int t = 0;
    for (int y = 0; y < 2; y++)
        for (int x = 0; x < 2; x++) {
            uint32_t a = (uint32_t)(y * 3 + x), q[6] = {a, a + 1, a + 4, a, a + 4, a + 3};
            memcpy(tri + 3 * t, q, sizeof q);
            t += 2;
        }
    char json[16384];

    /* EXT_meshopt_compression */
    uint8_t buf[4096];
    size_t n = 0, vp = 0, vu, vi, lp, lu, li;
    lp = meshopt_encodeVertexBuffer(buf, sizeof buf, pos, 9, 12);
    n = (lp + 3) & ~(size_t)3;
    vu = n;
    lu = meshopt_encodeVertexBuffer(buf + n, sizeof buf - n, uv, 9, 8);
    n = (n + lu + 3) & ~(size_t)3;
    vi = n;
    li = meshopt_encodeIndexBuffer(buf + n, sizeof buf - n, tri, 24);
    n = (n + li + 3) & ~(size_t)3;
    char *u = b64(buf, n, "application/octet-stream");
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_meshopt_compression\"],"
             "\"extensionsRequired\":[\"EXT_meshopt_compression\"],\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"},"
             "{\"byteLength\":264,\"extensions\":{\"EXT_meshopt_compression\":{\"fallback\":true}}}],\"bufferViews\":["
             "{\"buffer\":1,\"byteLength\":108,\"byteStride\":12,\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,"
             "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":12,\"count\":9,\"mode\":\"ATTRIBUTES\"}}},"
             "{\"buffer\":1,\"byteOffset\":108,\"byteLength\":72,\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,"
             "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":8,\"count\":9,\"mode\":\"ATTRIBUTES\",\"filter\":\"NONE\"}}},"
             "{\"buffer\":1,\"byteOffset\":180,\"byteLength\":96,\"extensions\":{\"EXT_meshopt_compression\":{\"buffer\":0,"
             "\"byteOffset\":%zu,\"byteLength\":%zu,\"byteStride\":4,\"count\":24,\"mode\":\"TRIANGLES\"}}}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":9,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5125,\"count\":24,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}\n",
             n, u, vp, lp, vu, lu, vi, li);
    free(u);
    write(gdir, "seed-meshopt.gltf", json, strlen(json));

    /* KHR_draco_mesh_compression */
    int ids[4];
    size_t dl = draco_encode_mesh(pos, nrm, uv, NULL, 9, tri, 8, 0, 11, 10, ids, buf, sizeof buf);
    if (!dl) return 1;
    u = b64(buf, dl, "application/octet-stream");
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"KHR_draco_mesh_compression\"],"
             "\"extensionsRequired\":[\"KHR_draco_mesh_compression\"],\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],"
             "\"bufferViews\":[{\"buffer\":0,\"byteLength\":%zu}],"
             "\"accessors\":[{\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"
             "{\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},{\"componentType\":5126,\"count\":9,\"type\":\"VEC2\"},"
             "{\"componentType\":5123,\"count\":24,\"type\":\"SCALAR\"}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3,"
             "\"extensions\":{\"KHR_draco_mesh_compression\":{\"bufferView\":0,\"attributes\":{\"POSITION\":%d,"
             "\"NORMAL\":%d,\"TEXCOORD_0\":%d}}}}]}],\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}\n",
             dl, u, dl, ids[0], ids[1], ids[2]);
    free(u);
    write(gdir, "seed-draco.gltf", json, strlen(json));

    /* WebP images, and EXT_texture_webp */
    uint8_t px[4 * 4 * 4];
    for (int i = 0; i < 64; i++) px[i] = (uint8_t)(i * 29);
    uint8_t *ll = NULL, *ly = NULL;
    size_t lln = WebPEncodeLosslessRGBA(px, 4, 4, 16, &ll), lyn = WebPEncodeRGB(px, 4, 5, 12, 50.0f, &ly);
    if (!lln || !lyn) return 1;
    write(idir, "seed-lossless.webp", ll, lln);
    write(idir, "seed-lossy.webp", ly, lyn);
    size_t vn = 0;
    memcpy(buf, pos, sizeof pos);
    memcpy(buf + 108, uv, sizeof uv);
    memcpy(buf + 180, tri, sizeof tri);
    vn = 276;
    u = b64(buf, vn, "application/octet-stream");
    char *w = b64(ll, lln, "image/webp");
    snprintf(json, sizeof json,
             "{\"asset\":{\"version\":\"2.0\"},\"extensionsUsed\":[\"EXT_texture_webp\"],"
             "\"buffers\":[{\"byteLength\":%zu,\"uri\":\"%s\"}],\"bufferViews\":[{\"buffer\":0,\"byteLength\":108},"
             "{\"buffer\":0,\"byteOffset\":108,\"byteLength\":72},{\"buffer\":0,\"byteOffset\":180,\"byteLength\":96}],"
             "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":9,\"type\":\"VEC3\"},"
             "{\"bufferView\":1,\"componentType\":5126,\"count\":9,\"type\":\"VEC2\"},"
             "{\"bufferView\":2,\"componentType\":5125,\"count\":24,\"type\":\"SCALAR\"}],"
             "\"images\":[{\"uri\":\"%s\"}],\"textures\":[{\"extensions\":{\"EXT_texture_webp\":{\"source\":0}}}],"
             "\"materials\":[{\"pbrMetallicRoughness\":{\"baseColorTexture\":{\"index\":0}}}],"
             "\"meshes\":[{\"primitives\":[{\"attributes\":{\"POSITION\":0,\"TEXCOORD_0\":1},\"indices\":2,\"material\":0}]}],"
             "\"nodes\":[{\"mesh\":0}],\"scenes\":[{\"nodes\":[0]}]}\n",
             vn, u, w);
    free(u);
    free(w);
    write(gdir, "seed-webp.gltf", json, strlen(json));
    WebPFree(ll);
    WebPFree(ly);
    return 0;
}
