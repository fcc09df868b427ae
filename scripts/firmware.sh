#!/usr/bin/env bash
# The firmware on a Cortex-M4F under QEMU (mps2-an386), a Cortex-M3
# (mps2-an385) and a Cortex-M7 (mps2-an500), end to end:
#  1. installs what it needs when missing (thumb targets, qemu-system-arm,
#     defmt-print), and fails loudly if it cannot;
#  2. lints and builds every program in four cargo calls (the Cortex-M3
#     and M4F libraries side by side in one; the M7 programs share the
#     M4F's target and library, build.rs linking them with memory-m7.x):
#     fvr-scene (plain, depth-cued, shaded and both) and fvr-filter-bench
#     (M4F), fvr-fixed-bench (M3), fvr-prepare (M4F) and fvr-prepare-m7
#     (M7), fvr-prepare-q15 (M4F 32^3, M3 64^3) and fvr-prepare-q15-m7 (M7
#     64^3), and fvr-trig-bench (M4F, M3; the package firmware/trig);
#  3. checks that each program linked with its own part's memory layout
#     (the end of RAM, _stack_start, against memory.x, memory-m3.x or
#     memory-m7.x);
#  4. runs each in QEMU with -icount shift=0 under a timeout (a HardFault
#     would otherwise spin forever), two at a time, decodes its defmt log
#     and requires exit 0 and the SysTick calibration;
#  5. checks the QEMU outputs against the host in one cargo call: every
#     M4F image bit for bit, and the display bytes against the host image
#     (firmware/tests/qemu_agreement.rs); the M3's integer transforms and
#     whole plain kb3 view, integer and soft-float f32
#     (firmware/tests/qemu_fixed.rs); the spectra and views prepared on
#     the device, f16 (firmware/tests/qemu_prepare.rs) and Q15
#     (firmware/tests/qemu_prepare_q15.rs), bit for bit and in dB; then
#     what the transcendental functions of libm and micromath cost the
#     image (firmware/trig/tests/trig.rs);
#  6. prints the instruction counts, the flash/RAM footprint, and RAM
#     beyond the spectrum of the device preparations;
#  7. checks that a scene over the flash budget fails to build, naming the
#     excess (build.rs for the tables alone, the linker for tables + code).
# Usage: bash scripts/firmware.sh
set -euo pipefail
cd "$(dirname "$0")/.."

TARGET=thumbv7em-none-eabihf
PROGRAMS=(fvr-scene fvr-filter-bench)
M3_TARGET=thumbv7m-none-eabi
M3_PROGRAM=fvr-fixed-bench
QEMU_TIMEOUT_S=120
# QEMU runs at a time (each is one thread; -icount makes the counts exact
# whatever the load).
QEMU_JOBS=2
DEFMT_PRINT_VERSION=1.2.0

fail() {
    echo "ERROR: $*" >&2
    exit 1
}

echo "== firmware: tools"
rustup target add "$TARGET" "$M3_TARGET"
if ! command -v qemu-system-arm >/dev/null; then
    echo "qemu-system-arm is missing: installing it with apt-get"
    if [ "$(id -u)" -eq 0 ]; then
        apt-get update -qq || fail "apt-get update failed: cannot install qemu-system-arm"
        DEBIAN_FRONTEND=noninteractive apt-get install -y -qq qemu-system-arm \
            || fail "apt-get install qemu-system-arm failed"
    else
        fail "qemu-system-arm is missing and this script is not root: install it (apt-get install -y qemu-system-arm)"
    fi
fi
command -v qemu-system-arm >/dev/null || fail "qemu-system-arm is still missing after installation"
qemu-system-arm --version | head -1
if ! command -v defmt-print >/dev/null; then
    echo "defmt-print is missing: cargo install defmt-print@$DEFMT_PRINT_VERSION (about 3 minutes)"
    cargo install --locked defmt-print --version "$DEFMT_PRINT_VERSION" || fail "cargo install defmt-print failed"
fi
command -v defmt-print >/dev/null || fail "defmt-print is not on PATH after cargo install"

