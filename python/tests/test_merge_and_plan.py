"""Merging two maps (transform and confidence) and planning a path on a map."""
import math
import platform
import resource
import unittest

import numpy as np

import fleetmap


class MergeTest(unittest.TestCase):
    def test_two_overlapping_parts_of_a_map_are_aligned(self):
        office = fleetmap.load_map("office").image
        # a: the left 130 columns; b: the right 130 columns (top row first), so b's cell x is a's x - 70.
        a = fleetmap.Map.from_image(office[:, :130].copy())
        b = fleetmap.Map.from_image(office[:, 70:].copy())
        result = fleetmap.merge_maps(a, b)
        self.assertTrue(result.merged, result.reason)
        self.assertGreaterEqual(result.confidence, 0.5)
        tx, ty, theta = result.transform
        # Sub-cell accuracy is the refinement's goal; half a cell and half a degree leave room for it.
        self.assertAlmostEqual(tx, 70.0, delta=0.5)
        self.assertAlmostEqual(ty, 0.0, delta=0.5)
        self.assertAlmostEqual(theta, 0.0, delta=math.radians(0.5))

    def test_maps_of_different_resolutions_are_aligned_through_the_coarser_cells(self):
        office = fleetmap.load_map("office").image
        a = fleetmap.Map.from_image(office[:, :130].copy(), resolution=0.05)
        coarse = fleetmap.Map.from_image(office[:, 70:].copy(), resolution=0.05).resampled(0.1)
        self.assertEqual((coarse.width, coarse.height), ((office.shape[1] - 70 + 1) // 2, (office.shape[0] + 1) // 2))
        self.assertAlmostEqual(coarse.resolution, 0.1)
        # The transform takes the second map's cells seen through the first's into the first's:
        # b's 0.05 m cell x is a's x + 70, and a's 0.1 m cell x is coarse's x - 35.
        for first, second, expected_tx in ((a, coarse, 70.0), (coarse, a, -35.0)):
            result = fleetmap.merge_maps(first, second)
            self.assertTrue(result.merged, result.reason)
            tx, ty, theta = result.transform
            self.assertAlmostEqual(tx, expected_tx, delta=1.0)
            self.assertAlmostEqual(ty, 0.0, delta=1.0)
            self.assertAlmostEqual(theta, 0.0, delta=math.radians(0.5))
        # Seen through one resolution, the same answer in 0.1 m cells.
        result = fleetmap.merge_maps(a.resampled(0.1), coarse)
        self.assertTrue(result.merged, result.reason)
        self.assertAlmostEqual(result.transform[0], 35.0, delta=0.5)
        with self.assertRaisesRegex(fleetmap.InputError, "resampled: resolution"):
            a.resampled(0.0)
        with self.assertRaisesRegex(fleetmap.InputError, "resampled: 0.001 m cells would make .* over the limit"):
            a.resampled(0.001)

    @unittest.skipUnless(platform.libc_ver()[0] == "glibc", "the allocator setting is glibc's")
    def test_merging_again_reuses_the_memory_of_the_last_merge(self):
        # Importing fleetmap keeps freed memory for reuse (core/memory.h): a script that merges
        # large maps in a loop would otherwise fault every merge's pages in again. Two 1000 x 1200
        # windows of campus: measured 12255 page faults for the first merge, then 310, 58 and 0; with
        # glibc's defaults 3061, 2681 and 2623.
        campus = fleetmap.load_map("campus").image
        a = fleetmap.Map.from_image(campus[:, : campus.shape[1] - 200].copy())
        b = fleetmap.Map.from_image(campus[:, 200:].copy())

        def faults_of_a_merge():
            before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
            result = fleetmap.merge_maps(a, b)
            self.assertTrue(result.merged, result.reason)
            self.assertAlmostEqual(result.transform[0], 200.0, delta=0.5)
            return resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before

        faults_of_a_merge()  # maps what a merge of this size needs
        for _ in range(2):
            self.assertLess(faults_of_a_merge(), 1000)  # 4 MB; glibc's defaults fault 10 MB in a merge

    def test_maps_with_nothing_in_common_are_not_merged(self):
        empty = np.full((60, 60), 205, np.uint8)
        empty[10:50, 10:50] = 254
        result = fleetmap.merge_maps(fleetmap.Map.from_image(empty), fleetmap.Map.from_image(empty))
        self.assertFalse(result.merged)
        self.assertTrue(result.reason)


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
