#!/usr/bin/python3
"""Prepare the 17 real laser SLAM maps of fleetmap's real-map merging benchmark.

Reads the images extracted from their public repositories (src/NAME.pgm or src/NAME.png, see
SOURCES below; src/NAME.repo.yaml is the repository's own YAML where it had one) and writes
NAME.pgm (8-bit binary P5, values 0 occupied / 205 unknown / 254 free) and NAME.yaml
(map_server format) beside this script.

Every map goes through map_server's own trinary rule (p = (255 - grey) / 255; occupied if
p > occupied_thresh, free if p < free_thresh, unknown otherwise; RGB(A) images read as the mean of
their colour channels), so a map loaded through the written YAML (thresholds 0.65 / 0.196) reads
exactly as the source image read through its thresholds; only the edits below change cells.

SOURCES also lists 5 held-out maps of other buildings (HELD_OUT: bham_cs_lgfloor,
upo_centre_sportif, ipa_office, aist_conveni, sapienza_diag), kept apart for a held-out check of
the merging; they are prepared only when asked for with --only.

Needs numpy, Pillow and scipy (Debian: python3-numpy python3-pil python3-scipy).
Usage: /usr/bin/python3 prepare.py --src DIR --out DIR [--only NAME,...|held-out|all]
  --only restricts the maps prepared, and the source files required in --src, to the names given
  (comma-separated); 'held-out' means the 5 held-out maps, 'all' all 22. Without it the 17
  benchmark maps are prepared, as before.
"""
import argparse
import os
import sys

import numpy as np
from PIL import Image
from scipy import ndimage as ndi

OCC, UNKNOWN, FREE = 0, 205, 254
STD_THRESH = (0.65, 0.196)  # (occupied_thresh, free_thresh) written to every YAML

