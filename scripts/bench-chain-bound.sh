#!/usr/bin/env bash
# The chain job's certified bound on every real nest of several contours (issue #14): prints a
# Markdown table of `cutroute solve FILE --solver chain --time-limit L --json` at the given
# prices. `ub` is the chained route's cost F, `lb` the certified bound, `P` the perimeters'
# cut that every route pays; "moves gap" is the gap on the rest, (ub − lb)/(ub − P). The peer
# is the trivial bound every chain route meets, P + one pierce: its moves gap is in the last
# gap column. Wall is the whole command's.
#
#   scripts/bench-chain-bound.sh [LIMIT_S] [C_OFF,C_ON,C_PT]   # defaults: 10 and 0.1,1,0.5
#
# Builds the release CLI first (cutroute-cli only).
set -u
cd "$(dirname "$0")/.."
LIMIT=${1:-10}
COST=${2:-0.1,1,0.5}
cargo build --release -q -p cutroute-cli || exit 1
BIN=target/release/cutroute
echo "| nest | contours | limit s | prices | pierces | ub (F) | lb | gap | P | moves gap | trivial moves gap | wall s |"
echo "|---|---|---|---|---|---|---|---|---|---|---|---|"
for nest in data/nests/dbs/nested.dbs data/nests/dbs/seven.dbs data/nests/dbs-json/test0.dbs.json \
  data/nests/dbs-json/test1.dbs.json data/nests/dbs-json/E1X_6_01.dbs.json data/nests/dxf/planka.dxf \
  data/nests/dxf/propeller.dxf data/nests/dxf/cross.dxf data/nests/svg/plates.svg \
  data/nests/tflex/Nest01.tfnesting data/nests/tflex/Nest02.tfnesting data/nests/tflex/Nest03.tfnesting; do
  t0=$(date +%s.%N)
  out=$("$BIN" solve "$nest" --solver chain --time-limit "$LIMIT" --cost "$COST" --json 2>/dev/null)
  t1=$(date +%s.%N)
  wall=$(echo "$t1 - $t0" | bc)
  contours=$("$BIN" inspect "$nest" --json 2>/dev/null | python3 -c 'import json,sys; print(json.load(sys.stdin).get("contours","?"))' 2>/dev/null)
  echo "$out" | NEST="$(basename "$nest")" LIMIT="$LIMIT" COST="$COST" WALL="$wall" CONTOURS="$contours" python3 -c '
import json, os, sys
d = json.load(sys.stdin)
env = os.environ
c_on, c_pt = (float(x) for x in env["COST"].split(",")[1:])
ub, lb = d["ub"], d["lb"]
p = (d["cut_length"] - d["link_length"]) * 1e-3 * c_on
moves = ub - p
gap = (ub - lb) / ub
moves_gap = (ub - lb) / moves if moves > 0 else 0.0
trivial = (ub - p - c_pt) / moves if moves > 0 else 0.0
wall = float(env["WALL"])
cells = [env["NEST"], env["CONTOURS"], env["LIMIT"], env["COST"], str(d["pierces"]),
         f"{ub:.3f}", f"{lb:.3f}", f"{100 * gap:.2f} %", f"{p:.3f}",
         f"{100 * moves_gap:.2f} %", f"{100 * trivial:.2f} %", f"{wall:.2f}"]
print("| " + " | ".join(cells) + " |")
' || echo "| $(basename "$nest") | $contours | $LIMIT | $COST | failed | | | | | | | |"
done
