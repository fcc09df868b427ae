/* Arm semihosting calls: `bkpt 0xab` with the operation in r0 and a
 * pointer to its arguments in r1 (ARM IHI 0071). */
#include "semihost.h"

enum {
    SYS_OPEN = 0x01,
    SYS_CLOSE = 0x02,
    SYS_WRITE0 = 0x04,
    SYS_WRITE = 0x05,
    SYS_EXIT_EXTENDED = 0x20,
    ADP_STOPPED_APPLICATION_EXIT = 0x20026,
    MODE_WB = 5,
};

static int32_t call(int32_t op, const void *arg) {
    register int32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

static size_t length(const char *s) {
    size_t n = 0;
    while (s[n]) n++;
    return n;
}

int32_t sh_open_write(const char *name) {
    uint32_t args[3] = {(uint32_t)name, MODE_WB, (uint32_t)length(name)};
    return call(SYS_OPEN, args);
}

int32_t sh_write(int32_t handle, const void *data, size_t len) {
    uint32_t args[3] = {(uint32_t)handle, (uint32_t)data, (uint32_t)len};
    return call(SYS_WRITE, args);
}

int32_t sh_close(int32_t handle) {
    uint32_t args[1] = {(uint32_t)handle};
    return call(SYS_CLOSE, args);
}

void sh_puts(const char *text) { call(SYS_WRITE0, text); }

_Noreturn void sh_exit(int32_t status) {
    uint32_t args[2] = {ADP_STOPPED_APPLICATION_EXIT, (uint32_t)status};
    call(SYS_EXIT_EXTENDED, args);
    for (;;) {
    }
}