# name: (source file in src/, repository : path, resolution in m, (occupied, free) thresholds
#        used to read the source image)
SOURCES = {
    "willow": ("willow.pgm", "ros-planning/navigation_tutorials : navigation_stage/stage_config/maps/willow-full-0.05.pgm", 0.05, STD_THRESH),
    # The repository's YAML says 0.0504 m (and origin [25.9, 48.5, 3.14], not kept).
    "stata_basement": ("stata_basement.png", "f1tenth/f1tenth_simulator : maps/stata_basement.png", 0.0504, STD_THRESH),
    "utexas_gdc_1": ("utexas_gdc_1.pgm", "utexas-bwi/bwi_common : utexas_gdc/maps/real/1/1-original.pgm", 0.05, STD_THRESH),
    "utexas_gdc_2": ("utexas_gdc_2.pgm", "utexas-bwi/bwi_common : utexas_gdc/maps/real/2/2_original.pgm", 0.05, STD_THRESH),
    "utexas_gdc_3ne": ("utexas_gdc_3ne.pgm", "utexas-bwi/bwi_common : bwi_virtour/web/image/3ne.pgm", 0.05, STD_THRESH),
    # intel.yaml: resolution 0.1, occupied_thresh 0.2, free_thresh 0.05 (its own grey levels).
    "intel_lab": ("intel_lab.pgm", "utexas-bwi/bwi_common : bwi_mapper/maps/intel.pgm", 0.1, (0.2, 0.05)),
    "uos_avz5": ("uos_avz5.pgm", "uos/uos_tools : uos_maps/maps/avz5floor_open.pgm", 0.05, STD_THRESH),
    # First version of cic.png (commit 6cf1b2abebdbda65738c76c49748f6d15cd1ba28 "added cic"), RGBA.
    "uos_cic": ("uos_cic.png", "uos/uos_tools : uos_maps/maps/cic.png @6cf1b2ab", 0.05, STD_THRESH),
    # rilo.yaml says free_thresh 0.25, under which its unknown grey 205 would read as free (the
    # whole unknown surround as floor); the image is a map_server-saved 0/205/254 map, so it is
    # read with the standard 0.196 and 205 stays unknown.
    "uos_rilo": ("uos_rilo.pgm", "uos/uos_tools : uos_maps/maps/rilo.pgm", 0.05, STD_THRESH),
    "jsk_eng6_1f": ("jsk_eng6_1f.pgm", "jsk-ros-pkg/jsk_demos : jsk_maps/raw_maps/eng6-1f-0.05.pgm", 0.05, STD_THRESH),
    "strands_tsc": ("strands_tsc.pgm", "strands-project/strands_morse : tsc/maps/tsc.pgm", 0.05, STD_THRESH),
    "strands_collection": ("strands_collection.pgm", "strands-project/strands_morse : collection/maps/collection1-cropped.pgm", 0.05, STD_THRESH),
    "strands_g4s_y2": ("strands_g4s_y2.pgm", "strands-project/strands_morse : g4s/maps/g4s_y2.pgm", 0.05, STD_THRESH),
    "upo_45": ("upo_45.pgm", "robotics-upo/upo_robot_navigation : upo_launchers/upo_45/maps/upo_45.pgm", 0.05, STD_THRESH),
    "upo_uva_demo": ("upo_uva_demo.pgm", "robotics-upo/upo_robot_navigation : upo_launchers/uva_demo/maps/uva_demo.pgm", 0.05, STD_THRESH),
    "upo_elderly_center": ("upo_elderly_center.pgm", "robotics-upo/upo_robot_navigation : upo_launchers/elderly_center/maps/elderly_center.pgm", 0.05, STD_THRESH),
    "upo_uva_lab": ("upo_uva_lab.pgm", "robotics-upo/upo_robot_navigation : upo_launchers/uva_lab/maps/uva_lab.pgm", 0.05, STD_THRESH),
    # --- held-out maps (not used while developing the merging; prepare them with --only) ---
    # Birmingham School of Computer Science, lower ground floor: map_saver output (0/205/254) of a
    # real Pioneer's gmapping run (ray fans through doors, speckled walls, map at a slant).
    "bham_cs_lgfloor": ("bham_cs_lgfloor.pgm", "IRUOB/socspioneer : data/lgfloor.pgm", 0.05, STD_THRESH),
    # TERESA "centre sportif" (a sports centre, not the UPO buildings above): real gmapping map with
    # long ray fans and clutter; black squares painted in the four corners like uva_demo.
    "upo_centre_sportif": ("upo_centre_sportif.pgm", "robotics-upo/upo_robot_navigation : upo_launchers/centre_sportif/maps/centre_sportif.pgm", 0.05, STD_THRESH),
    # Fraunhofer IPA office building, Stuttgart (Care-O-bot env): first version of ipa-office/map.pgm
    # (commit 226aae7fa0fe8f5973e686b963fc0c1a3243163b "added ipa-office"), a 0/205/254 map_saver
    # image of a real robot's run: ray fans from every door, speckle in the rooms.
    "ipa_office": ("ipa_office.pgm", "ipa320/cob_environments : cob_default_env_config/ipa-office/map.pgm @226aae7f", 0.05, STD_THRESH),
    # AIST mock convenience store (JSK aero robot, rooms/aist/raw_maps/map.pgm at commit
    # ba93ca5d634495e591d0f8fca2e1cec3ea847cbb, its YAML names it aist_conveni.pgm, 0.025 m):
    # 0/205/254 map of a real laser run with ray fans, shelf rows with ragged outlines.
    "aist_conveni": ("aist_conveni.pgm", "jsk-ros-pkg/jsk_robot : jsk_aero_robot/jsk_aero_startup/rooms/aist/raw_maps/map.pgm @ba93ca5d", 0.025, STD_THRESH),
    # DIAG, Sapienza University of Rome, B1 floor corridors (SPQReL Pepper team, 0.025 m): real
    # laser map with ray fans into rooms and broken walls; 0/205/254 plus 55 stray anti-aliasing
    # greys (207-253) that the trinary rule reads as free.
    "sapienza_diag": ("sapienza_diag.png", "LCAS/spqrel_navigation : maps/diag.png", 0.025, STD_THRESH),
}
HELD_OUT = ("bham_cs_lgfloor", "upo_centre_sportif", "ipa_office", "aist_conveni", "sapienza_diag")


