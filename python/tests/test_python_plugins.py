"""Planners, map aligners and localizers written in Python: registered with declared parameters,
listed, run through the public API by name, their parameters checked, their failures reported with
their names."""
import math
import unittest
from collections import deque

import numpy as np

import fleetmap


class BreadthFirst:
    """A 4-connected breadth-first search over the free cells, answering with cell centres; gives up
    (None) after expanding `max_cells` cells."""

    seen_params = []

    def search(self, free, resolution, origin, start, goal, params):
        BreadthFirst.seen_params.append(dict(params))
        height, width = free.shape

        def cell(p):
            return height - 1 - int((p[1] - origin[1]) / resolution), int((p[0] - origin[0]) / resolution)

        def centre(c):
            return origin[0] + (c[1] + 0.5) * resolution, origin[1] + (height - c[0] - 0.5) * resolution

        first, last = cell(start), cell(goal)
        previous = {first: None}
        queue = deque([first])
        expanded = 0
        while queue and last not in previous:
            if expanded >= params["max_cells"]:
                return None
            c = queue.popleft()
            expanded += 1
            for dr, dc in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                n = (c[0] + dr, c[1] + dc)
                if 0 <= n[0] < height and 0 <= n[1] < width and free[n] and n not in previous:
                    previous[n] = c
                    queue.append(n)
        if last not in previous:
            return None
        path, c = [], last
        while c is not None:
            path.append(centre(c))
            c = previous[c]
        return path[::-1]


class StraightLine:
    """Answers the straight segment whatever lies between: wrong whenever a wall is in the way."""

    def search(self, free, resolution, origin, start, goal, params):
        return [start, goal]


class StopsShort:
    def search(self, free, resolution, origin, start, goal, params):
        return [start, (0.5 * (start[0] + goal[0]), 0.5 * (start[1] + goal[1]))]


class RaisingPlanner:
    def search(self, free, resolution, origin, start, goal, params):
        raise ValueError("no search today")


class MergeMapsAligner:
    """Aligns the robots' maps with fleetmap.merge_maps, accepted from min_confidence on."""

    seen_params = []

    def align(self, receiver_map, sender_map, receiver_pose, sender_pose, params):
        MergeMapsAligner.seen_params.append(dict(params))
        assert receiver_map.image.dtype == np.uint8 and receiver_map.image.ndim == 2
        result = fleetmap.merge_maps(receiver_map, sender_map, min_confidence=params["min_confidence"])
        if not result.merged:
            return None
        tx, ty, theta_deg = result.transform
        return tx, ty, math.radians(theta_deg), result.confidence


class RaisingAligner:
    def align(self, receiver_map, sender_map, receiver_pose, sender_pose, params):
        raise KeyError("nothing to align")


class BiasedDeadReckoning:
    """Integrates the odometry and reports the pose moved by `bias` metres along the map frame's x."""

    made = []

    def __init__(self, initial_pose, params, seed):
        self.x, self.y, self.theta = initial_pose
        self.bias = params["bias"]
        self.scans = 0
        self.beams = set()
        BiasedDeadReckoning.made.append(self)

    def predict(self, dx, dy, dtheta):
        c, s = math.cos(self.theta), math.sin(self.theta)
        self.x += c * dx - s * dy
        self.y += s * dx + c * dy
        self.theta = math.atan2(math.sin(self.theta + dtheta), math.cos(self.theta + dtheta))

    def update_scan(self, ranges, angles, max_range):
        assert ranges.shape == angles.shape
        assert np.all((ranges > 0) & ((ranges <= max_range) | np.isinf(ranges)))
        self.scans += 1
        self.beams.add(len(ranges))

    def pose(self):
        return self.x + self.bias, self.y, self.theta

    def covariance(self):
        return np.diag([0.01, 0.01, 0.001])

    def change_frame(self, tx, ty, theta):
        c, s = math.cos(theta), math.sin(theta)
        self.x, self.y = c * self.x - s * self.y + tx, s * self.x + c * self.y + ty
        self.theta = math.atan2(math.sin(self.theta + theta), math.cos(self.theta + theta))


class StaysInItsFrame(BiasedDeadReckoning):
    change_frame = None


class RaisingLocalizer(BiasedDeadReckoning):
    def predict(self, dx, dy, dtheta):
        raise RuntimeError("wheel fell off")


fleetmap.register_planner("py-bfs", BreadthFirst, help="breadth-first search over cells (a Python test's own)",
                          complete=True,
                          params={"max_cells": {"default": 1000000, "min": 1, "doc": "cells expanded before giving up"}})
