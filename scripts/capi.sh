#!/usr/bin/env bash
# The C API end to end (issue 39), also run by scripts/test-all.sh:
#  1. installs what is missing (gcc-arm-none-eabi and qemu-system-arm with
#     apt-get, the thumbv7em-none-eabihf target);
#  2. tests the FFI boundary in Rust (capi/tests/ffi.rs) and checks that
#     the committed header capi/include/fvr.h is what cbindgen makes now
#     (capi/tests/header.rs);
#  3. compiles the header alone with gcc and arm-none-eabi-gcc,
#     -Wall -Wextra -Werror -std=c11 -pedantic;
#  4. `fvr prepare brainsmall --for m4f --emit c --out bs` (and the same as
#     a .fvrs file, which must hold the C array's bytes);
#  5. a host C program (capi/tests/c/host.c) on the host static library:
#     renders the view and checks the error statuses from C;
#  6. the C firmware example (firmware/c-example/) with gcc-arm-none-eabi on
#     the thumb static library and bs.c, in QEMU mps2-an386 under
#     -icount shift=0: its image must equal the host's bit for bit; prints
#     its instruction counts beside the Rust firmware's plain kb3 view.
set -euo pipefail
cd "$(dirname "$0")/.."

fail() {
    echo "capi.sh: error: $*" >&2
    exit 1
}
QEMU_TIMEOUT_S=120
TARGET=thumbv7em-none-eabihf

install() { # command package
    command -v "$1" >/dev/null && return 0
    echo "$1 is missing: installing $2 with apt-get"
    [ "$(id -u)" = 0 ] || fail "$1 is missing and this script is not root: apt-get install -y $2"
    apt-get update -qq || fail "apt-get update failed: cannot install $2"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "$2" >/dev/null || fail "apt-get install $2 failed"
    command -v "$1" >/dev/null || fail "$1 is still missing after installing $2"
}
install arm-none-eabi-gcc gcc-arm-none-eabi
install qemu-system-arm qemu-system-arm
rustup target list --installed | grep -qx "$TARGET" || rustup target add "$TARGET"

echo "== capi: the FFI boundary's tests and the header's currency"
cargo test --locked -p fvr-capi

# The host's library and fvr in the tests' profile (optimized; what
# `cargo test --workspace` in scripts/test-all.sh has built already), the
# thumb libraries in release (as scripts/firmware.sh builds the core).
echo "== capi: the static libraries (host, $TARGET, thumbv7m-none-eabi) and the fvr program"
cargo build --locked --profile test -p fvr-capi -p fvr-host
cargo build --locked --release -p fvr-capi --target "$TARGET"
rustup target list --installed | grep -qx thumbv7m-none-eabi || rustup target add thumbv7m-none-eabi
cargo build --locked --release -p fvr-capi --target thumbv7m-none-eabi
target_dir=$(cargo metadata --format-version 1 --no-deps --locked \
    | python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
host_lib="$target_dir/debug/libfvr_capi.a"
thumb_lib="$target_dir/$TARGET/release/libfvr_capi.a"
fvr="$target_dir/debug/fvr"
run="$target_dir/fvr-capi-run"
rm -rf "$run"
mkdir -p "$run"

echo "== capi: the header alone, -Wall -Wextra -Werror -std=c11 -pedantic"
CFLAGS=(-std=c11 -Wall -Wextra -Werror -pedantic)
printf '#include "fvr.h"\n' >"$run/header.c"
gcc "${CFLAGS[@]}" -Icapi/include -c "$run/header.c" -o "$run/header.o"
arm-none-eabi-gcc "${CFLAGS[@]}" -mcpu=cortex-m4 -mthumb -Icapi/include -c "$run/header.c" -o "$run/header-arm.o"

echo "== capi: fvr prepare brainsmall --for m4f --emit c --out bs"
(cd "$run" && "$fvr" prepare brainsmall --for m4f --filter kb3 --emit c --out bs)
(cd "$run" && "$fvr" prepare brainsmall --for m4f --filter kb3 --out bs.fvrs --quiet)
python3 - "$run/bs.c" "$run/bs.fvrs" <<'PY' || fail "bs.c does not hold the bytes of bs.fvrs"
import re, sys
c = open(sys.argv[1]).read().split("= {", 1)[1]
array = bytes(int(x, 16) for x in re.findall(r"0x([0-9a-f]{2})", c))
sys.exit(0 if array == open(sys.argv[2], "rb").read() else 1)
PY
# Over budget: refused with the numbers, nothing written.
if (cd "$run" && "$fvr" prepare brainsmall --for m4f --resample 128 --emit c --out big 2>big.err); then
    fail "a 128-side brainsmall was accepted for the m4f"
fi
grep -q "does not fit the m4f" "$run/big.err" || fail "no budget line: $(cat "$run/big.err")"
[ ! -e "$run/big.c" ] && [ ! -e "$run/big.h" ] || fail "a refused prepare wrote files"
cat "$run/big.err"

echo "== capi: host C program on $(basename "$host_lib")"
gcc "${CFLAGS[@]}" -O2 -Icapi/include capi/tests/c/host.c "$host_lib" -lpthread -ldl -lm -o "$run/host"
"$run/host" "$run/bs.fvrs" "$run/host.f32" 64

echo "== capi: C firmware example (arm-none-eabi-gcc, QEMU mps2-an386)"
ARM=(-mcpu=cortex-m4 -mthumb -mfpu=fpv4-sp-d16 -mfloat-abi=hard -O2 -ffreestanding -ffunction-sections -fdata-sections)
arm-none-eabi-gcc "${CFLAGS[@]}" "${ARM[@]}" -Icapi/include -I"$run" -nostdlib -nostartfiles -Wl,--no-warn-execstack \
    -T firmware/c-example/link.ld -Wl,--gc-sections \
    firmware/c-example/main.c firmware/c-example/startup.c firmware/c-example/semihost.c "$run/bs.c" \
    "$thumb_lib" -lgcc -o "$run/c-example.elf"
arm-none-eabi-size "$run/c-example.elf"
set +e
(cd "$run" && timeout --kill-after=5 "$QEMU_TIMEOUT_S" qemu-system-arm \
    -machine mps2-an386 -cpu cortex-m4 -nographic -monitor none -serial none \
    -semihosting-config enable=on,target=native -icount shift=0 \
    -kernel c-example.elf)
status=$?
set -e
[ "$status" = 0 ] || fail "the C example exited with status $status in QEMU (102: fault; 124: timeout)"
cmp "$run/host.f32" "$run/c-example.f32" || fail "the C example's image differs from the host's"
echo "c-example: its 64x64 image equals the host's bit for bit ($(wc -c <"$run/c-example.f32") bytes)"
echo "c-example: instructions (exact to +-40): $(tr '\n' ' ' <"$run/c-example.txt")"
rust_log="$target_dir/fvr-firmware-run/fvr-scene.log"
if [ -f "$rust_log" ]; then
    echo "Rust firmware, beside it: $(sed -n 's/^frame [^ ]* plain-kb3: render \([0-9]*\) instructions.*/fvr-scene plain-kb3 render \1/p' "$rust_log")"
else
    echo "Rust firmware, beside it: run bash scripts/firmware.sh for fvr-scene's plain kb3 count"
fi