def load_grey(path):
    """The image as float greys the way map_server reads it: mean of the colour channels."""
    im = Image.open(path)
    a = np.asarray(im)
    if a.ndim == 2:
        return a.astype(np.float64)
    colour = a[..., :3] if a.shape[2] >= 3 else a[..., :1]  # drop alpha (trinary mode ignores it)
    return colour.astype(np.float64).mean(axis=2)


def trinary(grey, occupied_thresh, free_thresh):
    """map_server's trinary rule -> 0 / 205 / 254."""
    p = (255.0 - grey) / 255.0
    out = np.full(grey.shape, UNKNOWN, np.uint8)
    out[p > occupied_thresh] = OCC
    out[p < free_thresh] = FREE
    return out


def border_components(mask):
    """Labels of the 4-connected components of mask touching the image border, and the labelling."""
    lab, _ = ndi.label(mask)
    b = np.unique(np.concatenate([lab[0], lab[-1], lab[:, 0], lab[:, -1]]))
    return lab, b[b > 0]


def rotation_wedge(comp, margin=2.0):
    """The straight-edged corner triangle that one border component of white is part of.

    A map turned by a few degrees inside a larger canvas leaves a white triangle in each corner;
    where the map's ray fans end at the old image edge, the triangle's white also runs a few cells
    into the fans' own white edges. Per line across the triangle's main border, the run of the
    component from the border is its depth; a line fitted to those depths (outliers dropped) gives
    the triangle's inner edge, and the triangle plus `margin` cells past that edge (the grey
    anti-aliasing fringe that the rotation's interpolation left, 206-254, i.e. read as free) is
    returned as a mask.
    """
    h, w = comp.shape
    # Main border: the side holding most of the component's cells.
    sides = {"top": comp[0].sum(), "bottom": comp[-1].sum(), "left": comp[:, 0].sum(), "right": comp[:, -1].sum()}
    side = max(sides, key=sides.get)
    # View with the main border as row 0.
    view = {"top": lambda m: m, "bottom": lambda m: m[::-1], "left": lambda m: m.T, "right": lambda m: m[:, ::-1].T}[side]
    v = view(comp)
    depth = np.where(v.all(axis=0), v.shape[0], np.argmin(v, axis=0)).astype(np.float64)
    j = np.nonzero(depth > 0)[0]
    d = depth[j]
    keep = np.ones(len(j), bool)
    for _ in range(5):  # least squares with outlier rejection (fan leaks are deeper than the edge)
        b, a = np.polyfit(j[keep], d[keep], 1)
        res = d - (a + b * j)
        new_keep = np.abs(res) <= 3.0
        if (new_keep == keep).all():
            break
        keep = new_keep
    cols = np.arange(v.shape[1])
    edge = a + b * cols + margin
    rows = np.arange(v.shape[0])[:, None]
    wedge_v = rows < edge[None, :]
    # Undo the view (each view is its own inverse up to the transposes).
    if side == "top":
        return wedge_v
    if side == "bottom":
        return wedge_v[::-1]
    if side == "left":
        return wedge_v.T
    return wedge_v.T[:, ::-1]


# --- edits, on the source greys before the trinary rule -------------------------------------

def edit_utexas_gdc_1(g):
    # White frame (grey 255) one or two cells wide along the top, bottom and left edges, left by
    # the rotation/shift that made 1-original.pgm: not seen floor, so unknown. It is the only
    # white component touching the border (the map itself is surrounded by unknown).
    lab, border = border_components(g == 255)
    mask = np.isin(lab, border)
    g[mask] = UNKNOWN
    return {"gdc_1 white rotation frame -> unknown": int(mask.sum())}


