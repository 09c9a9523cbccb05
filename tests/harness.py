"""Test harness for mobil's ROS 2 nodes: processes, topics, parameters.

The pytest fixtures in conftest.py wrap these; they can also be used on their own (a script that
called ``rosutil.setup_process_environment()``, ``rclpy.init()`` and spins its node with
``rosutil.Spinner``).

* ``NodeProcess`` / ``launch_node``: run an executable (a Rust node from ``MOBIL_BIN_DIR``) with
  ``--ros-args``, log its output to a file, stop it with SIGINT and check that it exits.
* ``wait_for_message``, ``collect``, ``subscribe``, ``publish_until``: topic helpers that wait
  for actual messages, never for a fixed time.
* ``param_get``, ``param_set``, ``param_list``: the rcl_interfaces parameter services, with
  retries (shared with tests/ros2cli.py through rosutil).
* ``run_ros2cli``: run tests/ros2cli.py as a subprocess in the test's ROS domain.
* ``launch_scenario``, ``SimClock``, ``publish_on_sim_time``: closed-loop scenarios faster than
  real time. ``launch_scenario`` starts ``sim_node`` with ``publish_clock:=true`` and
  ``real_time_factor:=R`` and the other nodes with ``use_sim_time:=true`` (one params file for
  all), returning the processes; ``SimClock`` follows ``/clock`` (``wait_started``, ``now``,
  ``wait_until(T)`` in simulated seconds, ``factor()``: simulated seconds per wall second since
  it started or since a ``mark()``, for a test to assert; ``max_gap``: the longest wall-clock
  pause of the clock); ``publish_on_sim_time`` sends a command every P simulated seconds (and at
  least every 0.1 wall seconds, so the nodes' steady-clock watchdogs never see a gap) until
  simulated time T.
"""

from __future__ import annotations

import atexit
import math
import os
import re
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, Optional, Union

import rosutil
from rosutil import (  # noqa: F401  (re-exported for tests)
    ROOT, TESTS_DIR, ServiceUnavailable, TopicRecorder, import_type, make_qos, message_to_yaml,
    qos_default, qos_latched, qos_sensor, set_message_fields, wait_for_node, wait_until)

__all__ = [
    "BIN_DIR", "CLEAN_EXIT_CODES", "MIN_REAL_TIME_FACTOR", "NodeProcess", "NodeProcessError",
    "ROOT", "ROS2CLI",
    "ServiceUnavailable", "SimClock", "TESTS_DIR", "TopicRecorder", "collect", "import_type",
    "launch_node", "launch_scenario", "make_qos", "message_to_yaml", "param_get", "param_list",
    "param_set", "publish_on_sim_time", "publish_until", "qos_default", "qos_latched",
    "qos_sensor", "resolve_executable", "run_ros2cli", "set_message_fields", "subscribe",
    "wait_for_message", "wait_for_node", "wait_until", "OdomFeed", "OpenSpaceScan", "odom_at",
    "stamped_pose",
]

BIN_DIR = Path(os.environ.get("MOBIL_BIN_DIR", str(ROOT / "target" / "release")))
ROS2CLI = TESTS_DIR / "ros2cli.py"

# Exit codes accepted after SIGINT: a clean exit, or death by the signal itself.
CLEAN_EXIT_CODES = (0, -signal.SIGINT, 128 + signal.SIGINT)
STOP_TIMEOUT = 5.0

_live_processes: list["NodeProcess"] = []


def thread_stacks(pid: int, timeout: float = 20.0) -> str:
    """Every thread's backtrace of a running process (gdb in batch mode), for the report of a
    process that hangs; a line saying why when gdb is missing or cannot attach."""
    if shutil.which("gdb") is None:
        return "(gdb is not installed: no backtraces)"
    try:
        out = subprocess.run(["gdb", "-p", str(pid), "-batch", "-nx", "-ex", "set pagination off",
                              "-ex", "thread apply all bt 12"],
                             capture_output=True, text=True, timeout=timeout)
    except subprocess.TimeoutExpired:
        return f"(gdb did not finish within {timeout:g} s)"
    lines = [line for line in out.stdout.splitlines()
             if line.startswith(("Thread ", "#"))]
    return "\n".join(lines[-400:]) or f"(gdb could not attach: {out.stderr.strip()[-300:]})"

