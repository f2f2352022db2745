#!/usr/bin/env bash
# Time limits are promises (issue #15): prints a Markdown table of the wall time of
# `cutroute solve --time-limit L` (and `convert --solver exact`) for every solver on the real
# nests, a generated nest and every PCGTSP instance of data/pcgtsp. "read" is the wall of
# `inspect` on the file (reading it is not the solver's time); a row is "over" when
# wall − read exceeds L + 1 s. Exit 1 within the limit = a clean "no route before the limit".
#
#   scripts/bench-time-limits.sh [LIMIT_S] [GENERATED_CONTOURS]   # defaults: 5 and 100000
#
# Builds the release CLI first (cutroute-cli only).
set -u
cd "$(dirname "$0")/.."
LIMIT=${1:-5}
CONTOURS=${2:-100000}
cargo build --release -q -p cutroute-cli || exit 1
BIN=target/release/cutroute
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
"$BIN" generate --contours "$CONTOURS" --seed 1 --out "$TMP/generated-$CONTOURS.json" || exit 1

wall() { # prints "wall exit" of a command
  local t0 t1 code
  t0=$(date +%s.%N)
  "$@" >/dev/null 2>&1
  code=$?
  t1=$(date +%s.%N)
  printf '%.2f %d' "$(echo "$t1 - $t0" | bc)" "$code"
}

row() { # file solver wall exit read
  local file=$1 solver=$2 w=$3 code=$4 read=$5 over="" net
  net=$(printf '%.2f' "$(echo "$w - $read" | bc)")
  if (($(echo "$net > $LIMIT + 1" | bc))); then over="**over**"; fi
  echo "| $(basename "$file") | $solver | $LIMIT | $read | $w | $net | $code | $over |"
}

echo "| file | solver | limit s | read s | wall s | wall − read s | exit | |"
echo "|---|---|---|---|---|---|---|---|"
NESTS=(data/nests/dbs/nested.dbs data/nests/dbs/seven.dbs data/nests/tflex/Nest02.tfnesting "$TMP/generated-$CONTOURS.json")
for nest in "${NESTS[@]}"; do
  read -r r _ <<<"$(wall "$BIN" inspect "$nest")"
  for solver in nearest ccp heuristic exact discrete chain sccp gsccp aoe; do
    read -r w code <<<"$(wall "$BIN" solve "$nest" --solver "$solver" --time-limit "$LIMIT" --json)"
    row "$nest" "$solver" "$w" "$code" "$r"
  done
  read -r w code <<<"$(wall "$BIN" convert "$nest" "$TMP/out.nc" --solver exact --time-limit "$LIMIT")"
  row "$nest" "convert --solver exact" "$w" "$code" "$r"
done
for instance in data/pcgtsp/pcgtsplib/*.pcglns data/pcgtsp/industrial/*.pcglns; do
  read -r r _ <<<"$(wall "$BIN" inspect "$instance")"
  for solver in heuristic exact; do
    read -r w code <<<"$(wall "$BIN" solve "$instance" --solver "$solver" --time-limit "$LIMIT" --json)"
    row "$instance" "$solver" "$w" "$code" "$r"
  done
done
