#!/usr/bin/env python3
"""Merge two maps (two overlapping parts of the office map, one turned a quarter), then plan a
path on the fused map from a room only a knew to one only b knew.

    PYTHONPATH=build/python python3 python/examples/merge.py [map_a map_b]
"""
import sys

import numpy as np

import fleetmap

if len(sys.argv) == 3:
    a, b = fleetmap.load_map(sys.argv[1]), fleetmap.load_map(sys.argv[2])
else:
    office = fleetmap.load_map("office").image
    a = fleetmap.Map.from_image(office[:, :130].copy())
    b = fleetmap.Map.from_image(np.rot90(office[:, 70:]).copy())  # b turned by 90 degrees

result = fleetmap.merge_maps(a, b)
tx, ty, theta = result.transform
print(f"merged: {result.merged} (method {result.method}, confidence {result.confidence:.2f})")
print(f"b's frame into a's (as `fleetmap merge` prints it): tx {tx:.3f} ty {ty:.3f} m, theta {theta:.3f} deg")
if not result.merged:
    sys.exit(f"why not: {result.reason}")
if len(sys.argv) != 3:
    path = fleetmap.plan_path(result.map, (1.0, 5.0), (9.0, 5.0))  # a's room on the left to b's on the right
    print(f"path on the fused map ({result.map.width} x {result.map.height} cells): {path.status}, {path.length_m:.2f} m")
