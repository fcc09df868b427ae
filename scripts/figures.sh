#!/usr/bin/env bash
# Regenerates the figures in docs/figures/ (paper figure 6 panels a-d and a
# figure-8-style render with three coloured lights 120 degrees apart).
# Usage: bash scripts/figures.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --locked --release -p fvr-host
fvr=target/release/fvr
out=docs/figures
mkdir -p "$out"

# Phantom: 24 random anisotropic Gaussians (`blobs`, seed 4), 128^3, kb4, oversample 2, f16.
view=(--dir 1,0.45,-0.3 --filter kb4 --oversample 2 --size 128)
p=blobs@128:4
"$fvr" render "$p" "${view[@]}" --out "$out/phantom-6a-xray.png"
"$fvr" render "$p" "${view[@]}" --depth-cue linear:1,0.15 --out "$out/phantom-6b-depth-cued.png"
"$fvr" render "$p" "${view[@]}" --light 0,0.6,1:1,1,1 --ambient 0.02 --out "$out/phantom-6c-shaded.png"
"$fvr" render "$p" "${view[@]}" --light 0,0.6,1:1,1,1 --ambient 0.02 --depth-cue linear:1,0.15 \
    --out "$out/phantom-6d-shaded-depth-cued.png"
"$fvr" render "$p" "${view[@]}" --light-ring 3 --ambient 0.05 --out "$out/phantom-8-three-lights.png"

# The InVesalius CT head (GPL-2; installed from Debian at run time, never
# committed), air set to zero, resampled to cubic voxels of 1.9 mm (128 along
# its longest side), lateral view.
ct=(ct-head --background -1024 --resample 128 --dir 1,0.25,0 --up 0,0,1)
bash scripts/fetch-ct-head.sh > /dev/null
"$fvr" render "${ct[@]}" --out "$out/ct-6a-xray.png"
"$fvr" render "${ct[@]}" --depth-cue linear:1,0.25 --out "$out/ct-6b-depth-cued.png"
"$fvr" render "${ct[@]}" --light 0,-1,0.4:1,1,1 --ambient 0.03 --out "$out/ct-6c-shaded.png"
"$fvr" render "${ct[@]}" --light 0,-1,0.4:1,1,1 --ambient 0.03 --depth-cue linear:1,0.25 \
    --out "$out/ct-6d-shaded-depth-cued.png"
"$fvr" render "${ct[@]}" --light-ring 3 --ambient 0.03 --out "$out/ct-8-three-lights.png"
