#!/usr/bin/env bash
# The main job: build the app and serve it at http://127.0.0.1:8080 (rebuilds on change).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
source scripts/wasm-env.sh
exec trunk serve --release "$@"
