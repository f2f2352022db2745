#!/usr/bin/env bash
# Remakes the README's screenshots (docs/screenshots/*.png) from the release build in dist/
# (scripts/build-release.sh first), through the e2e harness in headless Chromium.
set -euo pipefail
cd "$(dirname "$0")/../tests/e2e"
node screenshots.mjs
