"""Planners, map aligners, localizers and merge methods written in Python: registered with declared
parameters, listed, run through the public API by name, their parameters checked, their failures
reported with their names."""
import math
import unittest
from collections import deque

import numpy as np

import fleetmap
from test_merge_and_plan import office_windows


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


# `auto` runs every registered merge method, in this process's other tests too: the classes below
# propose nothing (and raise nothing) unless a test turns them on here.
MERGE_METHODS_ON = set()


# office_windows(): b's frame is a's moved 3.5 m along x (70 columns of 0.05 m cells).
WINDOWS_SHIFT = (3.5, 0.0, 0.0)
CELL = 0.05


class ShiftOracle:
    """Proposes office_windows()'s true transform moved by `offset` metres along x."""

    made = []

    def __init__(self, params):
        self.offset = params["offset"]
        self.seen = []
        ShiftOracle.made.append(self)

    def propose(self, a, b):
        if type(self) not in MERGE_METHODS_ON:
            return []
        self.seen.append((a, b))
        tx, ty, theta = WINDOWS_SHIFT
        return [(tx + self.offset, ty, theta)]


class FixedAnswer:
    """Proposes `answer` with a score; no parameters."""

    answer = None
    seen = []

    def __init__(self, params):
        FixedAnswer.seen.append(params)

    def propose(self, a, b):
        if type(self) not in MERGE_METHODS_ON:
            return []
        FixedAnswer.seen.append((a, b))
        return [FixedAnswer.answer + (1.0,)]


class GridFromPython:
    """Answers merge_maps' own transform of the two maps it gets (grid search), in radians."""

    calls = 0

    def __init__(self, params):
        pass

    def propose(self, a, b):
        if type(self) not in MERGE_METHODS_ON:
            return []
        GridFromPython.calls += 1
        result = fleetmap.merge_maps(a, b, method="grid", min_confidence=0.0)
        tx, ty, theta_deg = result.transform
        return [(tx, ty, math.radians(theta_deg), result.confidence)]


class RaisingMergeMethod:
    def __init__(self, params):
        pass

    def propose(self, a, b):
        if type(self) not in MERGE_METHODS_ON:
            return []
        raise ValueError(f"no idea where {b.width} x {b.height} goes")


class WrongShape(RaisingMergeMethod):
    def propose(self, a, b):
        return [(1.0, 2.0)] if type(self) in MERGE_METHODS_ON else []


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
fleetmap.register_merge_method("py-oracle", ShiftOracle, help="the true shift moved along x (a Python test's own)",
                               params={"offset": {"default": 0.0, "min": -5, "max": 5, "unit": "m",
                                                  "doc": "added to the true tx"}})
fleetmap.register_merge_method("py-fixed", FixedAnswer)
fleetmap.register_merge_method("py-grid", GridFromPython, help="merge_maps' grid search called from Python")
fleetmap.register_merge_method("py-raising-merge", RaisingMergeMethod)
fleetmap.register_merge_method("py-wrong-shape", WrongShape)

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


