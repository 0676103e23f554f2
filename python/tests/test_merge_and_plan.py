"""Merging two maps (transform, confidence, fused map) and planning a path on a map."""
import json
import math
import platform
import resource
import tempfile
import subprocess
import sys
import textwrap
import unittest
from pathlib import Path

import numpy as np

import fleetmap
from cli_support import run_fleetmap


def office_windows():
    """The built-in office (0.05 m cells, 200 x 200) cut in two overlapping windows: a holds its
    columns 0-129, b its columns 70-199, so b's frame is a's moved 3.5 m along x."""
    office = fleetmap.load_map("office").image
    return fleetmap.Map.from_image(office[:, :130].copy()), fleetmap.Map.from_image(office[:, 70:].copy())


class MergeTest(unittest.TestCase):
    def test_two_overlapping_parts_of_a_map_are_aligned_in_metres_and_degrees(self):
        a, b = office_windows()
        result = fleetmap.merge_maps(a, b)
        self.assertTrue(result.merged, result.reason)
        self.assertGreaterEqual(result.confidence, 0.5)
        # Sub-cell accuracy is the refinement's goal; half a cell and half a degree leave room for it.
        tx, ty, theta = result.transform
        self.assertAlmostEqual(tx, 3.5, delta=0.025)
        self.assertAlmostEqual(ty, 0.0, delta=0.025)
        self.assertAlmostEqual(theta, 0.0, delta=0.5)
        # The same in pixels: b's column u is a's column u + 70.
        px, py, ptheta = result.pixel_transform
        self.assertAlmostEqual(px, 70.0, delta=0.5)
        self.assertAlmostEqual(py, 0.0, delta=0.5)
        self.assertAlmostEqual(ptheta, 0.0, delta=0.5)
        self.assertEqual(result.scale, 1.0)

    def test_a_merge_methods_own_parameters_are_listed_set_and_checked(self):
        methods = {m["name"]: m for m in fleetmap.merge_methods()}
        self.assertEqual(list(methods)[:3], ["auto", "grid", "features"])
        ratio = next(p for p in methods["features"]["params"] if p["name"] == "ratio")
        self.assertEqual(ratio["default"], "0.8")
        a, b = office_windows()
        # More inliers than any ORB model here: features proposes nothing; under auto grid still merges.
        none = fleetmap.merge_maps(a, b, method="features", params={"features": {"min_inliers": 10000}})
        self.assertFalse(none.merged)
        self.assertIn("no candidate transform", none.reason)
        self.assertTrue(fleetmap.merge_maps(a, b, params={"features": {"min_inliers": 10000}}).merged)
        with self.assertRaisesRegex(fleetmap.InputError, "did you mean 'ratio'"):
            fleetmap.merge_maps(a, b, params={"features": {"ratoi": 0.5}})
        with self.assertRaisesRegex(fleetmap.InputError, "does not run 'features'"):
            fleetmap.merge_maps(a, b, method="grid", params={"features": {"ratio": 0.5}})
        with self.assertRaisesRegex(fleetmap.InputError, ">= 0.25"):
            fleetmap.merge_maps(a, b, params={"grid": {"sweep_step_deg": 0}})

    def test_an_explorations_merge_methods_get_their_parameters_under_merging(self):
        team = {"map": "office", "robots": {"random": 2, "min_separation": 4}, "seed": 1}
        run = fleetmap.explore(team, steps=60, merging={"mode": "overlap", "method": "features",
                                                         "features": {"min_inliers": 10000}})
        self.assertTrue(run.metrics["merges"])
        self.assertEqual({m["reason"] for m in run.metrics["merges"]}, {"no reliable overlap: no candidate transform"})
        with self.assertRaisesRegex(fleetmap.InputError, "merging.features.min_inliers.*from 3 to 10000"):
            fleetmap.explore(team, steps=5, merging={"mode": "overlap", "features": {"min_inliers": 1}})

    def test_a_merge_reports_its_covariance_in_metres_and_radians(self):
        a, b = office_windows()
        result = fleetmap.merge_maps(a, b)
        self.assertTrue(result.merged, result.reason)
        cov = result.covariance
        self.assertEqual(cov.shape, (3, 3))
        np.testing.assert_allclose(cov, cov.T, atol=1e-15)
        self.assertTrue(np.all(np.linalg.eigvalsh(cov) >= 0.0))
        # Its standard deviations, metres and degrees: a fraction of a 0.05 m cell and of a degree.
        std_tx, std_ty, std_theta = result.std
        self.assertAlmostEqual(std_tx, math.sqrt(cov[0, 0]), places=12)
        self.assertAlmostEqual(std_theta, math.degrees(math.sqrt(cov[2, 2])), places=9)
        self.assertLess(max(std_tx, std_ty), 0.025)
        self.assertLess(std_theta, 0.5)
        major, minor, direction = result.uncertain_direction
        self.assertGreaterEqual(major, minor)
        self.assertTrue(0.0 <= direction < 180.0)

    def test_a_turned_and_shifted_map_file_is_recovered_in_metres(self):
        office = fleetmap.load_map("office").image
        a = fleetmap.Map.from_image(office[:, :130].copy())
        # b: the right window turned a quarter turn counter-clockwise, its lower-left corner at (1, 2) m.
        # A point q of the office is at R(90) (q - (3.5, 0)) + (10, 0) + (1, 2) in b's frame, so a point
        # p of b's frame is at R(-90) p + (1.5, 11) in a's (= the office's).
        b = fleetmap.Map.from_image(np.rot90(office[:, 70:]).copy(), origin=(1.0, 2.0, 0.0))
        result = fleetmap.merge_maps(a, b)
        self.assertTrue(result.merged, result.reason)
        tx, ty, theta = result.transform
        self.assertAlmostEqual(theta, -90.0, delta=0.5)
        # Within a cell at b's far corner (10 m from its origin): the rotation's error included.
        self.assertLess(math.hypot(tx - 1.5, ty - 11.0), 0.05 + math.radians(abs(theta + 90.0)) * 12.0)

    def test_maps_of_different_resolutions_are_aligned_in_one_frame_of_metres(self):
        a, b = office_windows()
        coarse = b.resampled(0.1)
        self.assertEqual((coarse.width, coarse.height), ((b.width + 1) // 2, (b.height + 1) // 2))
        self.assertAlmostEqual(coarse.resolution, 0.1)
        # Metres do not depend on the cells: b's frame is a's moved 3.5 m, whichever map has which cells.
        for first, second, expected_tx, scale in ((a, coarse, 3.5, 2.0), (coarse, a, -3.5, 0.5),
                                                  (a.resampled(0.1), coarse, 3.5, 1.0)):
            result = fleetmap.merge_maps(first, second)
            self.assertTrue(result.merged, result.reason)
            tx, ty, theta = result.transform
            self.assertAlmostEqual(tx, expected_tx, delta=0.05)
            self.assertAlmostEqual(ty, 0.0, delta=0.05)
            self.assertAlmostEqual(theta, 0.0, delta=0.5)
            self.assertEqual(result.scale, scale)
        with self.assertRaisesRegex(fleetmap.InputError, "resampled: resolution"):
            a.resampled(0.0)
        with self.assertRaisesRegex(fleetmap.InputError, "resampled: 0.001 m cells would make .* over the limit"):
            a.resampled(0.001)

    def test_the_fused_map_plans_across_the_part_only_the_second_map_knew(self):
        a, b = office_windows()
        result = fleetmap.merge_maps(a, b)
        self.assertTrue(result.merged, result.reason)
        fused = result.map
        self.assertIsInstance(fused, fleetmap.Map)
        self.assertEqual(fused.resolution, a.resolution)
        self.assertGreater(fused.free_cells, max(a.free_cells, b.free_cells))
        # From a room only a knew (x < 3.5 m) to one only b knew (x > 6.5 m), along the corridor at y = 5 m.
        start, goal = (1.0, 5.0), (9.0, 5.0)
        self.assertFalse(fleetmap.plan_path(a, start, goal).success)
        path = fleetmap.plan_path(fused, start, goal)
        self.assertTrue(path.success, path.detail)
        self.assertGreater(path.path[:, 0].max(), 6.5)

    def test_a_planners_own_parameters_reach_it_and_are_checked(self):
        room = np.full((60, 80), 254, np.uint8)
        room[[0, -1], :] = 0
        room[:, [0, -1]] = 0
        room[10:50, 38:42] = 0  # a wall in the way
        grid = fleetmap.Map.from_image(room, 0.1)
        reactive = {p["name"]: p for p in fleetmap.planners()}["reactive"]
        self.assertIn("turn_angle_deg", [p["name"] for p in reactive["params"]])
        narrow = fleetmap.plan_path(grid, (1.0, 3.0), (7.0, 3.0), planner="reactive")
        wide = fleetmap.plan_path(grid, (1.0, 3.0), (7.0, 3.0), planner="reactive", params={"turn_angle_deg": 20})
        self.assertTrue(narrow.success, narrow.detail)
        self.assertTrue(wide.success, wide.detail)
        self.assertNotAlmostEqual(narrow.length_m, wide.length_m, places=3)  # another swerve around the wall
        with self.assertRaisesRegex(fleetmap.InputError, "planner 'astar' has no parameter 'turn_angle_deg'"):
            fleetmap.plan_path(grid, (1.0, 3.0), (7.0, 3.0), params={"turn_angle_deg": 30})
        with self.assertRaisesRegex(fleetmap.InputError, "turn_angle_deg"):
            fleetmap.plan_path(grid, (1.0, 3.0), (7.0, 3.0), planner="reactive", params={"turn_angle_deg": 500})

    def test_a_merge_refused_has_no_map_and_planning_on_it_says_so(self):
        empty = np.full((60, 60), 205, np.uint8)
        empty[10:50, 10:50] = 254
        result = fleetmap.merge_maps(fleetmap.Map.from_image(empty), fleetmap.Map.from_image(empty))
        self.assertFalse(result.merged)
        self.assertTrue(result.reason)
        self.assertIsNone(result.map)
        with self.assertRaisesRegex(fleetmap.InputError, "plan_path: map must be a fleetmap.Map, got None"):
            fleetmap.plan_path(result.map, (1, 1), (2, 2))
        with self.assertRaisesRegex(fleetmap.InputError, "merge_maps: b must be a fleetmap.Map"):
            fleetmap.merge_maps(fleetmap.Map.from_image(empty), empty)


class MergeAgreesWithTheCommandTest(unittest.TestCase):
    """Python and `fleetmap merge` on the same two map files give the same numbers and the same map."""

    def test_the_transform_and_the_fused_map_are_the_commands(self):
        office = fleetmap.load_map("office").image
        with tempfile.TemporaryDirectory() as tmp:
            folder = Path(tmp)
            # Inside a larger unknown area, as a robot's map often is; b turned and placed elsewhere.
            a = fleetmap.Map.from_image(np.pad(office[:, :130], 60, constant_values=205), origin=(-2.0, 1.0, 0.0))
            b = fleetmap.Map.from_image(np.pad(np.rot90(office[:, 70:], 3), 40, constant_values=205),
                                        origin=(3.0, -4.0, 0.3))
            fleetmap.save_map(a, folder / "a.yaml")
            fleetmap.save_map(b, folder / "b.yaml")
            code, out, err = run_fleetmap("merge", "a.yaml", "b.yaml", "--json", "r.json", "--out", "merged.yaml",
                                          cwd=folder)
            self.assertEqual(code, 0, err + out)
            command = json.loads((folder / "r.json").read_text())["transforms"][0]
            result = fleetmap.merge_maps(fleetmap.load_map(str(folder / "a.yaml")), fleetmap.load_map(str(folder / "b.yaml")))
            self.assertTrue(result.merged, result.reason)
            np.testing.assert_allclose(result.transform, (command["tx_m"], command["ty_m"], command["theta_deg"]),
                                       rtol=0, atol=1e-9)
            np.testing.assert_allclose(result.pixel_transform,
                                       (command["tx_px"], command["ty_px"], command["theta_px_deg"]), rtol=0, atol=1e-9)
            written = fleetmap.load_map(str(folder / "merged.yaml"))
            self.assertEqual((written.width, written.height), (result.map.width, result.map.height))
            np.testing.assert_allclose(written.origin, result.map.origin, atol=1e-6)
            np.testing.assert_array_equal(written.image, result.map.image)


class MergeMemoryTest(unittest.TestCase):
    @unittest.skipUnless(platform.libc_ver()[0] == "glibc", "the allocator setting is glibc's")
    def test_importing_changes_no_allocator_setting_and_the_call_keeps_freed_memory(self):
        # Run in a fresh interpreter: the setting is process-wide, and this one may have made it.
        # Two 1000 x 1200 windows of campus merged three times: glibc's defaults fault 10 MB of pages
        # in for every merge (measured 2623-3061 faults); with fleetmap.keep_freed_memory() the later
        # merges reuse the first one's memory (measured 310, 58, 0).
        script = textwrap.dedent("""
            import resource, sys
            import fleetmap
            campus = fleetmap.load_map("campus").image
            a = fleetmap.Map.from_image(campus[:, : campus.shape[1] - 200].copy())
            b = fleetmap.Map.from_image(campus[:, 200:].copy())
            def faults():
                before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
                assert fleetmap.merge_maps(a, b).merged
                return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before
            faults()
            default = max(faults(), faults())
            assert fleetmap.keep_freed_memory()
            faults()
            kept = max(faults(), faults())
            print(default, kept)
        """)
        out = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, check=True).stdout.split()
        default, kept = int(out[0]), int(out[1])
        self.assertGreater(default, 1000, "importing fleetmap should leave glibc's defaults alone")
        self.assertLess(kept, 1000)


class PlanTest(unittest.TestCase):
    def test_a_path_joins_start_and_goal_through_free_space(self):
        office = fleetmap.load_map("office")
        free = np.argwhere(office.image == 254)  # (row, column) of free cells
        res = office.resolution

        def metres(rc):
            return ((rc[1] + 0.5) * res, (office.height - 1 - rc[0] + 0.5) * res)

        start, goal = metres(free[len(free) // 3]), metres(free[2 * len(free) // 3])
        result = fleetmap.plan_path(office, start, goal, planner="astar", robot_radius=0.0)
        self.assertTrue(result.success, result.detail)
        path = result.path
        self.assertEqual(path.shape[1], 2)
        np.testing.assert_allclose(path[0], start)
        np.testing.assert_allclose(path[-1], goal)
        self.assertGreaterEqual(result.length_m, math.dist(start, goal) - 1e-9)
        self.assertAlmostEqual(result.length_m, np.linalg.norm(np.diff(path, axis=0), axis=1).sum(), places=6)

    def test_a_goal_in_a_wall_is_refused(self):
        office = fleetmap.load_map("office")
        result = fleetmap.plan_path(office, (1.0, 1.0), (0.01, 0.01))
        self.assertFalse(result.success)
        self.assertIn("obstacle", result.status.lower() + result.detail.lower())
        self.assertEqual(result.path.shape, (0, 2))


if __name__ == "__main__":
    unittest.main()