class NodeProcessError(AssertionError):
    """A node process misbehaved: did not stop on SIGINT, crashed, or exited early."""


class NodeProcess:
    """A running node executable with its output in a log file.

    Use ``stop()`` (SIGINT, then wait up to 5 s; SIGKILL only as a last resort, which is an
    error) or ``wait()`` for a process expected to exit by itself. ``stop()`` raises
    ``NodeProcessError`` if the process had to be killed, exited with an unclean code, or had
    already exited by itself before (a crash) unless the test collected it with ``wait()``.
    """

    def __init__(self, cmd: Sequence[str], log_path: Path, env: dict[str, str],
                 name: str, check_exit_code: bool = True, cwd: Optional[Path] = None) -> None:
        self.cmd = list(cmd)
        self.name = name
        self.log_path = log_path
        self.check_exit_code = check_exit_code
        self.returncode: Optional[int] = None
        self.stopped = False  # stop() or wait() has collected the process
        self.killed = False
        log_path.parent.mkdir(parents=True, exist_ok=True)
        self._log = open(log_path, "wb")
        prefix: list[str] = []
        if shutil.which("setpriv"):
            # Killed with pytest even if pytest itself is killed (no orphans).
            prefix = ["setpriv", "--pdeathsig", "KILL", "--"]
        self.proc = subprocess.Popen(
            prefix + self.cmd, stdin=subprocess.DEVNULL, stdout=self._log,
            stderr=subprocess.STDOUT, env=env, cwd=str(cwd or ROOT), start_new_session=True)
        self.pid = self.proc.pid
        self.started_at = time.monotonic()
        _live_processes.append(self)

    def __repr__(self) -> str:
        state = "running" if self.running else f"exited {self.proc.returncode}"
        return f"<NodeProcess {self.name} pid {self.pid} {state}>"

    @property
    def running(self) -> bool:
        return self.proc.poll() is None

    def log_text(self) -> str:
        return self.log_path.read_text(errors="replace")

    def log_tail(self, lines: int = 40) -> str:
        text = self.log_text().splitlines()
        return "\n".join(text[-lines:])

    def wait_for_log(self, pattern: str, timeout: float = 10.0) -> re.Match:
        """Wait until the output matches the regex ``pattern``; raise TimeoutError otherwise
        (or at once if the process exits without printing it)."""
        regex = re.compile(pattern, re.MULTILINE)
        deadline = time.monotonic() + timeout
        while True:
            match = regex.search(self.log_text())
            if match:
                return match
            if not self.running:
                raise NodeProcessError(f"{self.name} exited ({self.proc.returncode}) without "
                                       f"printing /{pattern}/\n{self._tail_block()}")
            if time.monotonic() >= deadline:
                raise TimeoutError(f"{self.name} did not print /{pattern}/ within {timeout:g} s"
                                   f"\n{self._tail_block()}")
            time.sleep(0.05)

    def wait(self, timeout: float = 10.0) -> int:
        """Wait for a process that is expected to exit by itself; return its exit code."""
        try:
            self.returncode = self.proc.wait(timeout)
        except subprocess.TimeoutExpired:
            raise TimeoutError(f"{self.name} still running after {timeout:g} s\n"
                               f"{self._tail_block()}") from None
        self._finish()
        return self.returncode

    def stop(self, timeout: float = STOP_TIMEOUT) -> int:
        """SIGINT, wait up to ``timeout``; return the exit code (see class doc for errors)."""
        if self.stopped:
            assert self.returncode is not None
            return self.returncode
        problems: list[str] = []
        early = self.proc.poll()
        if early is not None:
            problems.append(f"exited by itself with code {early} "
                            f"{time.monotonic() - self.started_at:.1f} s after start, before "
                            "it was stopped")
        else:
            self.proc.send_signal(signal.SIGINT)
            try:
                self.proc.wait(timeout)
            except subprocess.TimeoutExpired:
                stacks = thread_stacks(self.pid)
                self.proc.kill()
                self.proc.wait(5.0)
                self.killed = True
                problems.append(f"did not exit within {timeout:g} s of SIGINT: killed (SIGKILL)"
                                f"\n--- where its threads were ---\n{stacks}")
        self.returncode = self.proc.returncode
        if (self.check_exit_code and not self.killed and early is None
                and self.returncode not in CLEAN_EXIT_CODES):
            problems.append(f"exited with code {self.returncode} after SIGINT")
        self._finish()
        if problems:
            raise NodeProcessError(f"{self.name} (pid {self.pid}): {'; '.join(problems)}\n"
                                   f"{self._tail_block()}")
        return self.returncode

    def kill(self) -> None:
        """SIGKILL without checks (used at interpreter exit)."""
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait(5.0)
        self._finish()

    def _finish(self) -> None:
        self.stopped = True
        self.returncode = self.proc.returncode
        if not self._log.closed:
            self._log.close()
        if self in _live_processes:
            _live_processes.remove(self)

    def _tail_block(self, lines: int = 40) -> str:
        return (f"--- last {lines} lines of {self.log_path} ---\n{self.log_tail(lines)}\n"
                f"--- end of {self.name} log ---")


