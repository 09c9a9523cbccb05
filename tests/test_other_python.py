"""The round on the other Python: the suite's tests of what depends on the client's Python (the
generated message, service and action types, ``ros2cli``, the harness) run again under the other
interpreter ROS 2 Jazzy's wheels exist for (3.11 or 3.12), from its own venv.

tests/run_all sets ``MOBIL_OTHER_PYTHON_ROUND`` to that venv's interpreter and
``MOBIL_OTHER_PYTHON_TESTS`` to the test files; this test runs them there in one pytest process,
their closed-loop tests left out (``--skip-closed-loop``: the nodes' behaviour does not depend on
the client's Python and is tested once, by this run), on this worker's ROS domain, which nothing
else uses meanwhile. Marked ``last``, it runs on the worker that is not running the closed-loop
group, in the time that worker would otherwise wait for the group: the round's tests run beside
the group as this run's own tests of the same kind do. Without ``MOBIL_OTHER_PYTHON_ROUND`` (a
machine with one of the two Pythons, ``MOBIL_OTHER_PYTHON=0``) it is skipped.
"""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from harness import ROOT


@pytest.mark.last
@pytest.mark.timeout(600)
def test_the_other_pythons_round_passes(ros_domain_id: int, starting_environ: dict[str, str]):
    python = os.environ.get("MOBIL_OTHER_PYTHON_ROUND")
    if not python:
        pytest.skip("MOBIL_OTHER_PYTHON_ROUND not set (tests/run_all sets it where the machine "
                    "has the other Python)")
    files = os.environ.get("MOBIL_OTHER_PYTHON_TESTS", "").split()
    assert files, "MOBIL_OTHER_PYTHON_TESTS names no test file"
    version = subprocess.run([python, "-c", "import sys; print(sys.version_info[:2])"],
                             capture_output=True, text=True, timeout=30, check=True).stdout.strip()
    assert version != str(sys.version_info[:2]), f"{python} is this run's Python, {version}"
    # This process's starting environment without pytest's and pytest-xdist's variables (the
    # child is a pytest of its own, in one process) and on this worker's domain.
    env = {k: v for k, v in starting_environ.items() if not k.startswith("PYTEST_")}
    env.pop("ROS_DOMAIN_ID", None)
    env["MOBIL_TEST_DOMAIN_ID"] = str(ros_domain_id)
    out = subprocess.run([python, "-m", "pytest", *files, "-q", "-p", "no:cacheprovider", "-n", "0",
                          "--skip-closed-loop"],
                         cwd=ROOT, env=env, capture_output=True, text=True, timeout=560)
    summary = out.stdout.strip().splitlines()[-1:] or ["(no output)"]
    print(f"Python {version}: {summary[0]}")
    assert out.returncode == 0, (f"the round on Python {version} failed:\n"
                                 + out.stdout[-12000:] + out.stderr[-4000:])
