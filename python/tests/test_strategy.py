"""A coordination strategy written in Python: registered, run by name, benchmarked in a sweep."""
import math
import unittest

import numpy as np

import fleetmap


class CheapestFree:
    """Each robot takes the reachable target with the lowest wave cost that no teammate took."""

    calls = 0

    def assign(self, poses, targets, costs, claimed):
        CheapestFree.calls += 1
        assert poses.shape == (costs.shape[0], 3) and targets.shape == (costs.shape[1], 4)
        assert claimed.ndim == 2 and claimed.shape[1] == 2
        out, taken = [], set()
        for r in range(costs.shape[0]):
            free = [t for t in range(costs.shape[1]) if t not in taken and math.isfinite(costs[r, t])]
            best = min(free, key=lambda t: costs[r, t], default=-1)
            if best >= 0:
                taken.add(best)
            out.append(best)
        return out


class WrongLength:
    def assign(self, poses, targets, costs, claimed):
        return [0] * (len(poses) + 1)


class Recorder:
    """Takes the first reachable target; keeps what every call got (poses and the context)."""

    calls = []
    kept_context = None

    def assign(self, poses, targets, costs, claimed, context):
        gains = context.target_gains()
        between = context.target_costs()
        Recorder.calls.append((poses.copy(), context.team_indices.copy(), context.team_size, context.sensor_range,
                               context.params["beta"], targets.shape[0], between, gains))
        Recorder.kept_context = context
        return [next((t for t in range(costs.shape[1]) if math.isfinite(costs[r, t])), -1)
                for r in range(costs.shape[0])]


fleetmap.register_strategy("py-cheapest", CheapestFree, help="cheapest free target (a Python test's own)")
fleetmap.register_strategy("py-wrong", WrongLength)
fleetmap.register_strategy("py-recorder", Recorder,
                           params={"beta": {"default": 1.0, "min": 0, "doc": "weight of travel cost"}})


