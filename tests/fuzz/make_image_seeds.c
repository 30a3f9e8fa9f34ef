/*
 * make_image_seeds.c - writes the JPEG seeds of the image fuzzer (baseline,
 * progressive, greyscale) into tests/fuzz/corpus/image. The PNG, PFM and
 * HDR seeds come from tests/data/make_textures.py, the OpenEXR one from
 * `paprsek render -o seed.exr --width 4 --height 3`. Not part of the build:
 *   cc -o /tmp/seeds tests/fuzz/make_image_seeds.c -ljpeg && /tmp/seeds tests/fuzz/corpus/image
 */
#include <stdio.h>
#include <stdlib.h>
#include <jpeglib.h>

static void write_jpeg(const char *dir, const char *name, int w, int h, int nc, int progressive)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f) {
        perror(path);
        exit(1);
    }
    struct jpeg_compress_struct c;
    struct jpeg_error_mgr err;
    c.err = jpeg_std_error(&err);
    jpeg_create_compress(&c);
    jpeg_stdio_dest(&c, f);
    c.image_width = (JDIMENSION)w;
    c.image_height = (JDIMENSION)h;
    c.input_components = nc;
    c.in_color_space = nc == 1 ? JCS_GRAYSCALE : JCS_RGB;
    jpeg_set_defaults(&c);
    jpeg_set_quality(&c, 50, TRUE);
    if (progressive) jpeg_simple_progression(&c);
    jpeg_start_compress(&c, TRUE);
    unsigned char row[64 * 3];
    while (c.next_scanline < c.image_height) {
        for (int x = 0; x < w * nc; x++) row[x] = (unsigned char)((x * 37 + (int)c.next_scanline * 11) & 255);
        JSAMPROW r = row;
        jpeg_write_scanlines(&c, &r, 1);
    }
    jpeg_finish_compress(&c);
    jpeg_destroy_compress(&c);
    fclose(f);
}

int main(int argc, char **argv)
{
    const char *dir = argc > 1 ? argv[1] : ".";
    write_jpeg(dir, "seed_baseline.jpg", 9, 7, 3, 0);
    write_jpeg(dir, "seed_progressive.jpg", 17, 5, 3, 1);
    write_jpeg(dir, "seed_grey.jpg", 8, 8, 1, 0);
    return 0;
}
