#!/usr/bin/env bash
# Installs the InVesalius CT head (Debian's `invesalius-examples`, GPL-2, so it
# is never committed) when it is missing, and prints the path of Cranium.inv3
# (256 x 256 x 108 int16 CT, 0.957 x 0.957 x 1.5 mm).
#
# Usage: bash scripts/fetch-ct-head.sh      (prints the path on stdout)
# If FVR_CT_HEAD is set, that file is used instead and nothing is installed.
# Fails loudly (exit 1) when the file is missing and cannot be installed.
set -euo pipefail

path=/usr/share/doc/invesalius-examples/examples/Cranium.inv3

source "$(dirname "$0")/lib/path-from-env.sh"
path_from_env fetch-ct-head FVR_CT_HEAD

if [[ ! -f "$path" ]]; then
    if [[ "$(id -u)" -ne 0 ]]; then
        echo "fetch-ct-head: $path is missing and installing it needs root:" >&2
        echo "  sudo apt-get install invesalius-examples   (or set FVR_CT_HEAD to a copy of Cranium.inv3)" >&2
        exit 1
    fi
    if ! command -v apt-get > /dev/null; then
        echo "fetch-ct-head: $path is missing and apt-get is not available;" >&2
        echo "  get Cranium.inv3 from Debian's invesalius-examples package and set FVR_CT_HEAD" >&2
        exit 1
    fi
    echo "fetch-ct-head: installing Debian's invesalius-examples (18 MB, GPL-2)" >&2
    export DEBIAN_FRONTEND=noninteractive
    # The package lists may be stale or absent on a fresh machine.
    if ! apt-get install -y -q --no-install-recommends invesalius-examples > /dev/null; then
        apt-get update -q > /dev/null
        apt-get install -y -q --no-install-recommends invesalius-examples > /dev/null
    fi
fi

if [[ ! -f "$path" ]]; then
    echo "fetch-ct-head: invesalius-examples is installed but $path is missing" >&2
    exit 1
fi
echo "$path"
