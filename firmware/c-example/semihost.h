/* Arm semihosting (QEMU -semihosting-config enable=on): files on the host
 * and the exit status. */
#ifndef SEMIHOST_H
#define SEMIHOST_H

#include <stddef.h>
#include <stdint.h>

/* Open `name` for writing in binary ("wb"); a handle, or -1. */
int32_t sh_open_write(const char *name);
/* Write `len` bytes; 0 on success. */
int32_t sh_write(int32_t handle, const void *data, size_t len);
/* Close a handle; 0 on success. */
int32_t sh_close(int32_t handle);
/* Write a NUL-terminated string to the host's stderr. */
void sh_puts(const char *text);
/* End the program with `status` (QEMU exits with it). */
_Noreturn void sh_exit(int32_t status);

#endif
