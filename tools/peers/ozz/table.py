#!/usr/bin/env python3
"""The table of run.sh's results: one row per (row name, animation).

Bytes and errors come from the runs (checked identical across runs).
Timings, ns per pose (SamplingJob of the whole pose, forward at 60 fps; then
the same plus a LocalToModelJob):
  wall = median over runs of each run's median round (wall clock), with the
         range of the per-run medians
  best = fastest round over all runs (wall clock)
  cpu  = median over runs of each run's median round in thread CPU time
"""
import glob
import json
import os
import re
import statistics
import sys

res = sys.argv[1]
runs = {}
for path in sorted(glob.glob(os.path.join(res, "*.run*.json"))):
    m = re.match(r"(.+)\.run(\d+)\.json$", os.path.basename(path))
    if m:
        with open(path) as f:
            runs.setdefault(m.group(1), []).append(json.load(f))

print("| ozz animation | joints | bytes (`Animation::size()`) | max error, 3 cm shell | "
      "ns per pose, `SamplingJob`: wall (range; best; cpu) | + `LocalToModelJob` | runs |")
print("|---|---:|---:|---|---|---|---:|")
for name in sorted(runs):
    rs = runs[name]
    a = rs[0]
    # The _acl rows build the same every-key animation as their plain row.
    for kind in ("optimized",) if name.endswith("_acl") else ("built", "optimized"):
        x = a["animations"][kind]
        for k in ("bytes", "max_error_cm"):
            vals = {r["animations"][kind][k] for r in rs}
            if len(vals) != 1:
                print(f"<!-- {name} {kind}: {k} differs across runs: {sorted(vals)} -->")

        def col(key):
            med = [r["animations"][kind][f"{key}_ns"] for r in rs]
            best = min(r["animations"][kind][f"{key}_ns_min"] for r in rs)
            cpu = statistics.median(r["animations"][kind][f"{key}_cpu_ns"] for r in rs)
            return f"{statistics.median(med):.0f} ({min(med):.0f}-{max(med):.0f}; {best:.0f}; {cpu:.0f})"

        label = "`AnimationBuilder`" if kind == "built" else (
            f"`AnimationOptimizer` at {a['tolerance_cm']:g} cm, {a['distance_cm']:g} cm "
            f"({a['tolerance_units']:.4g}, {a['distance_units']:.4g} units) + builder")
        print(f"| {label} | {a['joints']} | {x['bytes']:,} | {x['max_error_cm']:.4f} cm "
              f"({x['max_error_units']:.3e} units, {x['max_error_joint']}) | {col('sample')} | "
              f"{col('l2m')} | {len(rs)} |")