@atexit.register
def _kill_leftovers() -> None:
    for proc in list(_live_processes):
        print(f"harness: killing leftover {proc}", file=sys.stderr)
        proc.kill()


def resolve_executable(exe: Union[str, Path]) -> Path:
    """A bare name is looked up in MOBIL_BIN_DIR; a path is used as it is."""
    path = Path(exe)
    if path.parent == Path("."):
        path = BIN_DIR / path
    if not path.is_file() or not os.access(path, os.X_OK):
        raise FileNotFoundError(
            f"node executable {path} not found (build it with `cargo build --release`, or set "
            f"MOBIL_BIN_DIR)")
    return path


def launch_node(exe: Union[str, Path], *ros_args: str, log_dir: Path,
                params_file: Union[str, Path, None] = None, name: Optional[str] = None,
                args: Sequence[str] = (), env: Optional[dict[str, str]] = None,
                check_exit_code: bool = True, niceness: int = 0,
                prefix: Sequence[str] = ()) -> NodeProcess:
    """Start ``exe [args] --ros-args ROS_ARGS [--params-file F] [-r __node:=NAME]``.

    ``params_file`` relative paths are relative to the repository root. ``env`` entries are
    added to the ROS environment (domain id, Fast DDS profile, RUST_BACKTRACE=1). A
    ``niceness`` above 0 starts it under ``nice`` (a lower CPU priority). ``prefix`` is a
    command that execs the node, e.g. ``ip netns exec NS`` (the node keeps the process id).
    """
    path = resolve_executable(exe)
    ros = list(ros_args)
    if ros and ros[0] == "--ros-args":
        ros = ros[1:]
    if params_file is not None:
        pf = Path(params_file)
        pf = pf if pf.is_absolute() else ROOT / pf
        if not pf.is_file():
            raise FileNotFoundError(f"parameter file {pf} not found")
        ros += ["--params-file", str(pf)]
    if name is not None:
        ros += ["-r", f"__node:={name}"]
    cmd = [str(path), *args] + (["--ros-args", *ros] if ros else [])
    if niceness > 0:
        cmd = ["nice", "-n", str(niceness), *cmd]
    cmd = [*prefix, *cmd]
    child_env = rosutil.ros_environ()
    child_env.setdefault("RUST_BACKTRACE", "1")
    child_env.update(env or {})
    label = name or path.name
    log_path = log_dir / f"{label}-{int(time.time() * 1000) % 100000:05d}.log"
    return NodeProcess(cmd, log_path, child_env, label, check_exit_code=check_exit_code)


# --------------------------------------------------------------------------------------------
# Topics
# --------------------------------------------------------------------------------------------

def subscribe(node: Any, msg_type: type, topic: str, qos: Any = None,
              discovery_timeout: float = 10.0) -> TopicRecorder:
    """Record every message of ``topic`` (close it, or use it as a context manager).

    ``qos=None`` matches the publishers' QoS, waiting up to ``discovery_timeout`` for one.
    """
    return TopicRecorder(node, msg_type, topic, qos, discovery_timeout=discovery_timeout)


