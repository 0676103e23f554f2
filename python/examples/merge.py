#!/usr/bin/env python3
"""Merge two maps: two overlapping parts of the office map, one turned a quarter, aligned again.

    PYTHONPATH=build/python python3 python/examples/merge.py [map_a map_b]
"""
import math
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
print(f"b's cells into a's: translation ({tx:.1f}, {ty:.1f}) cells, rotation {math.degrees(theta):.1f} deg")
if not result.merged:
    print("why not:", result.reason)