class PythonStrategyTest(unittest.TestCase):
    def test_a_registered_strategy_runs_by_name(self):
        self.assertIn("py-cheapest", fleetmap.strategy_names())
        before = CheapestFree.calls
        run = fleetmap.explore(map="office", robots=2, steps=60, seed=1, strategy="py-cheapest")
        self.assertGreater(CheapestFree.calls, before)
        self.assertEqual(run.metrics["strategy"], "py-cheapest")
        self.assertGreater(run.coverage[-1], run.coverage[0] + 0.05)

    def test_it_is_benchmarked_like_the_built_in_ones(self):
        rows = fleetmap.sweep(maps=["empty"], strategies=["py-cheapest", "coordinated"], robots=2, seeds=2,
                              steps=30, jobs=2)
        self.assertEqual([(r["strategy"], r["seed"]) for r in rows],
                         [("py-cheapest", 1), ("py-cheapest", 2), ("coordinated", 1), ("coordinated", 2)])
        for r in rows:
            self.assertEqual((r["map"], r["robots"], r["steps"]), ("empty", 2, 30))
            self.assertGreater(r["coverage"], 0.0)
        # The sweep's run is the run explore() makes of the same scenario.
        alone = fleetmap.explore(map="empty", robots=2, steps=30, seed=1, strategy="py-cheapest")
        self.assertAlmostEqual(rows[0]["coverage"], alone.metrics["coverage"], places=5)

    def test_it_gets_headings_and_the_context(self):
        starts = [[1.0, 1.0, 40.0], [8.5, 8.5, -115.0]]  # x, y in metres, heading in degrees
        run = fleetmap.explore(map="office", robots={"starts": starts}, steps=40, seed=1,
                               strategy={"name": "py-recorder", "beta": 0.7}, sensors={"range": {"max_range": 3.5}})
        self.assertGreater(len(Recorder.calls), 1)
        first_poses, first_indices = Recorder.calls[0][0], Recorder.calls[0][1]
        # The first round gets the start poses, headings included (in radians).
        for row, robot in zip(first_poses, first_indices):
            np.testing.assert_allclose(row, [starts[robot][0], starts[robot][1], math.radians(starts[robot][2])],
                                       atol=1e-9)
        turned = False
        for poses, indices, team_size, sensor_range, beta, targets, between, gains in Recorder.calls:
            self.assertEqual((team_size, sensor_range, beta), (2, 3.5, 0.7))
            self.assertTrue(set(indices.tolist()) <= {0, 1})
            # Every pose a robot was given is one it held (ideal localization: the estimates are the truth).
            for row, robot in zip(poses, indices):
                track = run.estimates[robot]
                self.assertTrue(np.any(np.all(np.abs(track - row) < 1e-9, axis=1)), (robot, row))
                self.assertTrue(-math.pi < row[2] <= math.pi)
                turned = turned or abs(row[2] - math.radians(starts[robot][2])) > 0.1
            self.assertEqual(between.shape, (targets, targets))
            self.assertTrue(np.all(np.diag(between) == 0.0))
            self.assertEqual(gains.shape, (targets,))
            self.assertTrue(np.all(gains >= 0.0))
        self.assertTrue(turned)
        with self.assertRaisesRegex(RuntimeError, "only while assign runs"):
            Recorder.kept_context.target_costs()

    def test_its_parameters_are_declared_and_checked(self):
        listed = {s["name"]: s for s in fleetmap.strategies()}
        self.assertEqual([p["name"] for p in listed["coordinated"]["params"]], ["beta"])
        self.assertEqual([(p["name"], p["default"], p["accepts"]) for p in listed["py-recorder"]["params"]],
                         [("beta", "1.0", "a number >= 0")])
        self.assertEqual(listed["market"]["params"], [])
        with self.assertRaisesRegex(ValueError, "py-recorder' has no parameter 'bta'.*did you mean 'beta'"):
            fleetmap.explore(map="empty", robots=1, steps=5, strategy={"name": "py-recorder", "bta": 1})
        with self.assertRaisesRegex(ValueError, "'beta'.*>= 0.*got '-2'"):
            fleetmap.explore(map="empty", robots=1, steps=5, strategy={"name": "py-recorder", "beta": -2})
        with self.assertRaisesRegex(ValueError, "py-bad-param.*'beta' needs a default"):
            fleetmap.register_strategy("py-bad-param", CheapestFree, params={"beta": {"min": 0}})

    def test_a_localizers_parameters_are_listed_and_set_like_a_strategys(self):
        listed = {s["name"]: s for s in fleetmap.localizers()}
        self.assertEqual([(p["name"], p["default"]) for p in listed["rbpf"]["params"]],
                         [("particles", "30"), ("sample_motion", "true"), ("linear_update", "0.3"),
                          ("angular_update", "0.1")])
        self.assertEqual(listed["ekf"]["params"], [])
        run = fleetmap.explore(map="empty", robots=1, steps=5, localization={"name": "rbpf", "particles": 2})
        self.assertEqual(run.steps, 5)
        with self.assertRaisesRegex(ValueError, "localization.particles.*a whole number from 1"):
            fleetmap.explore(map="empty", robots=1, steps=5, localization={"name": "rbpf", "particles": 0})
        aligners = {a["name"]: a for a in fleetmap.map_aligners()}
        self.assertEqual([(p["name"], p["default"]) for p in aligners["overlap"]["params"]],
                         [("method", "auto"), ("min_confidence", "0.5")])

    def test_assign_must_take_the_four_arrays(self):
        class TooFew:
            def assign(self, poses, targets):
                return []

        with self.assertRaisesRegex(ValueError, "py-too-few.*poses, targets, costs, claimed"):
            fleetmap.register_strategy("py-too-few", TooFew)
        self.assertNotIn("py-too-few", fleetmap.strategy_names())

    def test_a_bad_answer_is_reported(self):
        with self.assertRaisesRegex(RuntimeError, "py-wrong.*3 targets for 2 robots"):
            fleetmap.explore(map="empty", robots=2, steps=10, strategy="py-wrong")
        with self.assertRaisesRegex(RuntimeError, "already registered"):
            fleetmap.register_strategy("py-cheapest", CheapestFree)
        with self.assertRaisesRegex(ValueError, "no assign method"):
            fleetmap.register_strategy("py-none", object)


if __name__ == "__main__":
    unittest.main()
