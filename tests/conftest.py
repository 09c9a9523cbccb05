"""pytest fixtures for mobil's ROS 2 tests (see harness.py for the helpers).

Fixtures:
* ``ros_domain_id`` (session): the ROS_DOMAIN_ID of this run, random in 100..199 unless
  MOBIL_TEST_DOMAIN_ID is set (under pytest-xdist: one domain per worker, the base plus the
  worker's number); it is put in os.environ before rclpy starts and is inherited by
  every child process.
* ``starting_environ`` (session): this process's environment as it started (before this file
  set the domain and this Python's type-support paths), for a child on another Python.
* ``rclpy_context`` (session): one ``rclpy.init()`` for the run.
* ``spinner``: a background executor for the test; fails the test if a callback raised.
* ``ros_node``: a fresh rclpy node per test, spun by ``spinner``.
* ``start_node``: factory ``start_node(exe, *ros_args, params_file=None, name=None, ...)`` that
  launches a node executable and stops it at teardown (SIGINT, 5 s, else kill and fail).
* ``ros2cli``: ``ros2cli(*args, timeout=30)`` runs tests/ros2cli.py in the test's domain.
* ``start_scenario``: factory ``start_scenario(params_file, real_time_factor=R, nodes=(...),
  sim_args=(), node_args=(), lidar=False)`` (harness.launch_scenario on ``start_node``):
  ``sim_node`` publishing ``/clock`` at R× real time and the nodes on ``use_sim_time``.
* ``sim_clock``: a ``harness.SimClock`` on the test's node (``wait_started``, ``now``,
  ``wait_until``, ``factor``).

Options: ``--skip-closed-loop`` leaves the closed-loop tests out (the other Python's round).
Order: the closed-loop group first, then the other tests, those marked ``last`` at the end.

Environment: MOBIL_BIN_DIR (default target/release), MOBIL_TEST_DOMAIN_ID,
MOBIL_FASTDDS_VERBOSITY (Fast DDS's own log level in the test process: 1 = warnings;
its warnings about discovery and QoS are otherwise hidden); the Fast DDS profile,
RMW implementation and mobil_msgs paths are set here (rosutil.setup_process_environment).
"""

from __future__ import annotations

import itertools
import json
import os
import random
from collections.abc import Iterator
from pathlib import Path
from typing import Any, Callable

import pytest

import harness
import rosutil


def _choose_domain_id() -> int:
    # Under pytest-xdist (tests/run_all runs two workers) each worker is a process with a domain
    # of its own, so one worker's nodes never answer another's tests: the run's base domain (the
    # same for every worker: from the run's id) plus the worker's number (gw0, gw1, ...).
    worker = os.environ.get("PYTEST_XDIST_WORKER", "")
    index = int(worker[2:]) if worker.startswith("gw") and worker[2:].isdigit() else 0
    value = os.environ.get("MOBIL_TEST_DOMAIN_ID")
    if value:
        return int(value) + index
    run_id = os.environ.get("PYTEST_XDIST_TESTRUNUID")
    if run_id:
        return 100 + int(run_id[:8], 16) % (100 - 8) + index
    return random.SystemRandom().randrange(100, 200)


# The environment the test run was started with, before the lines below change it: what a test
# that starts another Python's pytest (test_other_python.py) hands on, without this Python's
# type-support paths. Recorded by the first process that loads this file (under pytest-xdist the
# controller, whose changed environment the workers inherit) and passed on to the workers.
_STARTING_KEY = "MOBIL_TEST_STARTING_ENVIRON"
if _STARTING_KEY not in os.environ:
    os.environ[_STARTING_KEY] = json.dumps(dict(os.environ))
STARTING_ENVIRON: dict[str, str] = json.loads(os.environ[_STARTING_KEY])

# Before anything can start rclpy: the domain and the process environment.
DOMAIN_ID = _choose_domain_id()
os.environ["ROS_DOMAIN_ID"] = str(DOMAIN_ID)
rosutil.setup_process_environment()

_node_counter = itertools.count(1)


def pytest_report_header(config: pytest.Config) -> list[str]:
    return [f"mobil: ROS_DOMAIN_ID={DOMAIN_ID} RMW={os.environ.get('RMW_IMPLEMENTATION')} "
            f"bin dir={harness.BIN_DIR}",
            f"mobil: FASTRTPS_DEFAULT_PROFILES_FILE={os.environ.get('FASTRTPS_DEFAULT_PROFILES_FILE')}"]


# Closed-loop scenarios: a simulation at several times real time with the nodes under test in
# its loop (the fixtures that start one, or the ``closed_loop`` marker, tests/pytest.ini, also on
# a real-time drive whose legs the test times itself). Under pytest-xdist (tests/run_all: two workers, ``--dist loadgroup``) they form one
# group, run one after another on one worker, first, while the other worker takes every other
# test: two such loops on two cores each lose the CPU to the other now and then, and at 5x real
# time a 20 ms stall of the navigator is 0.1 simulated seconds of driving on an old command (a
# U-trap run touched its wall that way). Every other test is its own unit of work.
CLOSED_LOOP_FIXTURES = frozenset({"start_scenario", "sim_clock"})
CLOSED_LOOP_GROUP = "closed_loop"


def is_closed_loop(item: pytest.Item) -> bool:
    return (item.get_closest_marker("closed_loop") is not None
            or bool(CLOSED_LOOP_FIXTURES.intersection(getattr(item, "fixturenames", ()))))