def wait_for_message(node: Any, msg_type: type, topic: str,
                     predicate: Optional[Callable[[Any], bool]] = None, timeout: float = 10.0,
                     qos: Any = None) -> Any:
    """First message on ``topic`` (received after the call) that satisfies ``predicate``.

    ``qos=None`` matches the publishers (best effort if any is, transient local if all are),
    waiting for a publisher to be discovered within the same ``timeout``; pass a profile (e.g.
    ``qos_sensor()``, ``qos_latched()``) to subscribe at once. Raises TimeoutError describing what
    was received and who publishes.
    """
    deadline = time.monotonic() + timeout
    with TopicRecorder(node, msg_type, topic, qos, discovery_timeout=timeout) as rec:
        return rec.wait_for(predicate, max(0.0, deadline - time.monotonic()))


def collect(node: Any, msg_type: type, topic: str, duration: float, qos: Any = None,
            first_timeout: float = 10.0, wait_first: bool = True) -> list[Any]:
    """Messages of ``topic`` over ``duration`` seconds.

    With ``wait_first`` (the default) the window starts at the first message, which must come
    within ``first_timeout`` (TimeoutError otherwise), so discovery time does not shorten it;
    without, the window starts now and the list may be empty.
    """
    with TopicRecorder(node, msg_type, topic, qos, discovery_timeout=first_timeout) as rec:
        if wait_first:
            rec.wait_for(None, first_timeout)
            start = rec.times[0]
        else:
            start = time.monotonic()
        time.sleep(max(0.0, start + duration - time.monotonic()))
        return [m for m, t in zip(rec.snapshot(), list(rec.times)) if t <= start + duration]


def publish_until(node: Any, pub: Any, msg: Union[Any, Callable[[], Any]],
                  until_predicate: Callable[[], Any], rate_hz: float = 10.0,
                  timeout: float = 10.0) -> int:
    """Publish ``msg`` (or ``msg()`` each time, for fresh stamps) at ``rate_hz`` until
    ``until_predicate()`` is truthy; return how many were published. Raises TimeoutError.

    Typical use: keep sending a command until the node under test shows it acted on it, e.g.
    ``publish_until(node, cmd_pub, twist, lambda: odom.latest and odom.latest.twist.twist.linear.x
    > 0.1)`` with ``odom = subscribe(node, Odometry, 'odom')``.
    """
    period = 1.0 / rate_hz
    deadline = time.monotonic() + timeout
    count = 0
    next_time = time.monotonic()
    while True:
        if until_predicate():
            return count
        now = time.monotonic()
        if now >= deadline:
            raise TimeoutError(f"condition not met within {timeout:g} s after publishing "
                               f"{count} message(s) on {pub.topic_name} "
                               f"({pub.get_subscription_count()} matched subscription(s))")
        if now >= next_time:
            pub.publish(msg() if callable(msg) else msg)
            count += 1
            next_time += period
            if next_time < now:
                next_time = now + period
        time.sleep(max(0.0, min(0.01, next_time - time.monotonic())))


# --------------------------------------------------------------------------------------------
# Parameters
# --------------------------------------------------------------------------------------------

def param_get(node: Any, target_node: str, name: str, timeout: float = 10.0) -> Any:
    """Value of ``target_node``'s parameter ``name`` as a Python value (None if not set)."""
    values = rosutil.get_parameters(node, target_node, [name], timeout=timeout)
    return rosutil.parameter_value_to_python(values[0]) if values else None


def param_set(node: Any, target_node: str, name: str, value: Any, timeout: float = 10.0) -> Any:
    """Set one parameter (Python value: bool/int/float/str/list); return the
    rcl_interfaces/SetParametersResult (``.successful``, ``.reason``)."""
    return rosutil.set_parameters(node, target_node, {name: value}, timeout=timeout)[0]


def param_list(node: Any, target_node: str, timeout: float = 10.0) -> list[str]:
    """Sorted names of ``target_node``'s parameters."""
    return rosutil.list_parameters(node, target_node, timeout=timeout)


# --------------------------------------------------------------------------------------------
# The command-line tool
# --------------------------------------------------------------------------------------------

def run_ros2cli(*args: str, timeout: float = 30.0,
                env: Optional[dict[str, str]] = None) -> subprocess.CompletedProcess:
    """Run ``tests/ros2cli.py ARGS`` in this ROS domain; return the completed process (text)."""
    child_env = rosutil.ros_environ()
    child_env.update(env or {})
    return subprocess.run([sys.executable, str(ROS2CLI), *args], env=child_env,
                          capture_output=True, text=True, timeout=timeout, cwd=str(ROOT))


