import json
import subprocess
import sys

import numpy as np
import pytest

# The paper's generic model (Section 4.4).
GENERIC_F = np.array([[0.9, 0.8, 0.7], [0.01, 0.1, 0.3], [0.0, 0.25, 0.1]])
GENERIC_G = np.array([[0.6], [0.1], [0.25]])
GENERIC_Z_STAR = np.array([19.933888, 19.999998, 20.000000, 16.339275, 20.000000])


@pytest.fixture
def generic_plant():
    import robustctl as rc

    return rc.Plant(GENERIC_F, GENERIC_G, dt=0.1)


def random_plant(rng, n, m, scale=1.0):
    """A random discrete plant (stabilisable with probability one)."""
    import robustctl as rc

    return rc.Plant(scale * rng.standard_normal((n, n)) / np.sqrt(n), rng.standard_normal((n, m)), dt=0.1)


# One interpreter for many `python -m moo` command lines (a user module is importable through PYTHONPATH).
_MANY = """
import contextlib, io, json, sys
from moo.__main__ import main
out = []
for argv in json.loads(sys.argv[1]):
    err, so = io.StringIO(), io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(so):
        code = main(argv)
    out.append([code, err.getvalue(), so.getvalue()])
print(json.dumps(out))
"""


def main_many(argvs, env, cwd):
    """``moo.__main__.main(argv)`` for each argv in one fresh interpreter: [(exit code, stderr, stdout), ...]."""
    proc = subprocess.run([sys.executable, "-c", _MANY, json.dumps(argvs)], env=env, cwd=cwd, capture_output=True,
                          text=True, timeout=300, check=False)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout.splitlines()[-1])
