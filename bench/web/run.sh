#!/usr/bin/env bash
# Views per second of the browser viewer in headless Chromium (issue 40):
# gaussians@128 and @256, full quality and the drag preview level (1), one
# thread in the page's Web Worker, 60 views turning about the up axis after
# one untimed view. A benchmark, not a test: it asserts nothing.
#
#   bash bench/web/run.sh        # builds web/dist and a release fvr first
set -euo pipefail
cd "$(dirname "$0")/../.."
bash scripts/web.sh >/dev/null
command -v chromium >/dev/null || { apt-get update -qq && apt-get install -y -qq chromium >/dev/null; }
cargo build --locked --release -p fvr-host --bin fvr
python3 scripts/web-test.py --fvr target/release/fvr --bench
