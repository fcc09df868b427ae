/*
 * Times FFTW 3's 2D real transforms in single precision, the peer of
 * fvr's f32 2D DHT (`cargo bench -p fvr-host --bench dht`):
 *   - r2r FFTW_DHT in both dimensions (FFTW's is the *separable* cas·cas
 *     transform; fvr's true 2D DHT adds the Hao–Bracewell pass on top);
 *   - r2c (the real-input FFT, FFTW's fastest real 2D transform).
 * Plans use FFTW_MEASURE, in place for r2r, out of place for r2c. Each
 * figure is the median of 101 timed batches; a batch repeats the transform
 * enough times to last about 2 ms. Usage: fftw-dht [sizes...] (default 256 512).
 */
#include <fftw3.h>
#include <stdio.h>
#include <stdlib.h>
#include <time.h>

#define BATCHES 101

static double now_s(void) {
    struct timespec t;
    clock_gettime(CLOCK_MONOTONIC, &t);
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}

static int compare(const void *a, const void *b) {
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* Median seconds per execution of `plan`. */
static double median_time(fftwf_plan plan) {
    double times[BATCHES];
    int reps = 1;
    for (;;) { /* calibrate the batch to about 2 ms */
        double t0 = now_s();
        for (int r = 0; r < reps; r++) fftwf_execute(plan);
        if (now_s() - t0 > 2e-3 || reps > (1 << 20)) break;
        reps *= 2;
    }
    for (int b = 0; b < BATCHES; b++) {
        double t0 = now_s();
        for (int r = 0; r < reps; r++) fftwf_execute(plan);
        times[b] = (now_s() - t0) / reps;
    }
    qsort(times, BATCHES, sizeof times[0], compare);
    return times[BATCHES / 2];
}

int main(int argc, char **argv) {
    int default_sizes[] = {256, 512};
    int count = argc > 1 ? argc - 1 : 2;
    printf("%-6s %14s %14s\n", "n", "r2r_DHT_us", "r2c_us");
    for (int i = 0; i < count; i++) {
        int n = argc > 1 ? atoi(argv[i + 1]) : default_sizes[i];
        if (n <= 0) {
            fprintf(stderr, "bad size %s\n", argv[i + 1]);
            return 1;
        }
        size_t len = (size_t)n * (size_t)n;
        float *data = fftwf_alloc_real(len);
        float *input = fftwf_alloc_real(len);
        fftwf_complex *spectrum = fftwf_alloc_complex((size_t)n * (size_t)(n / 2 + 1));
        fftwf_plan dht = fftwf_plan_r2r_2d(n, n, data, data, FFTW_DHT, FFTW_DHT, FFTW_MEASURE);
        fftwf_plan r2c = fftwf_plan_dft_r2c_2d(n, n, input, spectrum, FFTW_MEASURE);
        /* Planning with FFTW_MEASURE overwrites the arrays: fill them after. */
        unsigned state = 12345u;
        for (size_t k = 0; k < len; k++) {
            state = state * 1664525u + 1013904223u;
            data[k] = input[k] = (float)(state >> 8) / 16777216.0f - 0.5f;
        }
        double t_dht = median_time(dht);
        double t_r2c = median_time(r2c);
        printf("%-6d %14.1f %14.1f\n", n, 1e6 * t_dht, 1e6 * t_r2c);
        fftwf_destroy_plan(dht);
        fftwf_destroy_plan(r2c);
        fftwf_free(data);
        fftwf_free(input);
        fftwf_free(spectrum);
    }
    return 0;
}
