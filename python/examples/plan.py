#!/usr/bin/env python3
"""Plan a path across a map with each planner and compare their lengths.

    PYTHONPATH=build/python python3 python/examples/plan.py [map] [x0 y0 x1 y1]
"""
import sys

import fleetmap

name = sys.argv[1] if len(sys.argv) > 1 else "office"
start, goal = ((1.0, 1.0), (8.5, 8.5)) if len(sys.argv) < 6 else \
    ((float(sys.argv[2]), float(sys.argv[3])), (float(sys.argv[4]), float(sys.argv[5])))
m = fleetmap.load_map(name)
for planner in fleetmap.planner_names():
    result = fleetmap.plan_path(m, start, goal, planner=planner, robot_radius=0.2, time_budget=1.0)
    if result.success:
        print(f"{planner:16s} {result.length_m:6.2f} m through {len(result.path)} waypoints")
    else:
        print(f"{planner:16s} {result.status}: {result.detail}")
