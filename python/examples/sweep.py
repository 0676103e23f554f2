#!/usr/bin/env python3
"""A small benchmark sweep: two strategies, two team sizes, three seeds; mean coverage per series.
Its folder (out/python_sweep) is the one `fleetmap bench` writes: then
`fleetmap bench --compare coordinated uncoordinated out/python_sweep`.

    PYTHONPATH=build/python python3 python/examples/sweep.py [sweep.yaml]
"""
import statistics
import sys
from collections import defaultdict

import fleetmap

if len(sys.argv) > 1:
    rows = fleetmap.sweep(sys.argv[1], jobs=2, out="out/python_sweep")
else:
    rows = fleetmap.sweep(maps=["office"], strategies=["coordinated", "uncoordinated"], robots="2,4",
                          seeds=3, steps=300, jobs=2, out="out/python_sweep")
series = defaultdict(list)
for row in rows:
    series[(row["map"], row["strategy"], row["robots"])].append(row)
for (map_name, strategy, robots), runs in sorted(series.items()):
    coverage = statistics.mean(r["coverage"] for r in runs)
    steps = [r["steps_to_95"] for r in runs if r["steps_to_95"] is not None]
    print(f"{map_name:10s} {strategy:14s} {robots} robots: coverage {coverage:.1%}, "
          f"steps to 95% {f'{statistics.mean(steps):.0f}' if steps else '-'} over {len(runs)} runs")
