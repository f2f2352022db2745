#!/usr/bin/env python3
"""Exact-with-leads, edge-pierce and kerf-pierce numbers for BENCHMARKS.md (run from the worktree
root): `scripts/kerf-full-route-bench.py BIN exact|edge|kerf`."""
import json, subprocess, sys, time
BIN = sys.argv[1]
LEADS = ["--kerf", "2", "--pierce-clearance", "5", "--switch-off-clearance", "1", "--lead-in", "arc",
         "--lead-in-length", "8", "--lead-out", "line", "--lead-out-length", "2"]
def run(args):
    t = time.time()
    p = subprocess.run([BIN, "solve", *args, "--json"], capture_output=True, text=True)
    wall = time.time() - t
    if p.returncode != 0:
        return None, wall, p.stderr.strip().splitlines()[-1][:120]
    return json.loads(p.stdout), wall, None
mode = sys.argv[2]
if mode == "exact":
    print("| nest | contours | exact idle | exact lb | gap % | proven | exact wall s | heuristic idle | heuristic wall s |")
    print("|---|---:|---:|---:|---:|:-:|---:|---:|---:|")
    for f, n in [("data/nests/tflex/Nest01.tfnesting", 6), ("data/nests/dbs-json/E1X_6_01.dbs.json", 17),
                 ("data/nests/dbs-json/test0.dbs.json", 21), ("data/nests/dbs-json/test1.dbs.json", 26)]:
        e, we, err = run([f, "--solver", "exact", "--time-limit", "10", *LEADS])
        h, wh, err2 = run([f, "--solver", "heuristic", "--time-limit", "10", *LEADS])
        name = f.split("/")[-1]
        if e is None:
            print(f"| {name} | {n} | error: {err} |"); continue
        lb = e.get("lb"); idle = e["idle_length"]
        gap = "" if lb is None else f"{100*(idle-lb)/idle:.1f}"
        print(f"| {name} | {n} | {idle:.1f} | {'' if lb is None else f'{lb:.1f}'} | {gap} | {'yes' if e['proven_optimal'] else 'no'} | {we:.2f} | " +
              (h and "%.1f" % h["idle_length"] or "") + f" | {wh:.2f} |")
elif mode == "kerf":
    # The same solver run with and without --kerf-pierce (nearest is deterministic; ccp runs
    # 5 s each time), pierces 7 s in the sheet and 2 s in a kerf.
    print("| nest | solver | kerf pierces / pierces | idle off | idle on | time_s off | time_s on | saved s | saved % |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|")
    for f in ["data/nests/dbs-json/E1X_6_01.dbs.json", "data/nests/dbs-json/test0.dbs.json",
              "data/nests/dbs-json/test1.dbs.json", "data/nests/dbs/seven.dbs", "data/nests/dbs/nested.dbs",
              "data/nests/dxf/planka.dxf", "data/nests/tflex/Nest02.tfnesting", "data/nests/tflex/Nest03.tfnesting"]:
        name = f.split("/")[-1]
        for solver in ["nearest", "ccp"]:
            base = [f, "--solver", solver, "--time-limit", "5", *LEADS, "--edge-pierce-time", "2"]
            off, _, err = run(base)
            on, _, err_on = run([*base, "--kerf-pierce"])
            if off is None or on is None:
                print(f"| {name} | {solver} | refused: {err or err_on} |||||||"); continue
            if on.get("final_route_rejected") is not None:
                print(f"| {name} | {solver} | route rejected: {on['final_route_rejected']} |||||||"); continue
            k, p = on.get("kerf_pierces", 0), on["pierces"]
            saved = off["time_s"] - on["time_s"]
            print(f"| {name} | {solver} | {k} / {p} | {off['idle_length']:.0f} | {on['idle_length']:.0f} | "
                  f"{off['time_s']:.0f} | {on['time_s']:.0f} | {saved:.0f} | {100*saved/off['time_s']:.1f} |")
else:
    print("| nest | solver | edge pierces / pierces | pierce time s (7 s each) | pierce time s (edge 2 s) | idle off | idle on | time_s off | time_s on | no room off | no room on |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---|---|")
    for f in ["data/nests/dbs-json/E1X_6_01.dbs.json", "data/nests/dbs-json/test1.dbs.json",
              "data/nests/dbs/seven.dbs", "data/nests/tflex/Nest02.tfnesting", "data/nests/tflex/Nest03.tfnesting"]:
        name = f.split("/")[-1]
        off, _, err_off = run([f, "--solver", "ccp", "--time-limit", "5", *LEADS])
        on, _, err_on = run([f, "--solver", "ccp", "--time-limit", "5", *LEADS, "--edge-pierce", "--edge-pierce-time", "2"])
        if on is None:
            print(f"| {name} | ccp | | | | | | | | {err_off or ''} | {err_on} |"); continue
        p, e = on["pierces"], on.get("edge_pierces", 0)
        print(f"| {name} | ccp | {e} / {p} | {7*p:.0f} | {7*(p-e)+2*e:.0f} | " +
              (off and "%.0f" % off["idle_length"] or "") + f" | {on['idle_length']:.0f} | " +
              (off and "%.0f" % off["time_s"] or "") + f" | {on['time_s']:.0f} | {'yes' if off is None else 'no'} | no |")