fleetmap.register_planner("py-straight", StraightLine)
fleetmap.register_planner("py-short", StopsShort)
fleetmap.register_planner("py-raising-planner", RaisingPlanner)
fleetmap.register_map_aligner("py-merge-maps", MergeMapsAligner, help="merge_maps from Python",
                              params={"min_confidence": {"default": 0.5, "min": 0, "max": 1,
                                                         "doc": "lowest confidence accepted"}})
fleetmap.register_map_aligner("py-raising-aligner", RaisingAligner)
fleetmap.register_localizer("py-biased", BiasedDeadReckoning, help="dead reckoning moved by a bias",
                            params={"bias": {"default": 0.0, "min": -1, "max": 1, "unit": "m",
                                             "doc": "added to the estimate's x"}})
fleetmap.register_localizer("py-raising-localizer", RaisingLocalizer, params={"bias": 0.0})
fleetmap.register_localizer("py-stays-in-its-frame", StaysInItsFrame, params={"bias": 0.0})

START, GOAL = (1.0, 1.0), (15.0, 15.0)  # far apart in the office, walls between them


class PythonPlannerTest(unittest.TestCase):
    def test_it_is_listed_with_its_parameters(self):
        self.assertIn("py-bfs", fleetmap.planner_names())
        listed = {p["name"]: p for p in fleetmap.planners()}
        self.assertEqual(listed["py-bfs"]["help"], "breadth-first search over cells (a Python test's own)")
        self.assertEqual([(p["name"], p["kind"], p["default"], p["accepts"]) for p in listed["py-bfs"]["params"]],
                         [("max_cells", "number", "1000000", "a number >= 1")])
        self.assertEqual(listed["py-straight"]["params"], [])

    def test_plan_path_reaches_it_with_its_parameters(self):
        office = fleetmap.load_map("office")
        result = fleetmap.plan_path(office, START, GOAL, planner="py-bfs")
        self.assertTrue(result.success, result.detail)
        self.assertEqual(result.planner, "py-bfs")
        self.assertEqual(BreadthFirst.seen_params[-1], {"max_cells": 1000000.0})
        # The ends are the start and goal themselves; no segment is shorter than a path can be.
        np.testing.assert_allclose(result.path[0], START)
        np.testing.assert_allclose(result.path[-1], GOAL)
        straight = math.dist(START, GOAL)
        astar = fleetmap.plan_path(office, START, GOAL, planner="astar")
        self.assertGreaterEqual(result.length_m, astar.length_m - 1e-6)
        self.assertGreater(result.length_m, straight)
        # A budget too small for the search: the planner gives up, and says so as a status.
        small = fleetmap.plan_path(office, START, GOAL, planner="py-bfs", params={"max_cells": 50})
        self.assertEqual(BreadthFirst.seen_params[-1], {"max_cells": 50.0})
        self.assertFalse(small.success)
        self.assertEqual(small.status, "no path within budget")
        self.assertIn("py-bfs", small.detail)

    def test_an_exploration_plans_with_it(self):
        calls = len(BreadthFirst.seen_params)
        run = fleetmap.explore(map="office", robots=1, steps=20, seed=1,
                               exploration={"path_planner": {"name": "py-bfs", "max_cells": 5000}})
        self.assertGreater(len(BreadthFirst.seen_params), calls)
        self.assertEqual(BreadthFirst.seen_params[-1], {"max_cells": 5000.0})
        self.assertGreater(run.coverage[-1], run.coverage[0])

    def test_a_bad_value_is_refused_with_its_range(self):
        office = fleetmap.load_map("office")
        calls = len(BreadthFirst.seen_params)
        with self.assertRaisesRegex(ValueError, "py-bfs.*'max_cells'.*a number >= 1.*got '0'"):
            fleetmap.plan_path(office, START, GOAL, planner="py-bfs", params={"max_cells": 0})
        with self.assertRaisesRegex(ValueError, "py-bfs' has no parameter 'max_cell'.*did you mean 'max_cells'"):
            fleetmap.plan_path(office, START, GOAL, planner="py-bfs", params={"max_cell": 10})
        self.assertEqual(len(BreadthFirst.seen_params), calls)

    def test_a_path_that_is_not_one_is_an_error_naming_the_planner(self):
        office = fleetmap.load_map("office")
        with self.assertRaisesRegex(RuntimeError, "planner 'py-straight': segment 0 .* leaves the free space"):
            fleetmap.plan_path(office, START, GOAL, planner="py-straight")
        with self.assertRaisesRegex(RuntimeError, "planner 'py-short': the path's last waypoint .* from the goal"):
            fleetmap.plan_path(office, START, GOAL, planner="py-short")
        # Where nothing is in the way, the straight segment is a path.
        near = fleetmap.plan_path(office, START, (2.0, 1.0), planner="py-straight")
        self.assertTrue(near.success, near.detail)
        self.assertAlmostEqual(near.length_m, 1.0)

    def test_an_exception_in_search_names_the_planner(self):
        office = fleetmap.load_map("office")
        with self.assertRaisesRegex(RuntimeError, "planner 'py-raising-planner': search raised ValueError: no search"):
            fleetmap.plan_path(office, START, GOAL, planner="py-raising-planner")

    def test_search_must_take_its_arguments(self):
        class TooFew:
            def search(self, free, start, goal):
                return None

        with self.assertRaisesRegex(ValueError, "py-too-few.*search must take \\(free, resolution, origin"):
            fleetmap.register_planner("py-too-few", TooFew)
        self.assertNotIn("py-too-few", fleetmap.planner_names())


