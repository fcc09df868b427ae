#!/usr/bin/env bash
# Regenerates the measured figures of README.md and docs/ from runs, or
# checks that the docs still hold what the program prints.
#
# Every figure block in a Markdown file sits between two marker lines,
#   <!-- figures:NAME -->
#   ...
#   <!-- /figures:NAME -->
# and NAME is a generator of scripts/docs-figures/ whose standard output
# is the block (scripts/docs-figures/registry.py lists them).
#
# Usage: bash scripts/docs-figures.sh [--check] [--quick] [--all] [--list] [NAME...]
#   (no option)  rerun the generators (all but the manual ones, or NAME...)
#                and rewrite their blocks in place, each file atomically;
#   --check      rerun the deterministic generators (dB, instruction counts,
#                bytes, choices; not times) and fail, naming the file and
#                the block, where a doc differs from their output;
#   --quick      only the quick deterministic ones (what scripts/test-all.sh checks);
#   --all        the manual ones too (peers, long studies);
#   --list       the generators: name, checked or timing, cost, blocks.
# Environment: FVR (the fvr binary; default: a release build, made first),
# FVR_CT_HEAD and FVR_MRI_HEAD (the heads, for the blocks that need them),
# DOCS_FIGURES_FIRMWARE_LOG and DOCS_FIGURES_CAPI_LOG (the output of
# scripts/firmware.sh and scripts/capi.sh, instead of running them again),
# DOCS_FIGURES_CACHE (a directory kept between runs for the outputs of the
# long commands several blocks share).
set -euo pipefail
exec python3 "$(dirname "$0")/docs-figures/main.py" "$@"
