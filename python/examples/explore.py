#!/usr/bin/env python3
"""Explore a built-in map with two robots and look at the run: metrics, coverage, trajectories.

    PYTHONPATH=build/python python3 python/examples/explore.py [scenario.yaml] [--out folder]
"""
import argparse

import fleetmap

parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
parser.add_argument("scenario", nargs="?", help="a scenario YAML file (default: office, 2 robots, 300 steps)")
parser.add_argument("--out", help="also write the run's files (merged.png, metrics.json, map.yaml, ...) here")
args = parser.parse_args()

if args.scenario:
    run = fleetmap.explore(args.scenario)
else:
    run = fleetmap.explore(map="office", robots=2, steps=300, seed=1, strategy="coordinated")

m = run.metrics
print(f"{m['map']}: {m['robots']} robots, strategy {m['strategy']}, {run.steps} steps, "
      f"coverage {m['coverage']:.1%}, steps to 95% {m['steps_to_95']}, distance {m['distance_m']:.1f} m")
for k in range(0, run.steps + 1, max(1, run.steps // 6)):
    print(f"  step {k:4d}: coverage {run.coverage[k]:.1%}")
for i, poses in enumerate(run.trajectories):
    x, y, theta = poses[-1]
    print(f"  robot {i + 1}: {len(poses)} poses, ends at ({x:.2f}, {y:.2f}) m")
if args.out:
    print("wrote", ", ".join(run.save(args.out)))
