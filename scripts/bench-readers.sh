#!/usr/bin/env bash
# Read times of the largest real-world DXF and SVG files and of a generated 2.4 MB sheet of
# 1,200 closed splines: cutroute's readers (release build, fastest of 5 runs, wall and CPU time)
# beside ezdxf's `ezdxf.readfile` on the same DXF files in the same run (fastest of 3, wall and
# process CPU time; skipped with a note when ezdxf is not installed: `pip install ezdxf`).
# Prints a Markdown table for BENCHMARKS.md.
#
#   scripts/bench-readers.sh [FILE ...]   # default: the files below
set -u
cd "$(dirname "$0")/.."
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT
GENERATED="$TMP/generated-1200-closed-splines.dxf"
if (($#)); then
  files=("$@")
else
  files=(
    data/realworld/files/netdxf__sample.dxf
    data/realworld/files/ezdxf__uncommon.dxf
    data/realworld/files/bjnortier-dxf__issue28.dxf
    data/realworld/files/netdxf__sample_binary.dxf
    data/hostile/hang_dxf_minsert_400x400.dxf
    data/realworld/files/boxes__Matrix.svg
    data/realworld/files/boxes__GearBox.svg
  )
fi
# cargo runs benches in the package's folder: give it absolute paths.
absolute=()
for f in "${files[@]}"; do absolute+=("$(realpath "$f")"); done
cargo bench -q -p cutroute-cad --bench read_speed -- --generate "$GENERATED" "${absolute[@]}" \
  >"$TMP/ours.tsv" || exit 1

have_ezdxf=1
python3 -c "import ezdxf" 2>/dev/null || have_ezdxf=0
peer() { # prints ezdxf's fastest readfile time in ms, or a note
  if [[ "$1" == *.svg || "$1" == *.SVG ]]; then echo "— (not DXF)"; return; fi
  if ((!have_ezdxf)); then echo "— (ezdxf not installed)"; return; fi
  python3 - "$1" <<'PY'
import sys, time, ezdxf
best = cpu = float("inf")
for _ in range(3):
    t, c = time.perf_counter(), time.process_time()
    try:
        ezdxf.readfile(sys.argv[1])
        note = ""
    except Exception as e:  # a file ezdxf refuses: say so beside the time
        note = f" ({type(e).__name__})"
    best = min(best, time.perf_counter() - t)
    cpu = min(cpu, time.process_time() - c)
print(f"{best * 1000:.1f} / {cpu * 1000:.1f}{note}")
PY
}

echo "| file | bytes | cutroute read, wall / CPU (ms) | ezdxf readfile, wall / CPU (ms) | cutroute gives |"
echo "|---|---|---|---|---|"
while IFS=$'\t' read -r file bytes ms cpu outcome; do
  name=$(basename "$file")
  echo "| $name | $bytes | $ms / $cpu | $(peer "$file") | ${outcome:0:80} |"
done <"$TMP/ours.tsv"