# Two robots that start apart in the office, each in its own map frame, within talking range.
TWO_ROBOTS = {"map": "office", "robots": {"starts": [[1.0, 1.0, 0.0], [3.0, 1.0, 180.0]]}, "seed": 1}


class PythonMapAlignerTest(unittest.TestCase):
    def test_it_is_listed_with_its_parameters(self):
        listed = {a["name"]: a for a in fleetmap.map_aligners()}
        self.assertEqual([(p["name"], p["default"], p["unit"], p["accepts"])
                          for p in listed["py-merge-maps"]["params"]],
                         [("min_confidence", "0.5", "", "a number >= 0 and <= 1")])

    def test_explore_merges_with_it_by_name_and_its_parameter(self):
        MergeMapsAligner.seen_params.clear()
        eager = fleetmap.explore(TWO_ROBOTS, steps=30,
                                 merging={"mode": "py-merge-maps", "min_confidence": 0.0, "attempt_every": 5})
        self.assertEqual(MergeMapsAligner.seen_params[0], {"min_confidence": 0.0})
        self.assertEqual(eager.metrics["merging"], "py-merge-maps")
        self.assertGreaterEqual(eager.metrics["merges_made"], 1)
        self.assertEqual(eager.metrics["merges"][0]["method"], "py-merge-maps")
        # Nothing is ever certain enough at 1: every attempt is refused, and the robots stay apart.
        MergeMapsAligner.seen_params.clear()
        strict = fleetmap.explore(TWO_ROBOTS, steps=30,
                                  merging={"mode": "py-merge-maps", "min_confidence": 1.0, "attempt_every": 5})
        self.assertTrue(MergeMapsAligner.seen_params)
        self.assertTrue(all(p == {"min_confidence": 1.0} for p in MergeMapsAligner.seen_params))
        self.assertEqual(strict.metrics["merges_made"], 0)
        self.assertGreaterEqual(strict.metrics["merges_refused"], 1)

    def test_a_bad_value_is_refused_with_its_range(self):
        with self.assertRaisesRegex(ValueError, "min_confidence.*a number >= 0 and <= 1.*got '1.5'"):
            fleetmap.explore(TWO_ROBOTS, steps=5, merging={"mode": "py-merge-maps", "min_confidence": 1.5})

    def test_an_exception_in_align_names_the_aligner(self):
        with self.assertRaisesRegex(RuntimeError, "map aligner 'py-raising-aligner': align raised KeyError"):
            fleetmap.explore(TWO_ROBOTS, steps=30, merging={"mode": "py-raising-aligner", "attempt_every": 5})


