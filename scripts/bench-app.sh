#!/usr/bin/env bash
# The app benchmark (issue 7): first render, a 5,000-contour nest's render, frame rates while
# panning, zooming and animating it, and the compressed wasm size, measured in headless Chromium
# against the release build served from a sub-path as the end-to-end tests serve it. Prints a
# Markdown table (metric, value, target) and notes on where frame time goes.
#
#   scripts/bench-app.sh            # reuses dist/ when it exists
#   scripts/bench-app.sh --rebuild  # runs scripts/build-release.sh first
#
# CONTOURS and SEED (environment) choose the synthetic nest; default 5000 and 1.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export PATH="$HOME/.cargo/bin:$PATH"

if [ "${1:-}" = "--rebuild" ] || [ ! -f dist/index.html ]; then
  scripts/build-release.sh
fi

contours=${CONTOURS:-5000}
seed=${SEED:-1}
bench_dir=target/bench-app
mkdir -p "$bench_dir"
nest="$(pwd)/$bench_dir/synthetic-$contours-$seed.json"
cargo build --release -q -p cutroute-cli
cli="${CARGO_TARGET_DIR:-target}/release/cutroute"
"$cli" generate --contours "$contours" --seed "$seed" --out "$nest"
# The view draws one path per part; geometry JSON stores the sheet as its first part.
parts=$(( $("$cli" inspect "$nest" --json | sed -n 's/.*"parts":\([0-9]*\).*/\1/p') - 1 ))

echo "machine: $(nproc) cores, $(lscpu | sed -n 's/^Model name: *//p'), $(chromium --version 2>/dev/null || echo chromium), load average $(cut -d" " -f1-3 /proc/loadavg)" >&2
(cd tests/e2e && node bench.mjs "$nest" "$parts")
