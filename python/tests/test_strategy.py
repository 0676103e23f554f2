"""A coordination strategy written in Python: registered, run by name, benchmarked in a sweep."""
import math
import unittest

import numpy as np

import fleetmap


class CheapestFree:
    """Each robot takes the reachable target with the lowest wave cost that no teammate took."""

    calls = 0

    def assign(self, positions, targets, costs, claimed):
        CheapestFree.calls += 1
        assert positions.shape == (costs.shape[0], 2) and targets.shape == (costs.shape[1], 4)
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
    def assign(self, positions, targets, costs, claimed):
        return [0] * (len(positions) + 1)


fleetmap.register_strategy("py-cheapest", CheapestFree, help="cheapest free target (a Python test's own)")
fleetmap.register_strategy("py-wrong", WrongLength)


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

    def test_a_bad_answer_is_reported(self):
        with self.assertRaisesRegex(RuntimeError, "py-wrong.*3 targets for 2 robots"):
            fleetmap.explore(map="empty", robots=2, steps=10, strategy="py-wrong")
        with self.assertRaisesRegex(RuntimeError, "already registered"):
            fleetmap.register_strategy("py-cheapest", CheapestFree)
        with self.assertRaisesRegex(ValueError, "no assign method"):
            fleetmap.register_strategy("py-none", object)


if __name__ == "__main__":
    unittest.main()