def edit_utexas_gdc_2(g):
    # 2_original.pgm was turned by a few degrees: four white (255) triangles in the corners of
    # the canvas plus their anti-aliased grey fringe (206-254, i.e. "free"). Each white component
    # touching the border with >= 500 cells is such a triangle; its straight inner edge is fitted
    # and the triangle + 2 cells is set to unknown, cells darker than 205 (walls where ray fans
    # meet the old image edge) kept.
    lab, border = border_components(g == 255)
    sizes = ndi.sum(np.ones(g.shape), lab, border)
    total = np.zeros(g.shape, bool)
    for lbl, size in zip(border, sizes):
        if size < 500:
            continue  # a lone white cell where a ray fan reaches the edge: map content, kept
        total |= rotation_wedge(lab == lbl)
    mask = total & (g > UNKNOWN)
    g[mask] = UNKNOWN
    return {"gdc_2 white rotation corner triangles + fringe -> unknown": int(mask.sum())}


def edit_strands_tsc(g):
    # Painted text label "TSC 14/12/2015" in the top-right corner (rows 41-157, cols 1053-1375
    # of 1765 x 1419), well away from the mapped area: set to unknown. (The three letter-like
    # shapes in the middle of the map are scanned objects with rough outlines: kept.)
    y0, y1, x0, x1 = 30, 170, 1040, 1390
    ring = np.zeros(g.shape, bool)
    ring[y0 - 10:y1 + 10, x0 - 10:x1 + 10] = True
    ring[y0:y1, x0:x1] = False
    assert (g[ring] == UNKNOWN).all(), "tsc: the label box is not isolated any more"
    box = g[y0:y1, x0:x1]
    n = int((box != UNKNOWN).sum())
    box[...] = UNKNOWN
    return {"tsc text label -> unknown": n}


def clear_corner_squares(g, name, size=40):
    # Black squares (registration marks) painted in the four corners of the canvas; the maps'
    # own content is far from the corners (checked: only 0 and 205 in each 40 x 40 corner).
    h, w = g.shape
    n = 0
    for ys, xs in [(slice(0, size), slice(0, size)), (slice(0, size), slice(w - size, w)),
                   (slice(h - size, h), slice(0, size)), (slice(h - size, h), slice(w - size, w))]:
        c = g[ys, xs]
        assert set(np.unique(c)) <= {0.0, 205.0}, name + ": corner holds more than a black square"
        n += int((c == 0).sum())
        c[c == 0] = UNKNOWN
    return {name + " black corner squares -> unknown": n}


def edit_upo_uva_demo(g):
    # 32 x 33-cell black squares in the four corners.
    return clear_corner_squares(g, "uva_demo")


def edit_upo_elderly_center(g):
    # 18-20-cell black squares in the four corners.
    return clear_corner_squares(g, "elderly_center")


def edit_upo_centre_sportif(g):
    # 23-24-cell black squares in the four corners.
    return clear_corner_squares(g, "centre_sportif")


EDITS = {
    "utexas_gdc_1": edit_utexas_gdc_1,
    "utexas_gdc_2": edit_utexas_gdc_2,
    "strands_tsc": edit_strands_tsc,
    "upo_uva_demo": edit_upo_uva_demo,
    "upo_elderly_center": edit_upo_elderly_center,
    "upo_centre_sportif": edit_upo_centre_sportif,
    # intel_lab: no cell edit; its grey levels (free 255, unknown 230, occupied 64 and greys in
    # between) are mapped to 0 / 205 / 254 by the trinary rule with ITS OWN thresholds from
    # intel.yaml (occupied_thresh 0.2 -> grey <= 203 occupied, free_thresh 0.05 -> grey >= 243
    # free, 204-242 unknown), so its YAML can carry the standard 0.65 / 0.196.
}


def write_atomically(path, data):
    """Writes to a temporary name beside `path`, then renames: an interrupted run leaves no half file."""
    tmp = path + ".tmp"
    with open(tmp, "wb") as f:
        f.write(data)
    os.replace(tmp, path)


