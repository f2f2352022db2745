#!/usr/bin/env bash
# Benchmark: the same solver subset (crates/engine/tests/bench_subset) compiled to wasm32 and run
# in headless Chromium, and natively (release builds, one thread each). Prints a Markdown table
# with the wasm/native time ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export PATH="$HOME/.cargo/bin:$PATH"

wasm_log=$(mktemp); native_log=$(mktemp)
(
  source scripts/wasm-env.sh
  export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner
  export CHROMEDRIVER=/usr/bin/chromedriver
  export WASM_BINDGEN_TEST_TIMEOUT=3600
  cargo test --release --target wasm32-unknown-unknown -p cutroute-engine --test wasm_bench -- --nocapture
) > "$wasm_log" 2>&1 || { tail -n 30 "$wasm_log" >&2; exit 1; }
cargo bench -p cutroute-engine --bench wasm_peer > "$native_log" 2>/dev/null

echo "| case | result | native s | wasm s | wasm / native |"
echo "|---|---|---:|---:|---:|"
grep -o 'BENCH .*' "$native_log" | while read -r _ case native_s value proven; do
  wasm_s=$(grep -o "BENCH $case .*" "$wasm_log" | awk '{print $3}')
  ratio=$(python3 -c "print('%.2f' % (float('$wasm_s') / max(float('$native_s'), 1e-3)))")
  note=$([ "$proven" = true ] && echo "$value (proven)" || echo "$value")
  echo "| $case | $note | $native_s | $wasm_s | $ratio |"
done
rm -f "$wasm_log" "$native_log"
