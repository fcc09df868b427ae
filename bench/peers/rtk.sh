#!/usr/bin/env bash
# RTK's Joseph forward projector alone (pip itk-rtk, parallel geometry,
# oblique views, all ITK threads) on the Gaussian-mixture phantom: the median
# ms per view at each size and the SNR of one view against the closed-form
# line integrals. bench/peers/run.sh runs it beside fvr and scipy in one run;
# this is the RTK column alone.
# Usage: bash bench/peers/rtk.sh [SIZES] [VIEWS]   (default 128,256 and 7)
set -euo pipefail
cd "$(dirname "$0")/../.."
exec bash bench/peers/run.sh --rtk-only --sizes "${1:-128,256}" --views "${2:-7}"
