#!/usr/bin/env python3
"""A coordination strategy written in Python, benchmarked against a built-in one.

Each robot, nearest first, takes the target that reveals the most unknown area per metre of
travel among those no teammate took, counting a turn away from its heading as extra travel
(a greedy variant of Burgard et al. 2005's assignment, with the area behind each target as its
utility).

    PYTHONPATH=build/python python3 python/examples/python_strategy.py
"""
import math
import statistics

import numpy as np

import fleetmap

TURN_COST_M = 0.5  # a half turn costs as much as driving this far


class GreedyAreaAhead:
    def assign(self, poses, targets, costs, claimed, context):
        # poses (R, 3): x, y (m), heading (rad); targets (T, 4): goal x, goal y, frontier cells,
        # region; costs (R, T) wave metres (inf: unreachable); claimed (K, 2): goals teammates
        # drive to; context: team indices, sensor range, options, target_costs(), target_gains().
        out, taken = [-1] * len(poses), set()
        if len(targets) == 0:
            return out
        area = context.target_gains()  # (T,) m^2 never observed behind each target
        bearing = np.arctan2(targets[:, 1] - poses[:, 1:2], targets[:, 0] - poses[:, 0:1])  # R x T
        turn = np.abs(np.angle(np.exp(1j * (bearing - poses[:, 2:3])))) / math.pi  # 0 ahead .. 1 behind
        value = area / (1.0 + costs + TURN_COST_M * turn)  # R x T, 0 where unreachable
        for r in np.argsort(np.min(costs, axis=1)):  # the robot nearest to a target chooses first
            for t in np.argsort(-value[r]):
                if t not in taken and math.isfinite(costs[r, t]):
                    out[r] = int(t)
                    taken.add(t)
                    break
        return out


fleetmap.register_strategy("greedy-area-ahead", GreedyAreaAhead,
                           help="most unknown area per metre, turns counted (Python)")
rows = fleetmap.sweep(maps=["office"], strategies=["greedy-area-ahead", "coordinated"], robots=3, seeds=3,
                      steps=400, jobs=2)
for strategy in ("greedy-area-ahead", "coordinated"):
    runs = [r for r in rows if r["strategy"] == strategy]
    print(f"{strategy:18s} coverage {statistics.mean(r['coverage'] for r in runs):.1%}, "
          f"distance {statistics.mean(r['distance_m'] for r in runs):.0f} m over {len(runs)} runs")
