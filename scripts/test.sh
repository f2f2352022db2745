#!/usr/bin/env bash
# Every test: native unit/integration/doc tests, the engine as wasm in headless Chromium, and the
# end-to-end tests of the release build in headless Chromium. Installs what is missing first.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
export PATH="$HOME/.cargo/bin:$PATH"

echo "== native tests (every crate of the workspace, natively)"
mkdir -p target
cargo test --workspace 2>&1 | tee target/native-tests.log
scripts/check-tested-crates.py target/native-tests.log

echo "== wasm tests in headless Chromium"
(
  source scripts/wasm-env.sh
  export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_RUNNER=wasm-bindgen-test-runner
  export CHROMEDRIVER=/usr/bin/chromedriver
  export WASM_BINDGEN_TEST_TIMEOUT=300
  cargo test --target wasm32-unknown-unknown -p cutroute-engine --test wasm
)

echo "== end-to-end tests (release build served from a sub-path)"
scripts/build-release.sh
(cd tests/e2e && npm test)