# --------------------------------------------------------------------------------------------
# Scenarios under the simulated clock
# --------------------------------------------------------------------------------------------

# The CPU priority of the simulation under the nodes it drives (see launch_scenario).
SIM_NICENESS = 10


def launch_scenario(params_file: Union[str, Path], *, real_time_factor: float,
                    nodes: Sequence[str] = ("chassis_node",), sim_args: Sequence[str] = (),
                    node_args: Sequence[str] = (), lidar: bool = False,
                    log_dir: Optional[Path] = None,
                    launch: Optional[Callable[..., NodeProcess]] = None) -> list[NodeProcess]:
    """Start ``sim_node`` publishing ``/clock`` at ``real_time_factor`` simulated seconds per
    wall second, then each executable of ``nodes`` with ``use_sim_time:=true``, all configured by
    ``params_file``; return the processes, ``sim_node`` first.

    ``sim_args`` go to ``sim_node`` only, ``node_args`` to every other node. The LIDAR is off
    unless ``lidar`` (a 1081-beam scan costs the most of anything in the simulation).

    Watchdogs run on the steady clock at any factor (the time rule, ``mobil_ros::time``): the
    simulated motor drivers' ``command_timeout_s`` and chassis_node's ``cmd_vel`` and feedback
    timeouts are wall-clock seconds, so a test that commands on simulated time must also keep
    ``cmd_vel`` coming in wall time (``publish_on_sim_time`` does). ``launch``
    is the function that starts one process (the ``start_node`` fixture, which stops them at
    teardown); without it ``launch_node`` is used with ``log_dir`` and the caller stops them.
    Use ``SimClock`` to wait for the clock and to measure the factor actually reached.
    """
    if launch is None:
        if log_dir is None:
            raise ValueError("launch_scenario needs launch= or log_dir=")

        def launch(exe: str, *ros_args: str, params_file: Any = None, **kwargs: Any) -> NodeProcess:
            return launch_node(exe, *ros_args, log_dir=log_dir, params_file=params_file, **kwargs)

    clock_args = ["-p", "publish_clock:=true", "-p", f"real_time_factor:={float(real_time_factor)!r}"]
    lidar_args = [] if lidar else ["-p", "lidar.enabled:=false"]
    # The simulation yields the CPU to the nodes under test: on a machine short of CPU it is the
    # simulated clock that slows (sim_node drops a backlog beyond clock_catch_up_s), not the
    # nodes' reaction in simulated time. At 5x a navigator that waits 20 ms for a core drives
    # 0.1 simulated seconds on its old command; a VFO optimisation that waits ten times longer
    # drove a robot into an obstacle's forbidden radius that way.
    procs = [launch("sim_node", *clock_args, *lidar_args, *sim_args, params_file=params_file,
                    niceness=SIM_NICENESS)]
    for exe in nodes:
        procs.append(launch(exe, "-p", "use_sim_time:=true", *node_args, params_file=params_file))
    return procs


# The closed-loop scenarios ask sim_node for several times real time (each module's
# REAL_TIME_FACTOR) and require this much of the factor reached: simulated time at least twice as
# fast as real time, which is what keeps their wall time down. What the simulation reaches is the
# CPU the machine leaves it (the nodes under test, the other pytest worker): 4.97-5.03x of 5x on
# the 2-core machine of docs/performance.md, 3.3-4.0x of 4-5x on one 2-3 times slower. sim_node
# does not make up a stall (clock_catch_up_s: it never runs ahead of its nodes), so a factor
# short of the one asked is a slow machine, not a fault. What a simulation step costs is
# nodes/sim's bench.
MIN_REAL_TIME_FACTOR = 2.0