target_dir=$(cargo metadata --format-version 1 --no-deps --locked \
    | python3 -c 'import json, sys; print(json.load(sys.stdin)["target_directory"])')
bin_dir="$target_dir/$TARGET/release"
run_dir="$target_dir/fvr-firmware-run"

# The Cortex-M3's whole plain kb3 64x64 view (fvr-fixed-bench): integer
# (set-up, extraction, finish) against soft-float f32, from its log.
m3_view_counts() {
    local log="$run_dir/$M3_PROGRAM.log" view soft
    echo "== firmware: Cortex-M3 whole view (plain kb3 64x64, exact to +-40)"
    grep -h '^fixed phases-q15:' "$log" || fail "$M3_PROGRAM: no phase-table count"
    grep -h '^fixed view-q15:' "$log" || fail "$M3_PROGRAM: no integer view count"
    grep -h '^fixed view-f32:' "$log" || fail "$M3_PROGRAM: no soft-float view count"
    view=$(sed -n 's/^fixed view-q15: \([0-9]*\) .*/\1/p' "$log")
    soft=$(sed -n 's/^fixed view-f32: \([0-9]*\) .*/\1/p' "$log")
    echo "soft-float f32 view / integer view: $(python3 -c "print(f'{$soft / $view:.2f}')")"
}

m3_dir="$target_dir/$M3_TARGET/release"
# Programs built for both cores (the M3 builds only these); the M4F builds
# every program of fvr-firmware besides.
BOTH_CORES=(--bin fvr-fixed-bench --bin fvr-prepare-q15 --bin fvr-trig-bench)
PACKAGES=(-p fvr-firmware -p fvr-firmware-trig)

echo "== firmware: lint ($TARGET and $M3_TARGET, release)"
cargo clippy --locked "${PACKAGES[@]}" --target "$TARGET" --target "$M3_TARGET" --release \
    --lib "${BOTH_CORES[@]}" -- -D warnings
cargo clippy --locked -p fvr-firmware --target "$TARGET" --release --bins -- -D warnings
echo "== firmware: build ($TARGET and $M3_TARGET, release)"
cargo build --locked "${PACKAGES[@]}" --target "$TARGET" --target "$M3_TARGET" --release \
    "${BOTH_CORES[@]}"
cargo build --locked -p fvr-firmware --target "$TARGET" --release --bins

echo "== firmware: each program's memory layout (end of RAM = _stack_start)"
# The memory layouts: the Cortex-M4F's in the workspace root, the M3's and
# M7's in firmware/ (firmware/link_script.rs links each program with its
# part's). A program linked with another part's layout has another end of
# RAM, so this fails.
M4F_LAYOUT=memory.x
M3_LAYOUT=firmware/memory-m3.x
M7_LAYOUT=firmware/memory-m7.x
ram_end() { # layout: ORIGIN + LENGTH of its RAM region, in decimal
    python3 - "$1" <<'PY'
import re, sys
text = re.sub(r"/\*.*?\*/", "", open(sys.argv[1]).read(), flags=re.S)
m = re.search(r"^\s*RAM\s*:\s*ORIGIN\s*=\s*(\w+)\s*,\s*LENGTH\s*=\s*(\w+?)([KM]?)\s*$", text, re.M)
if not m:
    sys.exit(f"{sys.argv[1]}: no `RAM : ORIGIN = ..., LENGTH = ...` line")
unit = {"": 1, "K": 1024, "M": 1024 * 1024}[m.group(3)]
print(int(m.group(1), 0) + int(m.group(2), 0) * unit)
PY
}
m4f_ram_end=$(ram_end "$M4F_LAYOUT")
m3_ram_end=$(ram_end "$M3_LAYOUT")
m7_ram_end=$(ram_end "$M7_LAYOUT")
[ "$m4f_ram_end" != "$m3_ram_end" ] && [ "$m4f_ram_end" != "$m7_ram_end" ] && [ "$m3_ram_end" != "$m7_ram_end" ] \
    || fail "two memory layouts end their RAM at the same address: this check cannot tell them apart"
