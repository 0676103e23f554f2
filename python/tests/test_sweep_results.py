"""Sweeps run from Python give the results `fleetmap bench` gives, in files every bench verb reads."""
import csv
import tempfile
import unittest
from pathlib import Path

import numpy as np

import fleetmap
from cli_support import run_fleetmap

SPEC = {"maps": ["office"], "strategies": ["coordinated", "uncoordinated"], "robots": [2], "seeds": 2, "steps": 60}
FLAGS = ["--maps", "office", "--strategies", "coordinated,uncoordinated", "--robots", "2", "--seeds", "2",
         "--steps", "60", "--jobs", "1", "-q"]


def without_wall_time(path):
    """results.csv's lines without the wall_time_s column (the only one two runs of a key differ in)."""
    rows = list(csv.reader(path.read_text().splitlines()))
    drop = rows[0].index("wall_time_s")
    return [row[:drop] + row[drop + 1:] for row in rows]


class SweepResultsTest(unittest.TestCase):
    def setUp(self):
        self.folder = Path(self.enterContext(tempfile.TemporaryDirectory()))
        code, _, err = run_fleetmap("bench", *FLAGS, "--out", "cpp", cwd=self.folder)
        self.assertEqual(code, 0, err)

    def bench(self, *args):
        code, out, err = run_fleetmap("bench", *args, cwd=self.folder)
        self.assertEqual(code, 0, f"bench {' '.join(args)}: {err}")
        return out

    def assert_read_by_every_bench_verb_as_the_commands_sweep(self, folder):
        self.assertEqual(without_wall_time(self.folder / folder / "results.csv"),
                         without_wall_time(self.folder / "cpp" / "results.csv"))
        for metric in ("coverage", "distance_m"):
            self.assertEqual(self.bench("--compare", "coordinated", "uncoordinated", folder, "--metric", metric),
                             self.bench("--compare", "coordinated", "uncoordinated", "cpp", "--metric", metric))
        self.bench("--combine", folder, "--out", f"combined_{folder}")
        self.bench("--combine", "cpp", "--out", "combined_cpp")
        for table in ("summary.md", "summary.csv"):
            self.assertEqual((self.folder / f"combined_{folder}" / table).read_text(),
                             (self.folder / "combined_cpp" / table).read_text(), table)

    def test_a_sweeps_folder_is_benchs_folder(self):
        rows = fleetmap.sweep(SPEC, out=self.folder / "py")
        self.assertEqual(len(rows), 4)
        for name in ("results.csv", "summary.md", "summary.csv", "report.html", "coverage_office.png", "sweep.yaml",
                     "scenario.yaml"):
            self.assertTrue((self.folder / "py" / name).is_file(), name)
        self.assertEqual((self.folder / "py" / "sweep.yaml").read_text(), (self.folder / "cpp" / "sweep.yaml").read_text())
        self.assertEqual((self.folder / "py" / "summary.md").read_text(), (self.folder / "cpp" / "summary.md").read_text())
        self.assert_read_by_every_bench_verb_as_the_commands_sweep("py")

    def test_saved_rows_are_benchs_rows(self):
        rows = fleetmap.sweep(SPEC)
        self.assertIs(rows[0]["finished"], False)  # Python values, written back in bench's spelling
        fleetmap.save_results(rows, self.folder / "saved" / "results.csv")
        self.assert_read_by_every_bench_verb_as_the_commands_sweep("saved")

    def test_rows_written_with_pythons_csv_module_are_read_too(self):
        rows = fleetmap.sweep(SPEC)
        (self.folder / "dictwriter").mkdir()
        with open(self.folder / "dictwriter" / "results.csv", "w", newline="") as f:  # CR LF, True, 4.0
            writer = csv.DictWriter(f, fieldnames=list(rows[0]))
            writer.writeheader()
            writer.writerows(rows)
        self.assertEqual(self.bench("--compare", "coordinated", "uncoordinated", "dictwriter", "--metric", "coverage"),
                         self.bench("--compare", "coordinated", "uncoordinated", "cpp", "--metric", "coverage"))

    def test_a_sweep_of_a_python_strategy_gets_benchs_comparison_and_reports(self):
        class Nearest:
            def assign(self, poses, targets, costs, claimed):
                return [int(np.argmin(c)) if np.isfinite(c).any() else -1 for c in costs]

        fleetmap.register_strategy("py-nearest-results", Nearest)
        fleetmap.sweep(dict(SPEC, strategies=["py-nearest-results", "coordinated"]), out=self.folder / "mine")
        out = self.bench("--compare", "py-nearest-results", "coordinated", "mine", "--metric", "coverage")
        self.assertIn("| office | 2 | 2 |", out)
        # This program has no such strategy, so the folder's sweep.yaml does not load here: a note
        # says so, and the reports are made from the rows.
        code, out, err = run_fleetmap("bench", "--combine", "mine", "--out", "reports", cwd=self.folder)
        self.assertEqual(code, 0, err)
        self.assertIn("unknown strategy 'py-nearest-results'", err)
        self.assertIn("py-nearest-results", (self.folder / "reports" / "summary.md").read_text())
        self.assertTrue((self.folder / "reports" / "report.html").is_file())

    def test_bad_rows_are_refused_naming_the_row_and_column(self):
        rows = fleetmap.sweep(SPEC)
        with self.assertRaisesRegex(fleetmap.InputError, r"save_results: rows\[1\]: column 'finished': expected true or false, got 'maybe'"):
            fleetmap.save_results([rows[0], dict(rows[1], finished="maybe")], self.folder / "bad.csv")
        with self.assertRaisesRegex(fleetmap.InputError, r"save_results: rows\[0\]: no column 'seed'"):
            fleetmap.save_results([{k: v for k, v in rows[0].items() if k != "seed"}], self.folder / "bad.csv")
        self.assertFalse((self.folder / "bad.csv").exists())
        # An output folder holding a user's file is not taken.
        (self.folder / "mine").mkdir()
        (self.folder / "mine" / "notes.txt").write_text("mine")
        with self.assertRaisesRegex(fleetmap.InputError, "mine"):
            fleetmap.sweep(SPEC, out=self.folder / "mine")
        self.assertEqual((self.folder / "mine" / "notes.txt").read_text(), "mine")


if __name__ == "__main__":
    unittest.main()
