#!/usr/bin/env bash
# Renders the README gallery into docs/gallery/: for the CT head, the MNI152
# template, VolPack's brainsmall and the Utah teapot, an X-ray, a depth-cued
# view, a shaded view (one white light) and three coloured lights 120 degrees
# apart (paper, figure 8).
# The CT head (GPL-2, Debian's invesalius-examples) and MNI152 (from the
# nilearn wheel on PyPI) are fetched at run time and never committed; the
# PNGs are our own outputs.
# Usage: bash scripts/gallery.sh   (needs apt-get for the CT head, pip for MNI152)
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --locked --release -p fvr-host
fvr="${CARGO_TARGET_DIR:-target}/release/fvr"
out=docs/gallery
mkdir -p "$out"

bash scripts/fetch-ct-head.sh > /dev/null
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
pip download --quiet --no-deps nilearn -d "$work" > /dev/null
python3 - "$work" <<'PY'
import glob, sys, zipfile
work = sys.argv[1]
wheel = zipfile.ZipFile(glob.glob(f"{work}/nilearn-*.whl")[0])
name = "nilearn/datasets/data/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz"
open(f"{work}/mni152.nii.gz", "wb").write(wheel.read(name))
PY

# render NAME CUE LIGHT VOLUME-AND-VIEW...: the four pictures of one volume.
render() {
    local name=$1 cue=$2 light=$3
    shift 3
    "$fvr" render "$@" --out "$out/$name-xray.png"
    "$fvr" render "$@" --depth-cue "$cue" --out "$out/$name-depth-cued.png"
    "$fvr" render "$@" --light "$light" --ambient 0.03 --out "$out/$name-shaded.png"
    "$fvr" render "$@" --light-ring 3 --ambient 0.05 --out "$out/$name-three-lights.png"
}

# CT: air (-1024 HU) to zero, cubic voxels of 1.3 mm (192 along the longest side).
render ct-head linear:1,0.25 -1,-0.3,0.7:1 \
    ct-head --background -1024 --resample 192 --size 192 --dir 1,0.25,0
# MNI152 T1 template (skull-stripped), 1 mm voxels, seen from the side.
render mni152 linear:1,0.2 -1,-0.3,0.7:1 \
    "$work/mni152.nii.gz" --size 192 --dir 1,0.25,0
# brainsmall fills its grid: oversample 2 keeps the face from wrapping around.
render brainsmall linear:1,0.2 0.3,-0.7,-1:1 \
    brainsmall --background 30 --oversample 2 --dir 0,0,1 --up 0,-1,0
# The teapot, voxelized from Newell's patches at 192^3.
render teapot linear:1,0.15 -0.7,-1,1.1:1 \
    teapot@192 --size 192 --dir 0.3,1,-0.45
echo "wrote $(ls "$out"/*.png | wc -l) images to $out"
