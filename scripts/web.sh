#!/usr/bin/env bash
# Build the browser viewer (issue 40) into web/dist/: index.html, fvr.js
# (one JavaScript module: page and Web Worker) and fvr_web.wasm (fvr-engine
# for wasm32-unknown-unknown with SIMD128, one thread). No bundler, no
# wasm-bindgen, nothing fetched at run time: the page works offline.
#
#   bash scripts/web.sh          # then: fvr view brainsmall
set -euo pipefail
cd "$(dirname "$0")/.."

rustup target list --installed | grep -qx wasm32-unknown-unknown \
  || rustup target add wasm32-unknown-unknown

# Target-specific flags, so the host's build scripts and proc macros keep
# theirs (and their cache). No debug info: it is 30 MB of the module.
CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUSTFLAGS="-C target-feature=+simd128" \
CARGO_PROFILE_RELEASE_DEBUG=0 \
CARGO_PROFILE_RELEASE_STRIP=debuginfo \
  cargo build --release --locked -p fvr-web --target wasm32-unknown-unknown

dist=web/dist
rm -rf "$dist.tmp"
mkdir -p "$dist.tmp"
cp web/page/index.html "$dist.tmp/"
cp target/wasm32-unknown-unknown/release/fvr_web.wasm "$dist.tmp/"
# One module from the page's sources, in dependency order; their `export`
# keywords only document what the next file uses.
{
  echo "// Built by scripts/web.sh from web/page/*.js; edit those, not this."
  for f in camera worker viewer main; do
    echo "// ---- web/page/$f.js"
    sed 's/^export //' "web/page/$f.js"
  done
} > "$dist.tmp/fvr.js"
rm -rf "$dist"
mv "$dist.tmp" "$dist"
ls -l "$dist"
