#!/usr/bin/env bash
# Runs every cargo-fuzz target of the repository for SECONDS each (default 600) and prints a
# table: target, runs, wall seconds, result. Needs nightly Rust and cargo-fuzz.
#
#   scripts/fuzz-all.sh [SECONDS] [TARGET ...]
#
# Corpora stay in each project's `fuzz/corpus/`, findings in `fuzz/artifacts/`. One target dir
# is shared by the fuzz projects (they share most dependencies): $FUZZ_TARGET_DIR or
# target/fuzz.
set -uo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
shift || true
wanted=("$@")
export CARGO_TARGET_DIR="${FUZZ_TARGET_DIR:-$PWD/target/fuzz}"
log_dir="$CARGO_TARGET_DIR/logs"
mkdir -p "$log_dir"

rows=()
failed=0
for project in crates/*/fuzz; do
  for source in "$project"/fuzz_targets/*.rs; do
    target="$(basename "$source" .rs)"
    if ((${#wanted[@]})) && [[ " ${wanted[*]} " != *" $target "* ]]; then
      continue
    fi
    log="$log_dir/$target.log"
    corpus="$project/corpus/$target"
    mkdir -p "$corpus"
    # Seeds: the real files of the format, when the corpus is new.
    if [[ -z "$(ls -A "$corpus")" ]]; then
      case "$target" in
        dxf_reader) seeds=(data/nests/dxf/*.dxf data/realworld/files/*.dxf) ;;
        svg_reader) seeds=(data/nests/svg/*.svg data/realworld/files/*.svg) ;;
        gcode_reader) seeds=(data/gcode-samples/*) ;;
        tflex_reader) seeds=(data/nests/tflex/*.tfnesting) ;;
        dbs_reader) seeds=(data/nests/dbs/*.dbs data/nests/dbs/*.DBS) ;;
        json_readers) seeds=(data/nests/dbs-json/*.json data/nests/task-json/*.json data/nests/result-json/*.json) ;;
        pcglns_reader) seeds=(data/nests/pcgtsp/*) ;;
        *) seeds=() ;;
      esac
      for seed in "${seeds[@]}"; do
        [[ -f "$seed" && $(stat -c %s "$seed") -le 16384 ]] && cp "$seed" "$corpus/"
      done
    fi
    dict=()
    prefix="${target%%_*}"
    [[ -f "$project/$prefix.dict" ]] && dict=(-dict="fuzz/$prefix.dict")
    echo "[fuzz] $project $target for ${seconds}s (log: $log)" >&2
    start=$(date +%s)
    # -timeout: one input may take this long (sanitizer builds are slow on big expansions).
    (cd "$project/.." && cargo +nightly fuzz run "$target" "fuzz/corpus/$target" -- "${dict[@]}" \
      -max_total_time="$seconds" -timeout=60 -rss_limit_mb=4096 -max_len=16384 \
      -print_final_stats=1) \
      >"$log" 2>&1
    status=$?
    wall=$(($(date +%s) - start))
    runs=$(grep -o 'Done [0-9]* runs' "$log" | tail -1 | grep -o '[0-9]*')
    if [[ $status -eq 0 ]]; then
      result="clean"
    else
      result="FAILED (exit $status; see $log)"
      failed=1
    fi
    rows+=("| $project | $target | ${runs:-?} | $wall | $result |")
  done
done

echo "| project | target | runs | wall s | result |"
echo "|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"
exit $failed