class SimClock:
    """Follows ``/clock`` (rosgraph_msgs/Clock) in the test: simulated time and the factor
    reached. Close it (or use it as a context manager) when done.

    Best effort, as the nodes' own clock subscription. Each message is kept only as the latest
    (simulated seconds, monotonic arrival time), so a clock at 800 Hz costs no memory. A clock
    that goes backwards (a restarted simulation) restarts the measurement of ``factor``.
    ``max_gap`` is the longest wall time between two ``/clock`` arrivals: a stalled simulation
    (or test process) shows there, which the average ``factor`` hides (sim_node catches up).
    """

    def __init__(self, node: Any, topic: str = "/clock") -> None:
        from rosgraph_msgs.msg import Clock
        self.node = node
        self.count = 0
        self.max_gap = 0.0  # the longest wall time between two /clock arrivals [s]
        self._first: Optional[tuple[float, float]] = None
        self._latest: Optional[tuple[float, float]] = None
        self._cond = threading.Condition()
        self._sub = node.create_subscription(Clock, topic, self._callback, qos_sensor())

    def _callback(self, msg: Any) -> None:
        sample = (msg.clock.sec + msg.clock.nanosec * 1e-9, time.monotonic())
        with self._cond:
            if self._latest is None or sample[0] < self._latest[0]:
                self._first = sample
            else:
                self.max_gap = max(self.max_gap, sample[1] - self._latest[1])
            self._latest = sample
            self.count += 1
            self._cond.notify_all()

    def close(self) -> None:
        self.node.destroy_subscription(self._sub)

    def __enter__(self) -> "SimClock":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()

    def wait_started(self, timeout: float = 10.0) -> float:
        """Wait for the first ``/clock``; return the simulated time it carried."""
        with self._cond:
            if not self._cond.wait_for(lambda: self._latest is not None, timeout):
                raise TimeoutError(f"no /clock within {timeout:g} s (is sim_node running with "
                                   "publish_clock:=true?)")
            assert self._first is not None
            return self._first[0]

    def now(self) -> float:
        """The latest simulated time received [s]; raises if no ``/clock`` came yet."""
        with self._cond:
            if self._latest is None:
                raise RuntimeError("no /clock received yet (call wait_started first)")
            return self._latest[0]

    def wait_until(self, t: float, timeout: float = 30.0) -> float:
        """Wait until simulated time reaches ``t`` (not wall time); return the time reached.
        Raises TimeoutError after ``timeout`` wall seconds."""
        with self._cond:
            if not self._cond.wait_for(lambda: self._latest is not None and self._latest[0] >= t,
                                       timeout):
                at = "no /clock" if self._latest is None else f"at {self._latest[0]:.3f} s"
                raise TimeoutError(f"simulated time did not reach {t:.3f} s within {timeout:g} "
                                   f"wall seconds ({at})")
            assert self._latest is not None
            return self._latest[0]

    def mark(self) -> tuple[float, float]:
        """(simulated time, monotonic wall time) of the latest ``/clock``: a start for
        ``factor(since=...)``."""
        with self._cond:
            if self._latest is None:
                raise RuntimeError("no /clock received yet (call wait_started first)")
            return self._latest

    def factor(self, since: Optional[tuple[float, float]] = None) -> float:
        """Simulated seconds per wall second, from ``since`` (a ``mark()``; default: the first
        ``/clock`` received) to the latest ``/clock``. Both ends are arrival times in this
        process, so DDS latency cancels out; measure over a few wall seconds."""
        with self._cond:
            start, end = since or self._first, self._latest
            if start is None or end is None or end[1] <= start[1]:
                raise RuntimeError("too few /clock messages to measure the real-time factor")
            return (end[0] - start[0]) / (end[1] - start[1])


def publish_on_sim_time(pub: Any, msg: Union[Any, Callable[[float], Any]], clock: SimClock,
                        until: float, period: float = 0.05, max_wall_gap: float = 0.1,
                        timeout: float = 30.0, done: Optional[Callable[[], Any]] = None) -> int:
    """Publish ``msg`` (or ``msg(t)``, ``t`` the simulated time) every ``period`` simulated
    seconds until simulated time ``until`` (``math.inf``: no end) or until ``done()`` is truthy;
    return how many were published.

    The schedule is in simulated time, as a node under the simulation would publish. Also at
    least every ``max_wall_gap`` wall seconds: the nodes' watchdogs (``cmd_vel_timeout_s``,
    0.5 s) run on the steady clock by design, so a stream that is on time only in simulated
    time would stop the wheels whenever the simulation itself waits for the CPU; the extra
    messages repeat the current command, which changes nothing. Raises TimeoutError if
    ``until`` is not reached within ``timeout`` wall seconds.
    """
    deadline = time.monotonic() + timeout
    next_sim = clock.now()
    last_wall = -math.inf
    count = 0
    while True:
        t = clock.now()
        if t >= until or (done is not None and done()):
            return count
        wall = time.monotonic()
        if wall >= deadline:
            goal = f"not {until:.3f} s" if done is None else "condition not met"
            raise TimeoutError(f"simulated time at {t:.3f} s, {goal}, after {timeout:g} wall "
                               f"seconds ({count} message(s) published on {pub.topic_name})")
        if t >= next_sim or wall - last_wall >= max_wall_gap:
            pub.publish(msg(t) if callable(msg) else msg)
            count += 1
            last_wall = wall
            if t >= next_sim:
                next_sim = (math.floor(t / period + 1e-9) + 1) * period
        time.sleep(0.002)