def pgm_bytes(img, comment):
    h, w = img.shape
    return b"P5\n# " + comment.encode() + b"\n" + f"{w} {h}\n255\n".encode() + np.ascontiguousarray(img, np.uint8).tobytes()


def yaml_bytes(name, resolution):
    # Written for every map (origin [0, 0, 0]: the benchmark cuts windows by cells; the
    # repositories' origins, e.g. stata's yaw 3.14, are not kept).
    return (f"image: {name}.pgm\nresolution: {resolution}\norigin: [0.0, 0.0, 0.0]\nnegate: 0\n"
            f"occupied_thresh: {STD_THRESH[0]}\nfree_thresh: {STD_THRESH[1]}\nmode: trinary\n").encode()


def fail(message):
    print("prepare.py: " + message, file=sys.stderr)
    sys.exit(2)


def main():
    ap = argparse.ArgumentParser(description="Writes the real maps of the merging benchmark (17, and 5 held-out with --only) from their sources.")
    ap.add_argument("--src", required=True, help="folder with the source images (bench/real_maps/README.md)")
    ap.add_argument("--out", required=True, help="folder for NAME.pgm and NAME.yaml (created if missing)")
    ap.add_argument("--only", default="", metavar="NAME,...",
                    help="prepare (and require in --src) only these maps; default: the 17 benchmark maps; "
                         "'held-out' names the held-out maps, 'all' every map")
    args = ap.parse_args()
    if args.only in ("", "benchmark"):
        names = [n for n in SOURCES if n not in HELD_OUT]
    elif args.only == "all":
        names = list(SOURCES)
    elif args.only == "held-out":
        names = list(HELD_OUT)
    else:
        names = [n for n in args.only.split(",") if n]
        unknown = [n for n in names if n not in SOURCES]
        if unknown or not names:
            fail(f"--only: unknown map name(s) {', '.join(unknown) or '(none given)'}; known: {', '.join(SOURCES)}")
    sources = {n: SOURCES[n] for n in SOURCES if n in names}
    missing = [f for f, *_ in sources.values() if not os.path.isfile(os.path.join(args.src, f))]
    if missing:
        fail(f"{args.src}: missing {', '.join(missing)} (see bench/real_maps/README.md)")
    # Every output path is checked before any work: none may be a source, a folder, or a link.
    inputs = {os.path.realpath(os.path.join(args.src, f)) for f, *_ in sources.values()}
    if os.path.exists(args.out) and not os.path.isdir(args.out):
        fail(f"--out {args.out}: not a folder")
    for name in sources:
        for ext in (".pgm", ".yaml"):
            path = os.path.join(args.out, name + ext)
            if os.path.realpath(path) in inputs:
                fail(f"--out {args.out}: {name + ext} would replace a source image; give another folder")
            if os.path.islink(path) or (os.path.exists(path) and not os.path.isfile(path)):
                fail(f"--out {args.out}: {name + ext} exists and is not a regular file; not replaced")
    os.makedirs(args.out, exist_ok=True)
    yamls = []
    for name, (fname, origin, res, (occ_t, free_t)) in sources.items():
        g = load_grey(os.path.join(args.src, fname))
        notes = EDITS[name](g) if name in EDITS else {}
        img = trinary(g, occ_t, free_t)
        write_atomically(os.path.join(args.out, name + ".pgm"), pgm_bytes(img, f"fleetmap realmaps {name} from {origin}"))
        yaml = os.path.join(args.out, name + ".yaml")
        write_atomically(yaml, yaml_bytes(name, res))
        yamls.append(yaml)
        counts = np.bincount(img.ravel(), minlength=256)
        print(f"{name}: {img.shape[1]} x {img.shape[0]} cells, {res} m; occupied {counts[OCC]}, "
              f"unknown {counts[UNKNOWN]}, free {counts[FREE]}; edits {notes or '-'}")
    print(",".join(yamls))


if __name__ == "__main__":
    main()
