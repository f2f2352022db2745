#!/usr/bin/env bash
# Installs LinuxCNC's standalone G-code interpreter `rs274` (Debian package linuxcnc-uspace), the
# referee of the G-code tests (crates/gcode/tests/linuxcnc.rs), without installing the package:
# `apt-get install linuxcnc-uspace` pulls a whole GUI stack and wants a real-time setup, while
# the interpreter alone needs only the package's own libraries and Boost.Python. So the .debs are
# fetched with `apt-get download` and unpacked with `dpkg -x` into a folder outside the clone
# (CI runs in fresh clones; target/ would be empty there), and a wrapper sets LD_LIBRARY_PATH.
#
#   scripts/install-rs274.sh            installs into /opt/cutroute/linuxcnc (or $CUTROUTE_LINUXCNC_DIR)
#
# The result is $DIR/rs274: a wrapper taking rs274's own arguments (always give it `-t` with a
# tool table: without one the interpreter exits 1 with no message). Idempotent: does nothing when
# the wrapper already runs.
set -euo pipefail

DIR=${CUTROUTE_LINUXCNC_DIR:-/opt/cutroute/linuxcnc}
log() { printf '[install-rs274] %s\n' "$*" >&2; }

works() {
  [ -x "$DIR/rs274" ] || return 1
  local probe
  probe=$(mktemp -d)
  printf 'T1 P1 D2.0 ;\n' >"$probe/tool.tbl"
  printf 'G21 G90\nG00 X1 Y2\nM30\n' >"$probe/p.ngc"
  local out
  out=$("$DIR/rs274" -g -t "$probe/tool.tbl" "$probe/p.ngc" </dev/null 2>/dev/null || true)
  rm -rf "$probe"
  grep -q 'STRAIGHT_TRAVERSE(1.0000, 2.0000' <<<"$out"
}

if works; then
  log "already installed: $DIR/rs274"
  exit 0
fi

SUDO=""
[ "$(id -u)" = 0 ] || SUDO=sudo
$SUDO mkdir -p "$DIR"
[ -w "$DIR" ] || $SUDO chown "$(id -u):$(id -g)" "$DIR"

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

fetch() {
  # apt-get download into a folder the _apt user cannot write falls back to an unsandboxed
  # download and warns about it; the warning is harmless.
  apt-get download "$@" 2>&1 | grep -v 'unsandboxed' >&2 || true
}

if ! apt-cache policy linuxcnc-uspace 2>/dev/null | grep -q 'Candidate: [0-9]'; then
  log "apt-get update (linuxcnc-uspace is not in the package lists yet)"
  $SUDO apt-get update -qq
fi
log "downloading linuxcnc-uspace and libboost-python1.74.0"
fetch linuxcnc-uspace libboost-python1.74.0
for deb in ./*.deb; do dpkg -x "$deb" "$DIR/root"; done

libpath="$DIR/root/usr/lib:$DIR/root/usr/lib/x86_64-linux-gnu"
# Libraries a fresh machine may lack (those of this Debian's base image are usually there);
# fetched only when the interpreter still misses one.
if LD_LIBRARY_PATH=$libpath ldd "$DIR/root/usr/bin/rs274" | grep -q 'not found'; then
  log "fetching the remaining shared libraries"
  rm -f ./*.deb
  fetch libpython3.11 libedit2 libtirpc3 libbsd0 libmd0 libgssapi-krb5-2 libkrb5-3 \
    libk5crypto3 libkrb5support0 libkeyutils1 libexpat1 zlib1g libtinfo6 libstdc++6
  for deb in ./*.deb; do dpkg -x "$deb" "$DIR/root"; done
fi
if LD_LIBRARY_PATH=$libpath ldd "$DIR/root/usr/bin/rs274" | grep 'not found'; then
  log "rs274 still misses the libraries above"
  exit 1
fi

cat >"$DIR/rs274" <<EOF
#!/bin/sh
# LinuxCNC's standalone interpreter, unpacked by cutroute's scripts/install-rs274.sh.
LD_LIBRARY_PATH="$libpath\${LD_LIBRARY_PATH:+:\$LD_LIBRARY_PATH}" exec "$DIR/root/usr/bin/rs274" "\$@"
EOF
chmod +x "$DIR/rs274"

if works; then
  log "installed: $DIR/rs274"
else
  log "installed $DIR/rs274 but it does not interpret a probe program"
  exit 1
fi
