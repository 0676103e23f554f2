"""`import fleetmap` where the source folder python/fleetmap shadows the built package."""
import os
import subprocess
import sys
import unittest
from pathlib import Path

import fleetmap

SOURCE = Path(__file__).resolve().parents[1]  # python/, which holds the source package fleetmap/
BUILT = Path(fleetmap.__file__).resolve().parents[1]  # the folder that holds the built package


def python_in_source_folder(pythonpath):
    env = {k: v for k, v in os.environ.items() if k != "PYTHONPATH"}
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    return subprocess.run([sys.executable, "-c", "import fleetmap; print(fleetmap.map_names()[0])"], cwd=SOURCE,
                          env=env, capture_output=True, text=True, timeout=120)


class ImportTest(unittest.TestCase):
    def test_inside_the_source_folder_the_built_package_on_the_path_is_used(self):
        self.assertNotEqual(BUILT, SOURCE)
        done = python_in_source_folder(str(BUILT))
        self.assertEqual(done.returncode, 0, done.stderr)
        self.assertEqual(done.stdout.strip(), "empty")

    def test_inside_the_source_folder_without_the_built_package_one_line_says_what_to_do(self):
        done = python_in_source_folder("")
        self.assertNotEqual(done.returncode, 0)
        last = done.stderr.strip().splitlines()[-1]
        self.assertIn("is fleetmap's source folder, not the package the build makes", last)
        self.assertIn("PYTHONPATH=<build folder>/python", last)


if __name__ == "__main__":
    unittest.main()
