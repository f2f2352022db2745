#!/usr/bin/env bash
# Release build for static hosting: writes dist/ with relative asset URLs, so the folder works
# served from any path (https://host/, https://host/cutroute/, …).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/wasm-env.sh
# binaryen's wasm-opt from tools/ (npm): trunk takes it from the PATH when its version is the pinned one.
export PATH="$PWD/tools/node_modules/.bin:$PATH"
trunk build --release --public-url ./ "$@"
# The service worker caches every file of this build (offline after the first visit).
scripts/precache.py dist
# dist/cutroute.html: the same app in one file, for a double-click (file://) or a USB stick.
scripts/single-file.py dist
ls -l dist/*.wasm | awk '{print "[build] " $5 " bytes  " $9}' >&2