check_layout() { # elf layout ram-end
    local hex
    hex=$(readelf -sW "$1" | awk '$8 == "_stack_start" { print $2 }')
    [ -n "$hex" ] || fail "$1: no _stack_start symbol"
    [ $((16#$hex)) -eq "$3" ] \
        || fail "$(basename "$1") ($1): _stack_start is 0x$hex, but $2 ends RAM at $(printf '0x%08x' "$3"): it linked with another part's memory layout"
    printf '%-40s _stack_start 0x%s  %s\n' "${1#"$target_dir"/}" "$hex" "$2"
}
for program in fvr-scene fvr-filter-bench fvr-prepare fvr-prepare-q15 fvr-trig-bench; do
    check_layout "$bin_dir/$program" "$M4F_LAYOUT" "$m4f_ram_end"
done
for program in fvr-prepare-m7 fvr-prepare-q15-m7; do
    check_layout "$bin_dir/$program" "$M7_LAYOUT" "$m7_ram_end"
done
for program in "$M3_PROGRAM" fvr-prepare-q15 fvr-trig-bench; do
    check_layout "$m3_dir/$program" "$M3_LAYOUT" "$m3_ram_end"
done

# Every QEMU run: name (of its log and outputs), machine, cpu, elf.
QEMU_RUNS=(
    "fvr-scene mps2-an386 cortex-m4 $bin_dir/fvr-scene"
    "fvr-filter-bench mps2-an386 cortex-m4 $bin_dir/fvr-filter-bench"
    "$M3_PROGRAM mps2-an385 cortex-m3 $m3_dir/$M3_PROGRAM"
    "fvr-prepare mps2-an386 cortex-m4 $bin_dir/fvr-prepare"
    "fvr-prepare-m7 mps2-an500 cortex-m7 $bin_dir/fvr-prepare-m7"
    "fvr-prepare-q15 mps2-an386 cortex-m4 $bin_dir/fvr-prepare-q15"
    "fvr-prepare-q15-m7 mps2-an500 cortex-m7 $bin_dir/fvr-prepare-q15-m7"
    "fvr-prepare-q15-m3 mps2-an385 cortex-m3 $m3_dir/fvr-prepare-q15"
    "fvr-trig-bench-m4f mps2-an386 cortex-m4 $bin_dir/fvr-trig-bench"
    "fvr-trig-bench-m3 mps2-an385 cortex-m3 $m3_dir/fvr-trig-bench"
)
# The programs that must report an exact SysTick calibration.
CALIBRATED=(fvr-fixed-bench fvr-prepare fvr-prepare-m7 fvr-prepare-q15 fvr-prepare-q15-m7 fvr-prepare-q15-m3)

echo "== firmware: run in QEMU (-icount shift=0, timeout ${QEMU_TIMEOUT_S}s, $QEMU_JOBS at a time)"
rm -rf "$run_dir"
mkdir -p "$run_dir"
qemu_run() { # name machine cpu elf: writes name.defmt and name.status
    set +e
    (cd "$run_dir" && timeout --kill-after=5 "$QEMU_TIMEOUT_S" qemu-system-arm \
        -machine "$2" -cpu "$3" -nographic -monitor none -serial none \
        -semihosting-config enable=on,target=native -icount shift=0 \
        -kernel "$4" >"$1.defmt" 2>"$1.stderr")
    echo $? >"$run_dir/$1.status"
}
for run in "${QEMU_RUNS[@]}"; do
    while [ "$(jobs -rp | wc -l)" -ge "$QEMU_JOBS" ]; do
        wait -n || true
    done
    # shellcheck disable=SC2086 # the fields of one run
    qemu_run $run &
done
wait
for run in "${QEMU_RUNS[@]}"; do
    read -r name _ _ elf <<<"$run"
    echo "-- $name"
    defmt-print -e "$elf" <"$run_dir/$name.defmt" | tee "$run_dir/$name.log"
    cat "$run_dir/$name.stderr" >&2
    status=$(cat "$run_dir/$name.status")
    case $status in
        0) ;;
        124 | 137) fail "$name: QEMU timed out after ${QEMU_TIMEOUT_S}s (a HardFault loop or a hang)" ;;
        *) fail "$name: exited with status $status (101 panic, 102 HardFault, 1 error)" ;;
    esac
