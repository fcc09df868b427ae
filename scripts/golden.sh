#!/usr/bin/env bash
# The golden set: renders a fixed list of jobs with the `fvr` binary and
# prints one line per output, `sha256  name`, so that a refactor can show
# every image is bit for bit what it was.
#
# Usage: bash scripts/golden.sh [FVR_BINARY] > hashes.txt
#   then, after the change: bash scripts/golden.sh | diff hashes.txt -
# FVR_BINARY defaults to target/release/fvr (built first when it is the default).
# The CT head jobs run when FVR_CT_HEAD names Cranium.inv3
# (bash scripts/fetch-ct-head.sh prints it).
set -euo pipefail
cd "$(dirname "$0")/.."

fvr="${1:-}"
if [[ -z "$fvr" ]]; then
    cargo build --release --locked -p fvr-host --bin fvr >&2
    fvr=target/release/fvr
fi
fvr="$(realpath "$fvr")"
out="$(mktemp -d)"
trap 'rm -rf "$out"' EXIT

# name | arguments (the output path is appended as --out)
jobs=(
    "gauss-x-f16.nrrd|render gaussians --dir 1,0,0"
    "gauss-tilt-kb6.nrrd|render gaussians --dir 1,0.45,0.3 --filter kb6 --oversample 2 --precision f32"
    "gauss-diag-kb4.nrrd|render gaussians --dir 1,1,1 --filter kb4 --oversample 1.25 --precision f16"
    "gauss-acc80.nrrd|render gaussians --dir 0.3,-1,0.2 --accuracy 80"
    "gauss-f64-cubic.nrrd|render gaussians --dir 0,0,1 --up 0,1,0 --filter cubic --oversample 1 --precision f64"
    "gauss-nearest.nrrd|render gaussians --dir 1,0.2,0 --filter nearest --oversample 2 --precision f32"
    "gauss-linear.nrrd|render gaussians --dir 1,0.2,0.7 --filter linear --oversample 1.5 --precision f32"
    "gauss-kb3-size.nrrd|render gaussians --dir 1,2,3 --filter kb3 --size 48x40"
    "gauss-preview1.nrrd|render gaussians --dir 1,0.3,0.2 --preview-level 1"
    "gauss-adaptive.nrrd|render gaussians --dir 1,0.3,0.2 --adaptive 40 --filter kb6 --oversample 2"
    "gauss-adaptive-paper.nrrd|render gaussians --dir 0.2,1,0.3 --adaptive 30 --adaptive-bound paper --filter kb4 --oversample 2"
    "blobs-cue.nrrd|render blobs --dir 1,0.3,0.2 --depth-cue linear:1,0.2"
    "blobs-sine.nrrd|render blobs --dir 0,1,0.3 --depth-cue sine:1,0.4"
    "teapot-3lights.nrrd|render teapot --dir 1,0.3,0.2 --light-ring 3 --ambient 0.1,0.1,0.1"
    "teapot-light.png|render teapot --dir 0,1,0 --light 1,1,0:1,0.8,0.6"
    "shepp.png|render shepp-logan --dir 0,0,1 --up 0,1,0"
    "sphere-f32.nrrd|render sphere --dir 1,1,0 --precision f32"
    "brainsmall.nrrd|render brainsmall --dir 1,0,0"
    "brainsmall-tilt.png|render brainsmall --dir 1,0.3,0.2 --accuracy 60"
    "brainsmall-resample.nrrd|render brainsmall --dir 0,1,0.2 --resample 64"
    "brainsmall-cue-light.nrrd|render brainsmall --dir 1,0.5,0 --depth-cue linear:1,0.3 --light 1,0,0:1,1,1"
    "scene-gaussians.png|render --scene examples/gaussians-xray.toml"
    "scene-brainsmall.png|render --scene examples/brainsmall-xray-hot.toml"
    "turntable-gauss.apng|turntable gaussians --frames 6"
    "turntable-teapot.apng|turntable --scene examples/teapot-turntable.toml --frames 4"
    "convert-brainsmall.nrrd|convert brainsmall"
)
if [[ -n "${FVR_CT_HEAD:-}" && -f "${FVR_CT_HEAD}" ]]; then
    jobs+=(
        "ct-head.nrrd|render ct-head --dir 1,0.45,0.3"
        "ct-head-spacing.nrrd|render ct-head --dir 0,1,0 --up 0,0,1"
        "ct-head-adaptive.nrrd|render ct-head --dir 1,0.3,0.2 --adaptive 40 --ignore-spacing"
    )
fi

status=0
for job in "${jobs[@]}"; do
    name="${job%%|*}"
    read -r -a args <<< "${job#*|}"
    if ! "$fvr" "${args[@]}" --out "$out/$name" --quiet > "$out/$name.log" 2>&1; then
        echo "golden: \`fvr ${args[*]}\` failed:" >&2
        cat "$out/$name.log" >&2
        status=1
        continue
    fi
    (cd "$out" && sha256sum "$name")
done
exit $status