def pytest_addoption(parser: pytest.Parser) -> None:
    parser.addoption("--skip-closed-loop", action="store_true",
                     help="leave out the closed-loop tests (the other Python's round, "
                          "test_other_python.py: the nodes' behaviour is tested once)")


# tryfirst: pytest-xdist's own hook (registered later, so called earlier by default) turns the
# xdist_group markers into the group suffix of each test id; it must find them set.
@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    if config.getoption("skip_closed_loop"):
        left_out = [item for item in items if is_closed_loop(item)]
        if left_out:
            config.hook.pytest_deselected(items=left_out)
            items[:] = [item for item in items if not is_closed_loop(item)]
    # The closed-loop group first, the tests marked ``last`` at the end, the others between.
    # Stable: within each part the collection order stays (every worker collects the same).
    items.sort(key=lambda item: (not is_closed_loop(item), item.get_closest_marker("last") is not None))
    for item in items:
        if is_closed_loop(item):
            item.add_marker(pytest.mark.xdist_group(CLOSED_LOOP_GROUP))


@pytest.hookimpl(hookwrapper=True)
def pytest_runtest_makereport(item: pytest.Item, call: pytest.CallInfo) -> Iterator[None]:
    """On failure, attach the log tail of every node process the test started."""
    outcome = yield
    report = outcome.get_result()
    setattr(item, f"rep_{report.when}", report)
    if report.failed:
        for proc in getattr(item, "_mobil_node_processes", []):
            report.sections.append((f"node log: {proc.name} ({proc.log_path})",
                                    proc.log_tail(60)))


@pytest.fixture(scope="session")
def ros_domain_id() -> int:
    return DOMAIN_ID


@pytest.fixture(scope="session")
def starting_environ() -> dict[str, str]:
    """This process's environment as it started, before conftest.py set the domain and the paths
    of this Python's type support (a copy)."""
    return dict(STARTING_ENVIRON)


@pytest.fixture(scope="session")
def rclpy_context(ros_domain_id: int) -> Iterator[Any]:
    import rclpy
    from rclpy.signals import SignalHandlerOptions
    # No rclpy signal handlers: Ctrl-C stays pytest's KeyboardInterrupt.
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    if os.environ.get("MOBIL_FASTDDS_VERBOSITY"):
        import ctypes
        lib = ctypes.CDLL("libfastrtps.so.2.14")
        getattr(lib, "_ZN8eprosima7fastdds3dds3Log12SetVerbosityENS2_4KindE")(
            int(os.environ["MOBIL_FASTDDS_VERBOSITY"]))
    from rclpy.utilities import get_default_context
    yield get_default_context()
    rclpy.try_shutdown()


@pytest.fixture
def spinner(rclpy_context: Any) -> Iterator[rosutil.Spinner]:
    spin = rosutil.Spinner(context=rclpy_context).start()
    yield spin
    spin.stop()
    if spin.errors:
        raise AssertionError(f"{len(spin.errors)} rclpy callback(s) raised: "
                             + "; ".join(repr(e) for e in spin.errors))


@pytest.fixture
def ros_node(spinner: rosutil.Spinner) -> Any:
    """A fresh rclpy node, spun in the background; other nodes: ``spinner.add_node(n, own=True)``."""
    import rclpy
    node = rclpy.create_node(f"mobil_test_{next(_node_counter)}")
    return spinner.add_node(node, own=True)


@pytest.fixture
def start_node(request: pytest.FixtureRequest, tmp_path: Path) -> Iterator[Callable[..., harness.NodeProcess]]:
    """``start_node(exe, *ros_args, params_file=None, name=None, args=(), env=None,
    check_exit_code=True) -> NodeProcess``; every started process is stopped at teardown."""
    started: list[harness.NodeProcess] = []
    request.node._mobil_node_processes = started

    def start(exe: str, *ros_args: str, params_file: Any = None, name: str | None = None,
              **kwargs: Any) -> harness.NodeProcess:
        proc = harness.launch_node(exe, *ros_args, log_dir=tmp_path / "logs",
                                   params_file=params_file, name=name, **kwargs)
        started.append(proc)
        return proc

    yield start
    errors = []
    for proc in reversed(started):
        try:
            proc.stop()
        except harness.NodeProcessError as exc:
            errors.append(str(exc))
    if errors:
        pytest.fail("\n\n".join(errors), pytrace=False)


@pytest.fixture
def ros2cli() -> Callable[..., Any]:
    """``ros2cli('topic', 'echo', '/odom', '--once', timeout=30) -> CompletedProcess``."""
    return harness.run_ros2cli


@pytest.fixture
def start_scenario(start_node: Callable[..., harness.NodeProcess]) -> Callable[..., list[harness.NodeProcess]]:
    """``start_scenario(params_file, real_time_factor=R, ...) -> [sim, *nodes]``; see
    harness.launch_scenario. Stopped at teardown with the other started nodes."""
    def start(params_file: Any, **kwargs: Any) -> list[harness.NodeProcess]:
        return harness.launch_scenario(params_file, launch=start_node, **kwargs)
    return start


@pytest.fixture
def sim_clock(ros_node: Any) -> Iterator[harness.SimClock]:
    """The test node's view of ``/clock`` (see harness.SimClock)."""
    with harness.SimClock(ros_node) as clock:
        yield clock
