#!/usr/bin/env bash
# Per-solver thermal support (README "Heat and the shop rules"): for each solver on two real
# nests, H and machine time with weight 0 and 100 (σ 50 mm, τ 60 s), the violations of every
# rule, and with --rules-hard (weight 100) H and what is left. Needs the release CLI:
# cargo build --release -p cutroute-cli. Prints a Markdown table (BENCHMARKS.md).
cd "$(dirname "$0")/.."
B=target/release/cutroute
echo "| nest | solver | H plain | H W=100 | time s plain → W=100 | violations plain p/s/i | hard (W=100): H | hard: left p/s/i | hard: time s |"
echo "|---|---|---|---|---|---|---|---|---|"
for f in data/nests/dbs-json/test0.dbs.json data/nests/tflex/Nest01.tfnesting; do
  for s in nearest ccp heuristic exact chain sccp gsccp aoe; do
    run() { $B solve $f --solver $s --time-limit 2 --seed 1 --json "$@" 2>/dev/null; }
    a=$(run --rules part,sheet,islands); b=$(run --thermal-weight 100 --rules part,sheet,islands); c=$(run --thermal-weight 100 --rules-hard)
    python3 - "$f" "$s" "$a" "$b" "$c" <<'PY'
import json, sys
f, s, *rs = sys.argv[1:]
def load(t):
    try: return json.loads(t)
    except Exception: return None
a, b, c = map(load, rs)
def v(r):
    if r is None: return "failed"
    rv = r.get("rule_violations")
    if rv is None: return "—"
    return "/".join(str(rv[k]) for k in ("part", "sheet", "islands"))
def h(r): return "failed" if r is None else f"{r['heat']:.4f}"
def t(r): return "failed" if r is None else f"{r['time_s']:.0f}"
name = f.split("/")[-1]
print(f"| {name} | {s} | {h(a)} | {h(b)} | {t(a)} → {t(b)} | {v(a)} | {h(c)} | {v(c)} | {t(c)} |")
PY
  done
done
