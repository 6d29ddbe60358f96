/* The C ABI round trip: open a file given on the command line, sample it at times given on the
 * command line, print every value (the Rust test compares them with the Rust sampler's), check
 * the error paths, close. */
#include <stdio.h>
#include <stdlib.h>
#include "inbetween_ibk.h"

int main(int argc, char **argv) {
    if (argc < 2) return 2;
    FILE *f = fopen(argv[1], "rb");
    if (!f) return 3;
    fseek(f, 0, SEEK_END);
    long len = ftell(f);
    fseek(f, 0, SEEK_SET);
    uint8_t *bytes = malloc((size_t)len);
    if (fread(bytes, 1, (size_t)len, f) != (size_t)len) return 4;
    fclose(f);

    char err[256];
    /* A damaged copy is refused with a message, not a crash. */
    uint8_t *bad = malloc((size_t)len);
    for (long i = 0; i < len; i++) bad[i] = bytes[i];
    bad[len / 2] ^= 0x10;
    if (inbetween_ibk_open(bad, (size_t)len, err, sizeof err) != NULL) return 5;
    printf("damaged: %s\n", err);
    free(bad);

    InbetweenIbk *clip = inbetween_ibk_open(bytes, (size_t)len, err, sizeof err);
    if (!clip) {
        printf("open failed: %s\n", err);
        return 6;
    }
    uint32_t n = inbetween_ibk_num_joints(clip);
    printf("joints %u frames %u duration %.6f parent1 %d\n", n, inbetween_ibk_num_frames(clip),
           inbetween_ibk_duration(clip), inbetween_ibk_parent(clip, 1));
    float *rot = malloc(sizeof(float) * 4 * n), *tr = malloc(sizeof(float) * 3 * n);
    if (inbetween_ibk_sample(clip, 0.0, rot, tr, n + 1) != INBETWEEN_IBK_BUFFER) return 7;
    if (inbetween_ibk_sample(NULL, 0.0, rot, tr, n) != INBETWEEN_IBK_NULL) return 8;
    for (int a = 2; a < argc; a++) {
        double t = atof(argv[a]);
        if (inbetween_ibk_sample(clip, t, rot, tr, n) != INBETWEEN_IBK_OK) return 9;
        printf("t %s", argv[a]);
        for (uint32_t j = 0; j < 4 * n; j++) printf(" %.9g", rot[j]);
        for (uint32_t j = 0; j < 3 * n; j++) printf(" %.9g", tr[j]);
        printf("\n");
    }
    inbetween_ibk_close(clip);
    inbetween_ibk_close(NULL);
    free(rot);
    free(tr);
    free(bytes);
    return 0;
}
