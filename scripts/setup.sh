#!/usr/bin/env bash
# Installs everything cutroute's build and tests need on a fresh Debian machine of this project's
# kind, and nothing when it is already there (every step checks first). Safe to run repeatedly.
#
#   - Chromium + ChromeDriver (Debian packages) for wasm tests and end-to-end tests;
#   - the wasm32 standard library: rustup's if it can be had, else Debian's rustc-web toolchain
#     with std sources, from which std is built for wasm32 on the fly (see scripts/wasm-env.sh);
#   - trunk and wasm-bindgen-cli at the exact versions the project pins;
#   - wasm-opt (binaryen from npm, run by Node; the version Trunk.toml pins) for the release build;
#   - Firefox ESR (Debian) for the single-file page's test in a second browser;
#   - playwright-core and ws (npm; they drive the system browsers, they never download one);
#   - LinuxCNC's standalone interpreter rs274, unpacked outside the clone (scripts/install-rs274.sh);
#   - ezdxf (PyPI), the independent DXF reader the corpus oracle and the reader benchmark use.
set -euo pipefail
cd "$(dirname "$0")/.."

TRUNK_VERSION=0.21.14
# wasm-bindgen-cli must equal the `wasm-bindgen = "=X"` pin of Cargo.toml.
WASM_BINDGEN_VERSION=$(sed -n 's/^wasm-bindgen = "=\([0-9.]*\)"/\1/p' Cargo.toml | head -n1)
export PATH="$HOME/.cargo/bin:$PATH"

log() { printf '[setup] %s\n' "$*" >&2; }

apt_packages=()
command -v chromium >/dev/null 2>&1 || apt_packages+=(chromium)
command -v chromedriver >/dev/null 2>&1 || apt_packages+=(chromium-driver)
# The single-file page is also tested in Firefox (over WebDriver BiDi, tests/e2e/firefox.mjs).
command -v firefox-esr >/dev/null 2>&1 || apt_packages+=(firefox-esr)

wasm_std_installed() {
  [ -d "$(rustc --print sysroot)/lib/rustlib/wasm32-unknown-unknown/lib" ]
}
wasm_mode=""
if wasm_std_installed; then
  wasm_mode=rustup
elif [ -x /usr/bin/cargo ] && [ -d /usr/lib/rustlib/src/rust/library ]; then
  wasm_mode=debian
else
  log "wasm32 std missing: trying rustup (60 s at most)"
  if timeout 60 rustup target add wasm32-unknown-unknown >/dev/null 2>&1 && wasm_std_installed; then
    wasm_mode=rustup
  else
    log "rustup could not fetch it: using Debian's rustc-web toolchain and building std for wasm32"
    apt_packages+=(rustc-web cargo-web rust-web-src)
    wasm_mode=debian
  fi
fi

if [ ${#apt_packages[@]} -gt 0 ]; then
  log "apt-get install ${apt_packages[*]}"
  SUDO=""; [ "$(id -u)" = 0 ] || SUDO=sudo
  $SUDO apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${apt_packages[@]}" >/dev/null
fi
mkdir -p target && echo "$wasm_mode" > target/.wasm-mode

# trunk and wasm-bindgen are built with the rustup toolchain (the machine's default cargo).
if [ "$(trunk --version 2>/dev/null)" != "trunk $TRUNK_VERSION" ]; then
  log "cargo install trunk $TRUNK_VERSION"
  cargo install trunk --version "$TRUNK_VERSION" --locked --quiet
fi
if [ "$(wasm-bindgen --version 2>/dev/null)" != "wasm-bindgen $WASM_BINDGEN_VERSION" ]; then
  log "cargo install wasm-bindgen-cli $WASM_BINDGEN_VERSION"
  # Not --locked: one locked dependency of this release is missing from the registry mirror.
  cargo install wasm-bindgen-cli --version "$WASM_BINDGEN_VERSION" --quiet
fi

if [ ! -x tools/node_modules/.bin/wasm-opt ]; then
  log "npm ci (tools: binaryen's wasm-opt)"
  (cd tools && npm ci --no-audit --no-fund --silent)
fi

if [ ! -d tests/e2e/node_modules/playwright-core ] || [ ! -d tests/e2e/node_modules/ws ]; then
  log "npm ci (tests/e2e)"
  (cd tests/e2e && PLAYWRIGHT_SKIP_BROWSER_DOWNLOAD=1 npm ci --no-audit --no-fund --silent)
fi
# LinuxCNC's standalone interpreter, the G-code tests' referee (crates/gcode/tests/linuxcnc.rs).
scripts/install-rs274.sh
# ezdxf: the second opinion on DXF files (it computed data/realworld/expected.csv; the reader
# benchmark times it, and scripts/make-dxf-matrix.py writes the made DXF corpus with it).
if ! python3 -c 'import ezdxf' 2>/dev/null; then
  log "pip install ezdxf"
  python3 -m pip install --quiet ezdxf 2>/dev/null \
    || python3 -m pip install --quiet --user --break-system-packages ezdxf
fi
log "ready (wasm std: $wasm_mode)"