done
for program in "${CALIBRATED[@]}"; do
    grep -q '^calibration: delay loop of 2000002 instructions counted as 2000000$' "$run_dir/$program.log" \
        || fail "$program: the SysTick calibration is off"
done

echo "== firmware: QEMU outputs against the host (bit for bit, dB)"
# `--workspace`, not `-p`: the features then unify as in the workspace's
# own test build, which `scripts/test-all.sh` has just made, so these test
# binaries are reused instead of rebuilt with `fvr-host` under them.
FVR_QEMU_OUT="$run_dir" cargo test --locked --workspace \
    --test qemu_agreement --test qemu_fixed --test qemu_prepare --test qemu_prepare_q15 \
    -- --ignored --nocapture
echo "== firmware: what libm and micromath cost the image (host)"
cargo test --locked --workspace --test trig -- --nocapture

echo "== firmware: instruction counts (64x64 view, Cortex-M4F, exact to +-40)"
# Plain frames are split by a staged render; cued and shaded frames by
# timing their inverse again after render_scene (extraction is the rest),
# which relies on the inverse's cost not depending on the data: each plain
# frame's "inverse again on other data" must equal its inverse within two
# clock readings (80 instructions).
printf '%-18s %-13s %11s %11s %11s %11s\n' program frame render extraction inverse "(2D DHT)"
for program in "${PROGRAMS[@]}"; do
    sed -n 's/^frame \([^ ]*\) \([^:]*\): render \([0-9]*\) instructions = extraction \([0-9]*\) + inverse \([0-9]*\).*2D DHT alone \([0-9]*\).*/\1 \2 \3 \4 \5 \6/p' \
        "$run_dir/$program.log" \
        | while read -r p f r e i d; do printf '%-18s %-13s %11s %11s %11s %11s\n' "$p" "$f" "$r" "$e" "$i" "$d"; done
    sed -n 's/^frame [^ ]* \([^:]*\): .* inverse \([0-9]*\) (+ .*inverse again on other data \([0-9]*\);.*/\1 \2 \3/p' \
        "$run_dir/$program.log" \
        | while read -r f i again; do
            diff=$((i > again ? i - again : again - i))
            [ "$diff" -le 80 ] || fail "$program $f: the inverse took $i instructions, and $again on other data: its cost depends on the data, so the cued and shaded frames' split is wrong"
        done
done
grep -h '^f16 -> f32' "$run_dir/fvr-filter-bench.log" || fail "no f16 conversion report"
grep -h '^frame' "$run_dir/fvr-scene.log" "$run_dir/fvr-filter-bench.log" >/dev/null \
    || fail "no instruction counts in the firmware logs"
grep -q 'inverse again on other data' "$run_dir/fvr-scene.log" || fail "fvr-scene: no re-timed inverse of its plain frame"

# .text .rodata .data .bss .vector_table of an elf.
sections() {
    size -A "$1" | awk '
        $1==".text"{t=$2} $1==".rodata"{r=$2} $1==".data"{d=$2} $1==".bss"{b=$2} $1==".vector_table"{v=$2}
        END{print t+0, r+0, d+0, b+0, v+0}'
}
# The peak stack a program's log reports.
stack_of() {
    local stack
    stack=$(sed -n 's/^stack: peak \([0-9]*\) bytes.*/\1/p' "$run_dir/$1.log")
    [ -n "$stack" ] || fail "$1: no stack measurement in its log"
    echo "$stack"
}

