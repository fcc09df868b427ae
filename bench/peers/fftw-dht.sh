#!/usr/bin/env bash
# Peer benchmark (manual, not part of scripts/test-all.sh): FFTW 3's 2D
# FFTW_DHT (r2r) and r2c in f32 at 256² and 512², against fvr's true 2D DHT
# in f32 at the same sizes (criterion, `--bench dht`), so the ratio can be
# stated from one session on one machine.
#  1. installs libfftw3-dev with apt-get when fftw3.h is missing (as root);
#  2. compiles bench/peers/fftw-dht.c (ours; no FFTW code is vendored) with
#     gcc -O3 -march=native against libfftw3f;
#  3. prints FFTW's medians, then runs the fvr bench.
# Usage: bash bench/peers/fftw-dht.sh [sizes...]   (default: 256 512)
set -euo pipefail
cd "$(dirname "$0")/../.."

fail() {
    echo "ERROR: $*" >&2
    exit 1
}

if [ ! -f /usr/include/fftw3.h ]; then
    echo "libfftw3-dev is missing: installing it with apt-get"
    [ "$(id -u)" -eq 0 ] || fail "not root: install libfftw3-dev yourself (apt-get install -y libfftw3-dev)"
    apt-get update -qq || fail "apt-get update failed"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq libfftw3-dev || fail "apt-get install libfftw3-dev failed"
fi
command -v gcc >/dev/null || fail "gcc is missing (apt-get install -y gcc)"

out_dir="${CARGO_TARGET_DIR:-target}/peers"
mkdir -p "$out_dir"
gcc -O3 -march=native -o "$out_dir/fftw-dht" bench/peers/fftw-dht.c -lfftw3f -lm \
    || fail "could not compile bench/peers/fftw-dht.c against libfftw3f"

echo "== machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
echo "== FFTW $(dpkg-query -W -f='${Version}' libfftw3-dev 2>/dev/null || echo '?'): f32, FFTW_MEASURE, one thread, median of 101 batches"
"$out_dir/fftw-dht" "$@"
echo "== fvr: true 2D DHT in f32 (batched radix-2 + Hao-Bracewell), one thread"
cargo bench --locked -p fvr-host --bench dht
