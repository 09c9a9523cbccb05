"""The round on the other Python: the suite's tests of what depends on the client's Python (the
generated message, service and action types, ``ros2cli``, the harness) run again under the other
interpreter ROS 2 Jazzy's wheels exist for (3.11 or 3.12), from its own venv.

tests/run_all sets ``MOBIL_OTHER_PYTHON_ROUND`` to that venv's interpreter and
``MOBIL_OTHER_PYTHON_TESTS`` to the test files; this test runs them there in one pytest process,
their closed-loop tests left out (``--skip-closed-loop``: the nodes' behaviour does not depend on
the client's Python and is tested once, by this run), on this worker's ROS domain, which nothing
else uses meanwhile. Marked ``last``, it is queued after every other test: pytest-xdist hands the
closed-loop group's worker more work only near the group's end, so the round normally runs on the
other worker, in the time it would otherwise wait for the group, beside the group as this run's
own tests of the same kind do (on a run whose group ends first, it follows the group on that
worker). Without ``MOBIL_OTHER_PYTHON_ROUND`` (a machine with one of the two Pythons,
``MOBIL_OTHER_PYTHON=0`` or ``all``) it is skipped.
"""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from harness import ROOT


@pytest.mark.last
@pytest.mark.timeout(600)
def test_the_other_pythons_round_passes(ros_domain_id: int, starting_environ: dict[str, str]):
    python = os.environ.get("MOBIL_OTHER_PYTHON_ROUND")
    if not python:
        pytest.skip("MOBIL_OTHER_PYTHON_ROUND not set (tests/run_all sets it for its round on the "
                    "other Python, unless MOBIL_OTHER_PYTHON is 0 or all)")
    files = os.environ.get("MOBIL_OTHER_PYTHON_TESTS", "").split()
    assert files, "MOBIL_OTHER_PYTHON_TESTS names no test file"
    version = subprocess.run([python, "-c", "import sys; print(sys.version_info[:2])"],
                             capture_output=True, text=True, timeout=30, check=True).stdout.strip()
    assert version != str(sys.version_info[:2]), f"{python} is this run's Python, {version}"
    # The run's starting environment without pytest's and pytest-xdist's variables (the child is
    # a pytest of its own, in one process) and on this worker's domain.
    env = {k: v for k, v in starting_environ.items() if not k.startswith("PYTEST_")}
    for key in ("ROS_DOMAIN_ID", "MOBIL_OTHER_PYTHON_ROUND", "MOBIL_OTHER_PYTHON_TESTS"):
        env.pop(key, None)
    env["MOBIL_TEST_DOMAIN_ID"] = str(ros_domain_id)
    # Nothing of this Python's type support: the child must load its own (test_messages.py checks
    # where it came from).
    leaked = [p for key in ("PYTHONPATH", "LD_LIBRARY_PATH")
              for p in env.get(key, "").split(os.pathsep) if "msgs-install-py" in p]
    assert not leaked, leaked
    # Its own session: on a timeout the child pytest and the nodes it started are stopped.
    child = subprocess.Popen([python, "-m", "pytest", *files, "-q", "-p", "no:cacheprovider", "-n", "0",
                              "--skip-closed-loop"],
                             cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                             start_new_session=True)
    try:
        stdout, stderr = child.communicate(timeout=560)
    except subprocess.TimeoutExpired:
        os.killpg(child.pid, signal.SIGINT)
        try:
            stdout, stderr = child.communicate(timeout=15)
        except subprocess.TimeoutExpired:
            os.killpg(child.pid, signal.SIGKILL)
            stdout, stderr = child.communicate()
        pytest.fail(f"the round on Python {version} did not end within 560 s:\n{stdout[-12000:]}{stderr[-4000:]}")
    summary = stdout.strip().splitlines()[-1:] or ["(no output)"]
    print(f"Python {version}: {summary[0]}")
    assert child.returncode == 0, (f"the round on Python {version} failed:\n"
                                   + stdout[-12000:] + stderr[-4000:])