class PythonMergeMethodTest(unittest.TestCase):
    def turn_on(self, *classes):
        MERGE_METHODS_ON.update(classes)
        self.addCleanup(MERGE_METHODS_ON.clear)

    def test_it_is_listed_with_its_parameters(self):
        self.assertIn("py-oracle", fleetmap.merge_method_names())
        listed = {m["name"]: m for m in fleetmap.merge_methods()}
        self.assertEqual(listed["py-oracle"]["help"], "the true shift moved along x (a Python test's own)")
        self.assertEqual([(p["name"], p["kind"], p["default"], p["unit"], p["accepts"])
                          for p in listed["py-oracle"]["params"]],
                         [("offset", "number", "0.0", "m", "a number >= -5 and <= 5 (m)")])
        self.assertEqual(listed["py-fixed"]["help"], "written in Python")
        self.assertEqual(listed["py-fixed"]["params"], [])

    def test_merge_maps_refines_and_decides_on_its_candidates(self):
        self.turn_on(ShiftOracle)
        a, b = office_windows()
        for offset in (0.0, 0.15):
            result = fleetmap.merge_maps(a, b, method="py-oracle", params={"py-oracle": {"offset": offset}})
            self.assertEqual(ShiftOracle.made[-1].offset, offset)
            self.assertTrue(result.merged, result.reason)
            self.assertEqual(result.method, "py-oracle")
            self.assertGreater(result.confidence, 0.9)
            # Three cells off (0.15 m), the refinement brings the candidate to the truth within half a cell.
            tx, ty, theta = result.transform
            self.assertAlmostEqual(tx, 3.5, delta=CELL / 2)
            self.assertAlmostEqual(ty, 0.0, delta=CELL / 2)
            self.assertAlmostEqual(theta, 0.0, delta=0.5)
            px, py, _ = result.pixel_transform
            self.assertAlmostEqual(px, 70.0, delta=0.5)
            self.assertAlmostEqual(py, 0.0, delta=0.5)
        # Two metres off is beyond the refinement's reach: the walls cross and the merge is refused,
        # the reported transform where the method put it.
        far = fleetmap.merge_maps(a, b, method="py-oracle", params={"py-oracle": {"offset": 2.0}})
        self.assertFalse(far.merged)
        self.assertIn("no reliable overlap", far.reason)
        self.assertGreater(far.transform[0] - 3.5, 1.5)
        # Once per merge: made with the merge's parameters, asked with the two maps.
        oracle = ShiftOracle.made[-1]
        self.assertEqual(oracle.offset, 2.0)
        self.assertEqual(len(oracle.seen), 1)
        seen_a, seen_b = oracle.seen[0]
        np.testing.assert_array_equal(seen_a.image, a.image)
        np.testing.assert_array_equal(seen_b.image, b.image)

    def test_its_candidates_are_metres_between_the_frames_of_the_maps_given(self):
        self.turn_on(FixedAnswer)
        a, b = office_windows()
        # b inside unknown space: 40 rows above, 10 below, 20 columns left, 30 right. The merge cuts it
        # to its known cells (with a two-cell margin); the cut's origin says where that lies in b's frame.
        padded = np.full((b.height + 50, b.width + 50), 205, np.uint8)
        padded[40:40 + b.height, 20:20 + b.width] = b.image
        b_padded = fleetmap.Map.from_image(padded)
        # b's lower-left corner is now 20 columns left of and 10 rows below the window's.
        truth = (3.5 - 20 * CELL, -10 * CELL, 0.0)
        for answer, merged in ((truth, True), ((truth[0], -truth[1], 0.0), False)):
            FixedAnswer.answer = answer
            FixedAnswer.seen.clear()
            result = fleetmap.merge_maps(a, b_padded, method="py-fixed")
            self.assertEqual(result.merged, merged, (answer, result.reason))
            self.assertEqual(FixedAnswer.seen[0], {})
            seen_b = FixedAnswer.seen[1][1]
            self.assertEqual((seen_b.width, seen_b.height), (b.width + 4, b.height + 4))
            np.testing.assert_allclose(seen_b.origin, (18 * CELL, 8 * CELL, 0.0), atol=1e-12)
            if merged:
                np.testing.assert_allclose(result.transform, truth, atol=CELL / 2)
        # b turned a quarter turn counter-clockwise: b's point p is a's R(-90 deg) p + (3.5 m, b's width).
        turned = fleetmap.Map.from_image(np.rot90(b.image).copy())
        for theta, merged in ((-math.pi / 2, True), (math.pi / 2, False)):
            FixedAnswer.answer = (3.5, b.height * CELL, theta)
            result = fleetmap.merge_maps(a, turned, method="py-fixed")
            self.assertEqual(result.merged, merged, (theta, result.reason))
            if merged:
                np.testing.assert_allclose(result.transform, (3.5, b.height * CELL, -90.0), atol=CELL / 2)
        grid = fleetmap.merge_maps(a, turned, method="grid")
        self.assertTrue(grid.merged, grid.reason)
        np.testing.assert_allclose(grid.transform, (3.5, b.height * CELL, -90.0), atol=0.05)

    def test_auto_runs_it_with_its_parameters(self):
        # Windows sharing a metre: grid's first pass is not sure of them, so auto runs every method.
        office = fleetmap.load_map("office").image
        a = fleetmap.Map.from_image(office[:, :120].copy())
        b = fleetmap.Map.from_image(office[:, 100:].copy())
        self.turn_on(ShiftOracle)
        ShiftOracle.made.clear()
        result = fleetmap.merge_maps(a, b, params={"py-oracle": {"offset": 1.5}})
        self.assertEqual([(o.offset, len(o.seen)) for o in ShiftOracle.made], [(1.5, 1)])
        self.assertTrue(result.merged, result.reason)
        self.assertAlmostEqual(result.transform[0], 5.0, delta=CELL / 2)

    def test_explore_merges_with_it_through_the_overlap_aligner(self):
        self.turn_on(GridFromPython)
        GridFromPython.calls = 0
        run = fleetmap.explore(TWO_ROBOTS, steps=30, merging={"mode": "overlap", "method": "py-grid",
                                                              "attempt_every": 5})
        self.assertGreater(GridFromPython.calls, 0)
        merged = [m for m in run.metrics["merges"] if m["merged"]]
        self.assertTrue(merged)
        self.assertEqual(merged[0]["method"], "py-grid")
        self.assertLess(merged[0]["position_error_m"], 2 * CELL)
        # Sweeps run simulations on several threads, each taking the interpreter to ask it.
        GridFromPython.calls = 0
        rows = fleetmap.sweep(maps=["office"], strategies=["coordinated"], robots=2, seeds=2, steps=30, jobs=2,
                              merging="overlap",
                              vary={"merging.method": ["py-grid"], "merging.attempt_every": [5]})
        self.assertEqual(len(rows), 2)
        self.assertGreater(GridFromPython.calls, 1)

    def test_a_bad_value_is_refused_with_its_range(self):
        a, b = office_windows()
        made = len(ShiftOracle.made)
        with self.assertRaisesRegex(ValueError, "py-oracle.*'offset'.*a number >= -5 and <= 5.*got '10'"):
            fleetmap.merge_maps(a, b, method="py-oracle", params={"py-oracle": {"offset": 10}})
        with self.assertRaisesRegex(ValueError, "py-oracle' has no parameter 'ofset'.*did you mean 'offset'"):
            fleetmap.merge_maps(a, b, method="py-oracle", params={"py-oracle": {"ofset": 1}})
        self.assertEqual(len(ShiftOracle.made), made)

    def test_an_exception_or_a_wrong_answer_names_the_method(self):
        a, b = office_windows()
        self.turn_on(RaisingMergeMethod, WrongShape)
        with self.assertRaisesRegex(fleetmap.Error, "merge method 'py-raising-merge': propose raised ValueError: "
                                                    "no idea where 130 x 200 goes"):
            fleetmap.merge_maps(a, b, method="py-raising-merge")
        with self.assertRaisesRegex(fleetmap.Error, "merge method 'py-wrong-shape': propose must return a list of "
                                                    "\\(tx, ty, theta\\) or \\(tx, ty, theta, score\\), got \\(1.0, 2.0\\)"):
            fleetmap.merge_maps(a, b, method="py-wrong-shape")

        class RefusesToStart(RaisingMergeMethod):
            def __init__(self, params):
                if RefusesToStart in MERGE_METHODS_ON:
                    raise KeyError("not today")

        fleetmap.register_merge_method("py-refuses-to-start", RefusesToStart)
        self.turn_on(RefusesToStart)
        with self.assertRaisesRegex(fleetmap.Error, "merge method 'py-refuses-to-start': making it raised KeyError"):
            fleetmap.merge_maps(a, b, method="py-refuses-to-start")

    def test_it_must_be_made_with_params_and_propose_from_two_maps(self):
        class MadeWithoutArguments(ShiftOracle):
            def __init__(self):
                pass

        with self.assertRaisesRegex(ValueError, "py-no-params.*made as cls\\(params\\)"):
            fleetmap.register_merge_method("py-no-params", MadeWithoutArguments)

        class ProposesFromOne(ShiftOracle):
            def propose(self, a):
                return []

        with self.assertRaisesRegex(ValueError, "py-one-map.*propose must take \\(a, b\\)"):
            fleetmap.register_merge_method("py-one-map", ProposesFromOne)
        self.assertNotIn("py-no-params", fleetmap.merge_method_names())
        self.assertNotIn("py-one-map", fleetmap.merge_method_names())


if __name__ == "__main__":
    unittest.main()