echo "== firmware: footprint (bytes)"
footprint_header() {
    printf '%-18s %8s %8s %8s %8s %8s %10s %10s\n' program .text .rodata .data .bss stack flash RAM
}
footprint() { # elf program
    local text rodata data bss vt stack
    read -r text rodata data bss vt < <(sections "$1")
    stack=$(stack_of "$2")
    printf '%-18s %8s %8s %8s %8s %8s %10s %10s\n' "$2" "$text" "$rodata" "$data" "$bss" "$stack" \
        $((vt + text + rodata + data)) $((data + bss + stack))
}
footprint_header
for program in "${PROGRAMS[@]}"; do
    footprint "$bin_dir/$program" "$program"
done

echo "== firmware: instruction counts (64x64 block, Cortex-M3, exact to +-40)"
printf '%-20s %11s\n' item instructions
sed -n 's/^fixed \([^:]*\): \([0-9]*\) instructions.*/\1 \2/p; s/^fixed \(twiddles-q15\): build \([0-9]*\) instructions.*, flash \([0-9]*\) .*/\1-build \2\n\1-flash \3/p' \
    "$run_dir/$M3_PROGRAM.log" | while read -r item n; do printf '%-20s %11s\n' "$item" "$n"; done
q15=$(sed -n 's/^fixed idht-2d-q15: \([0-9]*\) .*/\1/p' "$run_dir/$M3_PROGRAM.log")
soft=$(sed -n 's/^fixed idht-2d-f32: \([0-9]*\) .*/\1/p' "$run_dir/$M3_PROGRAM.log")
[ -n "$q15" ] && [ -n "$soft" ] || fail "$M3_PROGRAM: no transform counts in its log"
echo "soft-float f32 / Q15: $(python3 -c "print(f'{$soft / $q15:.2f}')")"
m3_view_counts
echo "== firmware: Cortex-M3 footprint (bytes)"
footprint_header
footprint "$m3_dir/$M3_PROGRAM" "$M3_PROGRAM"

# ---- The transform on the device: fvr-prepare (Cortex-M4F, 32^3) and
# fvr-prepare-m7 (Cortex-M7 with 1 MiB of RAM, 64^3) prepare a spectrum in
# place in RAM from a u8 volume in flash and render the kb3 view from it.
echo "== firmware: device preparation, instruction counts (exact to +-40) and RAM (bytes)"
printf '%-16s %5s %12s %12s %10s %10s %10s %8s %10s\n' \
    program side preparation "(3D DHT)" render spectrum "RAM beyond" stack flash
for program in fvr-prepare fvr-prepare-m7; do
    read -r side prep dht render < <(sed -n \
        's/^prepare [^:]*: side \([0-9]*\), .*; preparation \([0-9]*\) instructions (3D DHT alone on a test signal \([0-9]*\)); render [0-9x]* view \([0-9]*\)$/\1 \2 \3 \4/p' \
        "$run_dir/$program.log")
    [ -n "${render:-}" ] || fail "$program: no preparation counts in its log"
    read -r text rodata data bss vt < <(sections "$bin_dir/$program")
    stack=$(stack_of "$program")
    spectrum=$((2 * side * side * side))
    printf '%-16s %5s %12s %12s %10s %10s %10s %8s %10s\n' "$program" "$side" "$prep" "$dht" "$render" \
        "$spectrum" $((data + bss + stack - spectrum)) "$stack" $((vt + text + rodata + data))
done

# ---- The Q15 transform on the device: fvr-prepare-q15 (Cortex-M4F, 32^3;
# Cortex-M3, 64^3) and fvr-prepare-q15-m7 (Cortex-M7, 64^3) prepare the Q15
# spectrum in integers in RAM from the u8 volume in flash and render the
# integer kb3 view from it.
echo "== firmware: Q15 device preparation, instruction counts (exact to +-40) and RAM (bytes)"
printf '%-20s %5s %12s %12s %10s %10s %10s %10s %8s %10s\n' \
    program side preparation "(3D DHT)" render "phases" spectrum "RAM beyond" stack flash
