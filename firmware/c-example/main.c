/* fvr from C on a Cortex-M4F: the view (1, 0.3, 0.2) of a spectrum linked
 * into flash (`fvr prepare brainsmall --for m4f --emit c --out bs`),
 * rendered through the C API (capi/include/fvr.h), written to
 * c-example.f32 over semihosting, with SysTick instruction counts in
 * c-example.txt (under QEMU -icount shift=0 one tick is 40 instructions,
 * as in firmware/src/device.rs). */
#include <stdint.h>

#include "bs.h"
#include "fvr.h"
#include "semihost.h"

#define SIDE 64

static float grid[SIDE * SIDE];
static float aux[4 * SIDE];
static float out[SIDE * SIDE];

/* SysTick (ARMv7-M B3.3), free-running from its reload on the core clock. */
#define SYST_CSR (*(volatile uint32_t *)0xE000E010)
#define SYST_RVR (*(volatile uint32_t *)0xE000E014)
#define SYST_CVR (*(volatile uint32_t *)0xE000E018)
#define RELOAD 0x00FFFFFFu
#define INSTRUCTIONS_PER_TICK 40u

static uint32_t ticks_since(uint32_t start) { return (start - SYST_CVR) & RELOAD; }

static int write_file(const char *name, const void *data, size_t len) {
    int32_t h = sh_open_write(name);
    if (h < 0) return 1;
    int failed = sh_write(h, data, len) != 0;
    return sh_close(h) != 0 || failed;
}

static char *decimal(char *p, uint32_t v) {
    char tmp[10];
    int n = 0;
    do {
        tmp[n++] = (char)('0' + v % 10);
        v /= 10;
    } while (v);
    while (n) *p++ = tmp[--n];
    return p;
}

static char *text(char *p, const char *s) {
    while (*s) *p++ = *s++;
    return p;
}

/* Say which call failed and with what status; the program's exit status. */
static int failed(const char *call, fvr_status s) {
    sh_puts("c-example: ");
    sh_puts(call);
    sh_puts(": ");
    sh_puts(fvr_status_str((int32_t)s));
    sh_puts("\n");
    return 1;
}

int main(void) {
    SYST_RVR = RELOAD;
    SYST_CVR = 0;
    SYST_CSR = 5; /* enable, processor clock, no interrupt */
    while (SYST_CVR == 0) {
    }

    fvr_source src;
    uint32_t t0 = SYST_CVR;
    fvr_status s = fvr_source_open(&src, bs, BS_LEN);
    uint32_t open_ticks = ticks_since(t0);
    if (s != FVR_OK) return failed("fvr_source_open", s);
    fvr_request req = {{1.0, 0.3, 0.2}, {0.0, 0.0, 1.0}, SIDE, SIDE, 0};
    fvr_lens lens;
    s = fvr_buffer_lens(&src, &req, &lens);
    if (s != FVR_OK || lens.grid > SIDE * SIDE || lens.aux > 4 * SIDE || lens.out > SIDE * SIDE) {
        sh_puts("c-example: the spectrum is not 64^3 or the buffers are too small\n");
        return 1;
    }
    fvr_buffers buf = {grid, lens.grid, aux, lens.aux, out, lens.out};
    t0 = SYST_CVR;
    s = fvr_render(&src, &req, &buf);
    uint32_t render_ticks = ticks_since(t0);
    if (s != FVR_OK) return failed("fvr_render", s);
    if (SYST_CSR & (1u << 16)) {
        sh_puts("c-example: SysTick wrapped; counts unusable\n");
        return 1;
    }
    char counts[96];
    char *p = text(counts, "open ");
    p = decimal(p, open_ticks * INSTRUCTIONS_PER_TICK);
    p = text(p, "\nrender ");
    p = decimal(p, render_ticks * INSTRUCTIONS_PER_TICK);
    p = text(p, "\n");
    if (write_file("c-example.f32", out, sizeof out) ||
        write_file("c-example.txt", counts, (size_t)(p - counts))) {
        sh_puts("c-example: cannot write over semihosting\n");
        return 1;
    }
    return 0;
}
