"""The fleetmap program beside the package, run as a user runs it (for tests that compare the two)."""
import os
import subprocess
from pathlib import Path

import fleetmap

# ctest names the program; from a build tree it is beside the package's folder (build/python/fleetmap).
PROGRAM = Path(os.environ.get("FLEETMAP_BINARY") or Path(fleetmap.__file__).resolve().parents[2] / "fleetmap")


def run_fleetmap(*args, cwd):
    """fleetmap's exit code, stdout and stderr for `args` run in `cwd`."""
    if not PROGRAM.is_file():
        raise AssertionError(f"no fleetmap program at {PROGRAM}; set FLEETMAP_BINARY")
    done = subprocess.run([str(PROGRAM), *map(str, args)], cwd=cwd, capture_output=True, text=True, timeout=300)
    return done.returncode, done.stdout, done.stderr