for program in fvr-prepare-q15 fvr-prepare-q15-m7 fvr-prepare-q15-m3; do
    case $program in
        fvr-prepare-q15-m3) elf="$m3_dir/fvr-prepare-q15" ;;
        *) elf="$bin_dir/$program" ;;
    esac
    read -r side prep dht render phases < <(sed -n \
        's/^prepare-q15 [^:]*: side \([0-9]*\), .*; preparation \([0-9]*\) instructions (3D DHT alone on a test signal \([0-9]*\)); render [0-9x]* view \([0-9]*\); phase table \([0-9]*\)$/\1 \2 \3 \4 \5/p' \
        "$run_dir/$program.log")
    [ -n "${phases:-}" ] || fail "$program: no preparation counts in its log"
    read -r text rodata data bss vt < <(sections "$elf")
    stack=$(stack_of "$program")
    # The spectrum: n^3 Q15 mantissas and n^2 exponents.
    spectrum=$((2 * side * side * side + side * side))
    printf '%-20s %5s %12s %12s %10s %10s %10s %10s %8s %10s\n' "$program" "$side" "$prep" "$dht" "$render" \
        "$phases" "$spectrum" $((data + bss + stack - spectrum)) "$stack" $((vt + text + rodata + data))
done

echo "== firmware: per-view transcendental functions, libm against micromath (M4F, M3)"
grep -h '^trig ' "$run_dir/fvr-trig-bench-m4f.log" "$run_dir/fvr-trig-bench-m3.log" \
    || fail "fvr-trig-bench: no counts in its logs"

echo "== firmware: a scene over the flash budget fails to build, naming the excess"
# In a copy of the workspace whose memory.x is smaller, building
# the program whose tables are largest (fvr-filter-bench) in the same
# target directory: the registry crates are reused. Cargo names a
# workspace crate's build by its path within the workspace, so the copy's
# crates get another version (and their own lock entries) to build apart
# from the workspace's, which stay untouched.
budget_ws="$target_dir/fvr-firmware-budget-ws"
rm -rf "$budget_ws"
mkdir -p "$budget_ws"
trap 'rm -rf "$budget_ws"' EXIT
git ls-files -z --cached --others --exclude-standard | xargs -0 cp --parents -t "$budget_ws"
sed -i 's/^version = "\([0-9.]*\)"$/version = "\1-budget"/' "$budget_ws/Cargo.toml"
grep -q '^version = "[0-9.]*-budget"$' "$budget_ws/Cargo.toml" || fail "could not set the copy's workspace version"
# Resolving the copy's lock offline needs every locked crate in the local
# registry, other platforms' too (cargo metadata reads them all), which a
# fresh machine's builds never download.
cargo fetch --locked --quiet || fail "cargo fetch failed: the copy's lock cannot be resolved offline"
(cd "$budget_ws" && cargo metadata --offline --format-version 1 >/dev/null) \
    || fail "could not update the copy's Cargo.lock offline"
expect_build_failure() { # flash-length pattern what
    sed -i "s/^\( *FLASH *: *ORIGIN = 0x00000000, LENGTH = \).*/\1$1/" "$budget_ws/memory.x"
    grep -q "LENGTH = $1\$" "$budget_ws/memory.x" || fail "could not set FLASH to $1 in the copy of memory.x"
    set +e
    (cd "$budget_ws" && CARGO_TARGET_DIR="$target_dir" \
        cargo build --locked -p fvr-firmware --target "$TARGET" --release --bin fvr-filter-bench) \
        >"$budget_ws/build.log" 2>&1
    local status=$?
    set -e
    [ $status -ne 0 ] || fail "$3: the build succeeded with FLASH = $1"
    grep -Eo "$2" "$budget_ws/build.log" | head -1 | sed "s/^/$3: /" | grep . \
        || { cat "$budget_ws/build.log" >&2; fail "$3: the build failed without saying by how much"; }
}
expect_build_failure 1M 'does not fit: .* over by [0-9]+ bytes' "FLASH 1 MiB, tables alone too big (build.rs)"
expect_build_failure 1600K "section '[^']+' will not fit in region 'FLASH': overflowed by [0-9]+ bytes" "FLASH 1600 KiB, tables + code too big (linker)"
echo "firmware: all checks passed"
