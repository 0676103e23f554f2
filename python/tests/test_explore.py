"""Explorations from keyword arguments, dicts and files: metrics.json's dict and per-step arrays."""
import math
import tempfile
import unittest
from pathlib import Path

import numpy as np

import fleetmap


class ExploreTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.base = fleetmap.explore(map="empty", robots=2, steps=40, seed=3)

    def test_metrics_and_arrays_describe_the_same_run(self):
        run = self.base
        self.assertEqual(run.metrics["map"], "empty")
        self.assertEqual(run.metrics["robots"], 2)
        self.assertEqual(run.metrics["steps"], run.steps)
        self.assertEqual(run.coverage.shape, (run.steps + 1,))
        self.assertAlmostEqual(run.metrics["coverage"], run.coverage[-1])
        self.assertTrue(np.all(np.diff(run.coverage) >= -1e-12), "the merged map never forgets")
        self.assertGreater(run.coverage[-1], run.coverage[0])
        self.assertEqual(len(run.trajectories), 2)
        travelled = 0.0
        for poses in run.trajectories:
            self.assertEqual(poses.shape, (run.steps + 1, 3))
            travelled += np.linalg.norm(np.diff(poses[:, :2], axis=0), axis=1).sum()
        # metrics.json's distance is the length of the arcs the robots drove; the poses give the
        # chords. A step turns at most 90 degrees (the default turn rate at a 1 s period), where a
        # chord is sin(45 deg) / (pi / 4) = 0.900 of its arc; the motion noise adds 1 mm a step.
        distance = run.metrics["distance_m"]
        self.assertGreater(distance, 1.0)
        noise = 2 * 0.001 * 3 * run.steps
        self.assertLessEqual(travelled, distance + noise)
        self.assertGreaterEqual(travelled, 0.900 * distance - noise)
        self.assertEqual(run.merged_map.image.shape, fleetmap.load_map("empty").image.shape)

    def test_the_same_scenario_as_a_dict_or_a_file_gives_the_same_run(self):
        scenario = {"map": "empty", "robots": 2, "steps": 40, "seed": 3}
        by_dict = fleetmap.explore(scenario)
        with tempfile.TemporaryDirectory() as tmp:
            path = Path(tmp) / "s.yaml"
            path.write_text("map: empty\nrobots: 2\nsteps: 40\nseed: 3\n")
            by_file = fleetmap.explore(path)
            files = by_file.save(Path(tmp) / "out")
            self.assertTrue((Path(tmp) / "out" / "metrics.json").is_file())
            self.assertIn(str(Path(tmp) / "out" / "merged.png"), files)
        for run in (by_dict, by_file):
            np.testing.assert_array_equal(run.coverage, self.base.coverage)
            np.testing.assert_array_equal(run.trajectories[1], self.base.trajectories[1])

    def test_a_bad_key_is_named(self):
        with self.assertRaisesRegex(ValueError, "robots"):
            fleetmap.explore(map="empty", robots=0)
        with self.assertRaisesRegex(ValueError, "no_such_key"):
            fleetmap.explore(map="empty", no_such_key=1)


if __name__ == "__main__":
    unittest.main()
