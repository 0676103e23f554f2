#!/usr/bin/env python3
"""A coordination strategy written in Python, benchmarked against a built-in one.

Each robot takes the target with the lowest wave cost among those no teammate took, preferring
large frontier pieces (cells / cost): a greedy variant of Burgard et al. 2005's assignment.

    PYTHONPATH=build/python python3 python/examples/python_strategy.py
"""
import math
import statistics

import numpy as np

import fleetmap


class GreedyLargestFrontier:
    def assign(self, positions, targets, costs, claimed):
        # positions (R, 2) m; targets (T, 4): goal x, goal y, frontier cells, region;
        # costs (R, T) wave metres (inf: unreachable); claimed (K, 2): goals teammates drive to.
        out, taken = [-1] * len(positions), set()
        if len(targets) == 0:
            return out
        gain = targets[:, 2] / (1.0 + costs)  # R x T, 0 where unreachable
        for r in np.argsort(np.min(costs, axis=1)):  # the robot nearest to a target chooses first
            for t in np.argsort(-gain[r]):
                if t not in taken and math.isfinite(costs[r, t]):
                    out[r] = int(t)
                    taken.add(t)
                    break
        return out


fleetmap.register_strategy("greedy-largest", GreedyLargestFrontier, help="largest frontier per metre (Python)")
rows = fleetmap.sweep(maps=["office"], strategies=["greedy-largest", "coordinated"], robots=3, seeds=3,
                      steps=400, jobs=2)
for strategy in ("greedy-largest", "coordinated"):
    runs = [r for r in rows if r["strategy"] == strategy]
    print(f"{strategy:15s} coverage {statistics.mean(r['coverage'] for r in runs):.1%}, "
          f"distance {statistics.mean(r['distance_m'] for r in runs):.0f} m over {len(runs)} runs")
