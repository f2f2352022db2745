# Sourced before every wasm build: points cargo (as called by trunk or by `cargo test --target
# wasm32-unknown-unknown`) at a toolchain that has a wasm32 standard library. Native builds must
# not source this: it swaps the compiler.
_cutroute_root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
export PATH="$HOME/.cargo/bin:$PATH"
if [ "$(cat "$_cutroute_root/target/.wasm-mode" 2>/dev/null)" = debian ]; then
  # Debian's Rust 1.96 (rustc-web) plus its std sources: build std for wasm32 on the fly.
  _rustup_sysroot="$(rustup run stable rustc --print sysroot)"
  export CARGO_TARGET_WASM32_UNKNOWN_UNKNOWN_LINKER="$_rustup_sysroot/lib/rustlib/x86_64-unknown-linux-gnu/bin/rust-lld"
  export RUSTC_BOOTSTRAP=1
  export CARGO_UNSTABLE_BUILD_STD=std,panic_abort
  export PATH="/usr/bin:$PATH"
  export RUSTC=/usr/bin/rustc CARGO=/usr/bin/cargo RUSTDOC=/usr/bin/rustdoc
  unset RUSTUP_TOOLCHAIN
  # Separate artifacts: std built from source must not mix with rustup's prebuilt one.
  export CARGO_TARGET_DIR="$_cutroute_root/target/wasm"
fi
unset _cutroute_root _rustup_sysroot
