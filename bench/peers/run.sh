#!/usr/bin/env bash
# Peers side by side in one run: fvr's frequency-domain view (turntable, all
# cores), RTK's Joseph forward projector (pip itk-rtk, all cores) and
# scipy.fft.rfftn (f32, all cores) on the same Gaussian-mixture volume, with
# each image's SNR against the closed-form line integrals
# (bench/peers/peers.py says how).
#
# Installs itk-rtk, numpy and scipy from PyPI into a venv under the Cargo
# target directory, builds fvr in release, then prints the table and writes
# it to docs/performance/peers.md.
#
# Usage: bash bench/peers/run.sh [--sizes 128,256] [--filters kb3,kb4,kb6]
#                                [--precision f16] [--views 7]
#        bash bench/peers/run.sh --heads [--views 7]
# --heads runs bench/peers/heads.py instead: RTK against fvr at its default
# and at 2x padding on the CT head (scripts/fetch-ct-head.sh) and, when
# FVR_MRI_HEAD is set, the MRI head (scripts/fetch-mri-head.sh); it writes
# docs/performance/heads.md.
# --finufft runs bench/peers/finufft_peer.py instead: FINUFFT type 2 (pip
# finufft) as a slice extractor against fvr --accuracy 50/60/80 on a tilted
# orbit, each with its dB against the closed-form line integrals; it writes
# docs/performance/finufft.md. Its own options: [--sizes 128,256]
# [--accuracies 50,60,80] [--eps 1e-2,...,1e-9] [--upsampfacs 2.0,1.25]
# [--upsampfacs-large 1.25] [--frames 21] [--repeats 2] [--fvr-repeats 3]
# [--fftw estimate|measure] [--out FILE].
# PEERS_OUT_DIR (default docs/performance) is where the Markdown goes
# (scripts/docs-figures.sh writes it elsewhere, then compares or copies).
# This is a manual benchmark: it is not part of scripts/test-all.sh. Run it
# on an idle machine; the ratios come from one run, the absolute times drift.
set -euo pipefail
cd "$(dirname "$0")/../.."

TARGET="${CARGO_TARGET_DIR:-target}"
VENV="$TARGET/peers/venv"
if [ ! -x "$VENV/bin/python" ]; then
    python3 -m venv "$VENV"
fi
if ! "$VENV/bin/python" -c "import itk, scipy; from itk import RTK" 2>/dev/null; then
    "$VENV/bin/pip" install --quiet itk-rtk numpy scipy
fi
case " $* " in
    *" --finufft "*)
        if ! "$VENV/bin/python" -c "import finufft" 2>/dev/null; then
            "$VENV/bin/pip" install --quiet finufft
        fi
        ;;
esac
case " $* " in
    *" --rtk-only "*) ;;
    *) cargo build --locked --release -p fvr-host ;;
esac
echo "machine: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2 | sed 's/^ //')"
out_dir="${PEERS_OUT_DIR:-docs/performance}"
mkdir -p "$out_dir"
case " $* " in
    *" --finufft "*)
        rest=()
        for arg in "$@"; do
            [ "$arg" = "--finufft" ] || rest+=("$arg")
        done
        exec "$VENV/bin/python" bench/peers/finufft_peer.py --fvr "$TARGET/release/fvr" \
            --work "$TARGET/peers/work" --out "$out_dir/finufft.md" \
            --command "bash bench/peers/run.sh $*" "${rest[@]}"
        ;;
    *" --heads "*)
        rest=()
        for arg in "$@"; do
            [ "$arg" = "--heads" ] || rest+=("$arg")
        done
        mri=()
        if [ -n "${FVR_MRI_HEAD:-}" ]; then
            mri=(--mri "$(bash scripts/fetch-mri-head.sh)")
        fi
        exec "$VENV/bin/python" bench/peers/heads.py --fvr "$TARGET/release/fvr" \
            --ct "$(bash scripts/fetch-ct-head.sh)" "${mri[@]}" \
            --work "$TARGET/peers/work" --out "$out_dir/heads.md" "${rest[@]}"
        ;;
esac
"$VENV/bin/python" bench/peers/peers.py --fvr "$TARGET/release/fvr" \
    --work "$TARGET/peers/work" --out "$out_dir/peers.md" "$@"
