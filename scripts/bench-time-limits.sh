#!/usr/bin/env bash
# Time limits are promises (issue #15): prints a Markdown table of the wall time of
# `cutroute solve --time-limit L` (and `convert --solver exact`) for every solver on the real
# nests, a generated nest and every PCGTSP instance of data/pcgtsp. "read" is the wall of
# `inspect` on the file; `solve` counts reading against its limit, so a row is "over" when
# the wall exceeds L + 1 s ("wall − read" is shown for readers slower than the limit).
# Exit 1 within the limit = a clean "no route before the limit".
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

wall() { # prints "wall exit" of a command; its standard output is kept in $TMP/out
  local t0 t1 code
  t0=$(date +%s.%N)
  "$@" >"$TMP/out" 2>/dev/null
  code=$?
  t1=$(date +%s.%N)
  printf '%.2f %d' "$(echo "$t1 - $t0" | bc)" "$code"
}

row() { # file solver wall exit read
  local file=$1 solver=$2 w=$3 code=$4 read=$5 over="" net
  net=$(printf '%.2f' "$(echo "$w - $read" | bc)")
  if (($(echo "$w > $LIMIT + 1" | bc))); then over="**over**"; fi
  # The solver had no route of its own by the limit: the report's `fallback` says so.
  if grep -q '"fallback":"' "$TMP/out" 2>/dev/null; then over="$over fallback"; fi
  echo "| $(basename "$file") | $solver | $LIMIT | $read | $w | $net | $code | $over |"
}

echo "| file | solver | limit s | read s | wall s | wall − read s | exit | |"
echo "|---|---|---|---|---|---|---|---|"
# Large single contours (work in slices proportional to vertices, not contours), a nest of
# 60,000 generated contours, a 2 MB DXF of 1,200 closed splines (with ezdxf, if installed) and
# a tiny DXF that expands to 160,000 contours.
"$BIN" generate --contours 60000 --seed 1 --out "$TMP/generated-60000.json" || exit 1
python3 - "$TMP" <<'PY' || exit 1
import json, math, sys
out = sys.argv[1]
def contour_file(name, points):
    path = [[x, y, 0] for x, y in points]
    path.append(path[0])
    with open(f"{out}/{name}", "w") as f:
        # (The first element is the sheet: none here.)
        json.dump([{"partid": "no sheet", "paths": []}, {"partid": name, "paths": [path]}], f)
for n in (20000, 200000):
    contour_file(f"circle-{n}.dbs.json",
                 [(500 + 400 * math.cos(2 * math.pi * k / n), 500 + 400 * math.sin(2 * math.pi * k / n)) for k in range(n)])
# A 40,000-vertex square: 10,000 collinear vertices per side.
side = 10000
square = [(k * 0.1, 0.0) for k in range(side)] + [(1000.0, k * 0.1) for k in range(side)]
square += [(1000.0 - k * 0.1, 1000.0) for k in range(side)] + [(0.0, 1000.0 - k * 0.1) for k in range(side)]
contour_file("square-40000.dbs.json", square)
try:
    import ezdxf
except ImportError:
    sys.exit(0)
doc = ezdxf.new("R2010")
# In mm (ezdxf's default drawing unit is the metre: every curve would be 1000 times larger).
doc.units = ezdxf.units.MM
msp = doc.modelspace()
# 24 control points a spline: a drawing of about 2 MB.
SPLINE_POINTS = 24
for i in range(1200):
    cx, cy = (i % 40) * 60.0, (i // 40) * 60.0
    points = [(cx + 20 * math.cos(2 * math.pi * k / SPLINE_POINTS) * (1 + 0.2 * math.sin(3 * 2 * math.pi * k / SPLINE_POINTS)),
               cy + 20 * math.sin(2 * math.pi * k / SPLINE_POINTS)) for k in range(SPLINE_POINTS)]
    # ezdxf 1.4 has no add_closed_spline: control points interpolating the fit points, the
    # first repeated at the end, close the curve.
    msp.add_spline_control_frame(points + [points[0]])
doc.saveas(f"{out}/splines-1200.dxf")
PY
BIG=("$TMP/circle-20000.dbs.json" "$TMP/circle-200000.dbs.json" "$TMP/square-40000.dbs.json" "$TMP/generated-60000.json")
if [ -f "$TMP/splines-1200.dxf" ]; then BIG+=("$TMP/splines-1200.dxf"); fi
# 224 bytes that expand to 160,000 circles (a MINSERT array of 400 × 400).
BIG+=(data/hostile/hang_dxf_minsert_400x400.dxf)
NESTS=(data/nests/dbs/nested.dbs data/nests/dbs/seven.dbs data/nests/tflex/Nest02.tfnesting "$TMP/generated-$CONTOURS.json" "${BIG[@]}")
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