class PythonLocalizerTest(unittest.TestCase):
    def test_it_is_listed_with_its_parameters(self):
        listed = {a["name"]: a for a in fleetmap.localizers()}
        self.assertEqual([(p["name"], p["default"], p["unit"], p["accepts"]) for p in listed["py-biased"]["params"]],
                         [("bias", "0.0", "m", "a number >= -1 and <= 1 (m)")])

    def test_explore_uses_it_with_its_parameter(self):
        # Without odometry noise dead reckoning is the truth, so the estimate is the truth moved by the bias.
        for bias in (0.0, 0.3):
            BiasedDeadReckoning.made.clear()
            run = fleetmap.explore(TWO_ROBOTS, steps=15, noise={"position": 0.0, "heading_deg": 0.0},
                                   localization={"name": "py-biased", "bias": bias})
            self.assertEqual(len(BiasedDeadReckoning.made), 2)
            for localizer in BiasedDeadReckoning.made:
                self.assertEqual(localizer.bias, bias)
                self.assertGreaterEqual(localizer.scans, run.steps)  # it reads scans: it has update_scan
                self.assertEqual(len(localizer.beams), 1)
            for truth, estimate in zip(run.trajectories, run.estimates):
                self.assertGreater(np.ptp(truth[:, 0]) + np.ptp(truth[:, 1]), 0.1)  # the robot moved
                np.testing.assert_allclose(estimate[:, 0] - truth[:, 0], bias, atol=1e-6)
                np.testing.assert_allclose(estimate[:, 1:], truth[:, 1:], atol=1e-6)

    def test_it_moves_into_a_teammates_frame_after_a_merge(self):
        run = fleetmap.explore(TWO_ROBOTS, steps=20, noise={"position": 0.0, "heading_deg": 0.0},
                               localization="py-biased", merging={"mode": "py-merge-maps", "attempt_every": 5})
        merge = next(m for m in run.metrics["merges"] if m["merged"])
        sender = merge["sender"] - 1
        truth, estimate = run.trajectories[sender], run.estimates[sender]
        # After the merge the estimate is off by the merge's own error: its position error where the
        # sender was, and its rotation error over the distance the sender went on from there.
        after = merge["step"] + 1
        travelled = np.max(np.linalg.norm(truth[after:, :2] - truth[merge["step"], :2], axis=1))
        tolerance = merge["position_error_m"] + math.radians(merge["rotation_error_deg"]) * travelled + 1e-6
        self.assertLess(np.max(np.linalg.norm(estimate[after:, :2] - truth[after:, :2], axis=1)), tolerance)
        with self.assertRaisesRegex(RuntimeError, "localizer 'py-stays-in-its-frame' has no change_frame"):
            fleetmap.explore(TWO_ROBOTS, steps=20, localization="py-stays-in-its-frame",
                             merging={"mode": "py-merge-maps", "attempt_every": 5})

    def test_a_bad_value_is_refused_with_its_range(self):
        with self.assertRaisesRegex(ValueError, "localization.bias.*a number >= -1 and <= 1.*got '2'"):
            fleetmap.explore(TWO_ROBOTS, steps=5, localization={"name": "py-biased", "bias": 2})

    def test_an_exception_in_predict_names_the_localizer(self):
        with self.assertRaisesRegex(RuntimeError, "localizer 'py-raising-localizer': predict raised RuntimeError: "
                                                  "wheel fell off"):
            fleetmap.explore(TWO_ROBOTS, steps=5, localization="py-raising-localizer")

    def test_an_exception_in_its_constructor_names_the_localizer(self):
        class RefusesToStart(BiasedDeadReckoning):
            def __init__(self, initial_pose, params, seed):
                raise ValueError(f"no start at {initial_pose}")

        fleetmap.register_localizer("py-refuses-to-start", RefusesToStart)
        with self.assertRaisesRegex(RuntimeError, "localizer 'py-refuses-to-start': making it raised ValueError: "
                                                  "no start at \\(1.0, 1.0, 0.0\\)"):
            fleetmap.explore(TWO_ROBOTS, steps=5, localization="py-refuses-to-start")

    def test_sweeps_run_it_on_several_threads(self):
        rows = fleetmap.sweep(maps=["empty"], strategies=["coordinated"], robots=2, seeds=2, steps=10, jobs=2,
                              localization="py-biased")
        self.assertEqual([r["localization"] for r in rows], ["py-biased", "py-biased"])

    def test_it_must_have_predict_and_pose(self):
        class NoPose:
            def __init__(self, initial_pose, params, seed):
                pass

            def predict(self, dx, dy, dtheta):
                pass

        with self.assertRaisesRegex(ValueError, "register_localizer 'py-no-pose': the class has no pose method"):
            fleetmap.register_localizer("py-no-pose", NoPose)
        self.assertNotIn("py-no-pose", [m["name"] for m in fleetmap.localizers()])

        class MadeWithoutArguments(BiasedDeadReckoning):
            def __init__(self):
                pass

        with self.assertRaisesRegex(ValueError, "py-no-arguments.*made as cls\\(initial_pose, params, seed\\)"):
            fleetmap.register_localizer("py-no-arguments", MadeWithoutArguments)


if __name__ == "__main__":
    unittest.main()