# Feeds for a node run without a simulator
# --------------------------------------------------------------------------------------------

class OpenSpaceScan:
    """Publishes an empty 270° scan (541 beams, all +inf: nothing in range) on ``scan`` at 20
    wall Hz from a thread, until stopped: a scan whose end the test controls."""

    def __init__(self, node: Any) -> None:
        from sensor_msgs.msg import LaserScan
        self.pub = node.create_publisher(LaserScan, "scan", qos_sensor())
        self.msg = LaserScan()
        self.msg.header.frame_id = "laser"
        fov = 1.5 * math.pi
        self.msg.angle_min, self.msg.angle_max = -fov / 2, fov / 2
        self.msg.angle_increment = fov / 540
        self.msg.range_min, self.msg.range_max = 0.06, 10.0
        self.msg.ranges = [math.inf] * 541
        self.last_sent = math.nan
        self.defects: list = []
        self.defects_sent = 0
        self._broken = threading.Event()
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        n = 0
        while not self._stop.wait(0.05):
            if self._broken.is_set():
                self.pub.publish(self.defects[n % len(self.defects)])
                n += 1
                self.defects_sent = n
                continue
            self.pub.publish(self.msg)
            self.last_sent = time.monotonic()

    def break_scans(self) -> float:
        """From now on, only defective scans, each a defect the checked Scan refuses (no beams;
        a negative, a NaN increment; NaN angles; more beams than the angles span; range_min
        above range_max; three intensities for 541 ranges); returns the monotonic time of the
        last valid scan."""
        from sensor_msgs.msg import LaserScan

        def bad(**fields: Any) -> Any:
            m = LaserScan()
            for name in ("header", "angle_min", "angle_max", "angle_increment", "range_min",
                         "range_max", "ranges"):
                setattr(m, name, getattr(self.msg, name))
            for name, value in fields.items():
                setattr(m, name, value)
            return m
        self.defects = [bad(ranges=[]), bad(angle_increment=-0.01), bad(angle_increment=math.nan),
                        bad(angle_min=math.nan), bad(ranges=[1.0] * 900),
                        bad(range_min=20.0), bad(intensities=[1.0, 2.0, 3.0])]
        self._broken.set()
        assert wait_until(lambda: self.defects_sent > 0, 5.0), "no defective scan sent"
        return self.last_sent

    def stop(self) -> float:
        """Stops; returns the monotonic time of the last scan sent."""
        self._stop.set()
        self._thread.join(timeout=5)
        return self.last_sent


class OdomFeed:
    """Publishes ``msg`` on ``odom`` at 20 wall Hz from a thread until stopped; the test swaps
    ``msg`` to feed bad odometry."""

    def __init__(self, node: Any, msg: Any) -> None:
        from nav_msgs.msg import Odometry
        self.pub = node.create_publisher(Odometry, "odom", 10)
        self.msg = msg
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(0.05):
            self.pub.publish(self.msg)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)


def odom_at(x: float = 0.0, frame: str = "odom") -> Any:
    from nav_msgs.msg import Odometry
    m = Odometry()
    m.header.frame_id, m.child_frame_id = frame, "base_link"
    m.pose.pose.position.x = x
    m.pose.pose.orientation.w = 1.0
    return m


def stamped_pose(x: float, y: float, frame: str = "odom", yaw: float = 0.0) -> Any:
    """A PoseStamped at (x, y) facing ``yaw`` in ``frame`` (a goal, a dock, a waypoint)."""
    from geometry_msgs.msg import PoseStamped
    p = PoseStamped()
    p.header.frame_id = frame
    p.pose.position.x, p.pose.position.y = float(x), float(y)
    p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return p
