/* Writes an image the way most C++ course frameworks do: with
 * stb_image_write (Debian's libstb-dev). formats.py compiles and calls it.
 *
 *   stb_write png|bmp|tga|jpg IN.ppm OUT [QUALITY]   (IN: binary P6, maxval 255)
 *   stb_write hdr IN.pfm OUT                         (IN: RGB PFM, little-endian)
 */
#define STB_IMAGE_WRITE_IMPLEMENTATION
#include <stb/stb_image_write.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static unsigned char *read_ppm(const char *path, int *w, int *h) {
    FILE *f = fopen(path, "rb");
    int maxval;
    if (!f || fscanf(f, "P6 %d %d %d", w, h, &maxval) != 3 || maxval != 255 || fgetc(f) == EOF) {
        fprintf(stderr, "%s: expected a binary PPM of maxval 255\n", path);
        exit(2);
    }
    size_t n = (size_t)*w * *h * 3;
    unsigned char *data = malloc(n);
    if (fread(data, 1, n, f) != n) {
        fprintf(stderr, "%s: truncated\n", path);
        exit(2);
    }
    fclose(f);
    return data;
}

static float *read_pfm(const char *path, int *w, int *h) {
    FILE *f = fopen(path, "rb");
    float scale;
    if (!f || fscanf(f, "PF %d %d %f", w, h, &scale) != 3 || scale >= 0 || fgetc(f) == EOF) {
        fprintf(stderr, "%s: expected a little-endian RGB PFM\n", path);
        exit(2);
    }
    size_t row = (size_t)*w * 3;
    float *data = malloc(row * *h * sizeof(float));
    /* PFM stores the bottom row first; stb writes the top row first. */
    for (int y = *h - 1; y >= 0; y--) {
        if (fread(data + row * y, sizeof(float), row, f) != row) {
            fprintf(stderr, "%s: truncated\n", path);
            exit(2);
        }
    }
    fclose(f);
    return data;
}

int main(int argc, char **argv) {
    if (argc < 4) {
        fprintf(stderr, "usage: stb_write png|bmp|tga|jpg|hdr IN OUT [QUALITY]\n");
        return 2;
    }
    const char *kind = argv[1], *in = argv[2], *out = argv[3];
    int w, h, ok;
    if (strcmp(kind, "hdr") == 0) {
        float *data = read_pfm(in, &w, &h);
        ok = stbi_write_hdr(out, w, h, 3, data);
    } else {
        unsigned char *data = read_ppm(in, &w, &h);
        if (strcmp(kind, "png") == 0) ok = stbi_write_png(out, w, h, 3, data, w * 3);
        else if (strcmp(kind, "bmp") == 0) ok = stbi_write_bmp(out, w, h, 3, data);
        else if (strcmp(kind, "tga") == 0) ok = stbi_write_tga(out, w, h, 3, data);
        else if (strcmp(kind, "jpg") == 0) ok = stbi_write_jpg(out, w, h, 3, data, argc > 4 ? atoi(argv[4]) : 90);
        else {
            fprintf(stderr, "unknown format %s\n", kind);
            return 2;
        }
    }
    if (!ok) {
        fprintf(stderr, "%s: stb_image_write failed\n", out);
        return 1;
    }
    return 0;
}
