/* The C API from C on the host (scripts/capi.sh): renders a view of a
 * .fvrs file and writes the image as raw little-endian f32, and checks
 * that the error cases come back as status codes.
 *
 *   host IMAGE.fvrs OUT.f32 [SIDE]
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "fvr.h"

static int fail(const char *what, fvr_status s) {
    fprintf(stderr, "host: %s: %s (%d)\n", what, fvr_status_str((int32_t)s), (int)s);
    return 1;
}

#define EXPECT(call, want)                                                   \
    do {                                                                     \
        fvr_status got_ = (call);                                            \
        if (got_ != (want)) {                                                \
            fprintf(stderr, "host: %s gave %d (%s), expected %s\n", #call,   \
                    (int)got_, fvr_status_str((int32_t)got_), #want);        \
            return 1;                                                        \
        }                                                                    \
    } while (0)

int main(int argc, char **argv) {
    if (argc < 3) {
        fprintf(stderr, "usage: host IMAGE.fvrs OUT.f32 [SIDE]\n");
        return 2;
    }
    FILE *f = fopen(argv[1], "rb");
    if (!f) {
        perror(argv[1]);
        return 1;
    }
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    size_t cap = ((size_t)len + 63) / 64 * 64 + 64;
    uint8_t *image = aligned_alloc(64, cap);
    if (!image || fread(image, 1, (size_t)len, f) != (size_t)len) {
        fprintf(stderr, "host: cannot read %s\n", argv[1]);
        return 1;
    }
    fclose(f);

    fvr_source src;
    fvr_status s = fvr_source_open(&src, image, (size_t)len);
    if (s != FVR_OK) return fail("fvr_source_open", s);
    fvr_info info;
    EXPECT(fvr_source_info(&src, &info), FVR_OK);
    uint32_t side = argc > 3 ? (uint32_t)atoi(argv[3]) : info.n;
    fvr_request req = {{1.0, 0.3, 0.2}, {0.0, 0.0, 1.0}, side, side, 0};
    fvr_lens lens;
    EXPECT(fvr_buffer_lens(&src, &req, &lens), FVR_OK);
    float *grid = malloc(lens.grid * sizeof(float));
    float *aux = malloc(lens.aux * sizeof(float));
    float *out = malloc(lens.out * sizeof(float));
    if (!grid || !aux || !out) return 1;
    fvr_buffers buf = {grid, lens.grid, aux, lens.aux, out, lens.out};
    s = fvr_render(&src, &req, &buf);
    if (s != FVR_OK) return fail("fvr_render", s);
    FILE *o = fopen(argv[2], "wb");
    if (!o || fwrite(out, sizeof(float), lens.out, o) != lens.out || fclose(o) != 0) {
        perror(argv[2]);
        return 1;
    }

    /* The error cases, from C. */
    EXPECT(fvr_render(NULL, &req, &buf), FVR_ERR_NULL);
    EXPECT(fvr_render(&src, NULL, &buf), FVR_ERR_NULL);
    fvr_buffers shortb = buf;
    shortb.out_len -= 1;
    EXPECT(fvr_render(&src, &req, &shortb), FVR_ERR_BUFFER_TOO_SMALL);
    fvr_buffers mis = buf;
    mis.grid = (float *)(void *)((char *)grid + 2);
    EXPECT(fvr_render(&src, &req, &mis), FVR_ERR_MISALIGNED);
    fvr_buffers overlap = buf;
    overlap.aux = grid;
    EXPECT(fvr_render(&src, &req, &overlap), FVR_ERR_OVERLAP);
    fvr_request bad = req;
    bad.dir[0] = bad.dir[1] = bad.dir[2] = 0.0;
    EXPECT(fvr_render(&src, &bad, &buf), FVR_ERR_VIEW);
    bad = req;
    bad.width = info.n + 1;
    EXPECT(fvr_render(&src, &bad, &buf), FVR_ERR_SIZE);
    /* A flipped spectrum byte: the open refuses it and leaves the handle closed. */
    image[200] ^= 0x40;
    fvr_source corrupt;
    EXPECT(fvr_source_open(&corrupt, image, (size_t)len), FVR_ERR_CHECKSUM);
    EXPECT(fvr_render(&corrupt, &req, &buf), FVR_ERR_NOT_OPEN);
    image[200] ^= 0x40;
    EXPECT(fvr_source_open(&corrupt, image + 1, (size_t)len - 1), FVR_ERR_MISALIGNED);
    EXPECT(fvr_source_open(&corrupt, image, (size_t)len - 1), FVR_ERR_LENGTH);
    if (strcmp(fvr_status_str(FVR_ERR_CHECKSUM), "checksum mismatch: the .fvrs image is corrupt") != 0 ||
        strncmp(fvr_status_str(999), "unknown", 7) != 0) {
        fprintf(stderr, "host: fvr_status_str texts\n");
        return 1;
    }
    printf("host: %ux%u view of n=%u rendered; 11 error cases returned their status\n", side, side,
           info.n);
    free(grid);
    free(aux);
    free(out);
    free(image);
    return 0;
}
