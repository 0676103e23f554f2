#!/usr/bin/env python3
"""Maps as numpy arrays: load a built-in map, draw into it, save it as a map_server map, load it back.

    PYTHONPATH=build/python python3 python/examples/maps.py [out_folder]
"""
import sys
from pathlib import Path

import numpy as np

import fleetmap

out = Path(sys.argv[1] if len(sys.argv) > 1 else "out/python_maps")
out.mkdir(parents=True, exist_ok=True)

office = fleetmap.load_map("office")
image = office.image  # uint8 (rows, columns), top row first: 0 occupied, 254 free, 205 unknown
print(office, "values", dict(zip(*np.unique(image, return_counts=True))))

blocked = image.copy()
rows, cols = blocked.shape
blocked[rows // 2 - 2: rows // 2 + 2, :] = 0  # a wall across the middle
edited = fleetmap.Map.from_image(blocked, resolution=office.resolution, origin=office.origin)
fleetmap.save_map(edited, out / "office_split.yaml")  # writes office_split.yaml + office_split.pgm
again = fleetmap.load_map(str(out / "office_split.yaml"))
assert np.array_equal(again.image, blocked)
print(f"saved {out / 'office_split.yaml'}: {again.occupied_cells - office.occupied_cells} more occupied cells")
