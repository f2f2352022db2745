#!/usr/bin/env bash
# Benchmark: the exact PCGTSP solver compiled to wasm32 and run in headless Chromium, against the
# same instances solved natively by the CLI (release builds, one thread each). Prints a Markdown
# table with the wasm/native time ratio.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export PATH="$HOME/.cargo/bin:$PATH"

wasm_log=$(mktemp)
(
  source scripts/wasm-env.sh
  export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner
  export CHROMEDRIVER=/usr/bin/chromedriver
  export WASM_BINDGEN_TEST_TIMEOUT=1800
  cargo test --release --target wasm32-unknown-unknown -p cutroute-engine --test wasm_bench -- --nocapture
) 2>&1 | tee "$wasm_log" | grep -E 'WASM-BENCH|test result' >&2

cargo build --release -p cutroute-cli -q
echo "| instance | optimum (native) | native s | wasm s | wasm / native |"
echo "|---|---:|---:|---:|---:|"
grep -o 'WASM-BENCH .*' "$wasm_log" | while read -r _ name ub lb proven elapsed; do
  wasm_s=${elapsed#elapsed_s=}
  native=$(target/release/cutroute solve "../shared/data/pcgtsp/industrial/$name.pcglns" --solver exact --time-limit 120 --json)
  native_s=$(printf '%s' "$native" | python3 -c 'import json,sys; print("%.3f" % json.load(sys.stdin)["elapsed_s"])')
  native_ub=$(printf '%s' "$native" | python3 -c 'import json,sys; d=json.load(sys.stdin); print("%g%s" % (d["ub"], "" if d["proven_optimal"] else " (not proven)"))')
  ratio=$(python3 -c "print('%.2f' % ($wasm_s / max($native_s, 1e-3)))")
  echo "| $name | $native_ub | $native_s | $wasm_s (${ub#ub=}, ${proven}) | $ratio |"
done
rm -f "$wasm_log"
