#!/usr/bin/env bash
# Fetches an MRI head when it is missing and prints its path: the MNI152
# 2009a symmetric T1 template (197 x 233 x 189 uint8, 1 mm, .nii.gz) that
# nilearn's PyPI wheel ships as package data. Only the wheel is downloaded
# (pip download, no install) and only that one file is unzipped, into
# target/data/; the data is never committed.
#
# Usage: bash scripts/fetch-mri-head.sh      (prints the path on stdout)
# If FVR_MRI_HEAD is set, that file is used instead and nothing is fetched.
# Fails loudly (exit 1) when the file is missing and cannot be fetched.
set -euo pipefail
cd "$(dirname "$0")/.."

version=0.14.1
member=nilearn/datasets/data/mni_icbm152_t1_tal_nlin_sym_09a_converted.nii.gz
dir=target/data/mri-head
path="$dir/mni_icbm152_t1_tal_nlin_sym_09a.nii.gz"

source scripts/lib/path-from-env.sh
path_from_env fetch-mri-head FVR_MRI_HEAD

if [[ ! -f "$path" ]]; then
    pip=""
    for candidate in pip3 pip; do
        if command -v "$candidate" > /dev/null; then
            pip="$candidate"
            break
        fi
    done
    if [[ -z "$pip" ]]; then
        if python3 -m pip --version > /dev/null 2>&1; then
            pip="python3 -m pip"
        else
            echo "fetch-mri-head: pip is not available; install it (e.g. apt-get install python3-pip)," >&2
            echo "  or set FVR_MRI_HEAD to a NIfTI MRI head" >&2
            exit 1
        fi
    fi
    if ! command -v unzip > /dev/null && ! command -v python3 > /dev/null; then
        echo "fetch-mri-head: neither unzip nor python3 is available to open the wheel" >&2
        exit 1
    fi
    mkdir -p "$dir"
    wheels="$dir/wheel"
    echo "fetch-mri-head: downloading nilearn $version's wheel from PyPI (12 MB) for its MNI152 T1 template" >&2
    $pip download --quiet --no-deps --only-binary=:all: "nilearn==$version" -d "$wheels" >&2
    wheel="$(ls "$wheels"/nilearn-"$version"-*.whl | head -n 1)"
    tmp="$path.tmp"
    if command -v unzip > /dev/null; then
        unzip -p "$wheel" "$member" > "$tmp"
    else
        python3 -c 'import sys, zipfile; sys.stdout.buffer.write(zipfile.ZipFile(sys.argv[1]).read(sys.argv[2]))' \
            "$wheel" "$member" > "$tmp"
    fi
    if [[ ! -s "$tmp" ]]; then
        rm -f "$tmp"
        echo "fetch-mri-head: $member is missing from $wheel" >&2
        exit 1
    fi
    mv "$tmp" "$path"
    rm -rf "$wheels"
fi

echo "$(pwd)/$path"
