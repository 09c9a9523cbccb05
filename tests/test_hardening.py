"""The motion nodes under hostile conditions, from real rclpy (ROS 2 Jazzy, Fast DDS), without a
simulator: the test owns ``/clock``, odometry and the scan.

* A stopped clock stops the robot: under ``use_sim_time``, ``/clock`` frozen mid-goal gives a zero
  ``cmd_vel`` from local_nav and the planner within ``clock_timeout_s`` (0.5 s) plus one watchdog
  period (50 ms), no moving command while it stands, STALE_INPUT in the status, and commands again
  once it moves; ROS time going back ends the goal CLOCK_BACKWARDS.
* Nothing non-finite is published: odometry at x = 1e308 (finite, but a distance from it
  overflows) mid-goal is refused like any bad sample (the robot stops), and no output of either
  node carries an infinity, nor a NaN but in the fields NavStatus documents as NaN while unknown.
* No log floods: a storm of 300 goals and a 100 Hz ``/clock`` with invalid nanoseconds each leave
  a bounded number of log lines (each call site: a burst of 10, then one a second).
"""

from __future__ import annotations

import contextlib
import dataclasses
import math
import threading
import time
from collections.abc import Iterator
from typing import Any

import pytest

from action_client import ActionClient
from harness import (OdomFeed, OpenSpaceScan, make_qos, odom_at, qos_latched, qos_sensor,
                     stamped_pose as pose, subscribe, wait_until)

from geometry_msgs.msg import PoseStamped, Twist
from rosgraph_msgs.msg import Clock
from visualization_msgs.msg import MarkerArray

from mobil_msgs.msg import NavStatus
from nav2_msgs.action import DockRobot, NavigateToPose

PARAMS = "params/omr3.yaml"
REPLY_TIMEOUT = 10.0
CLOCK_TIMEOUT_S = 0.5  # clock_timeout_s's default
WATCHDOG_PERIOD_S = 0.05  # both nodes' 20 Hz watchdog tick
# What a loaded 2-core machine adds to the bound: DDS hops and a late tick or callback.
SCHEDULING_S = 0.25
DEEP = make_qos("reliable", "volatile", 1000)
# NavStatus fields documented as NaN while unknown (msgs/mobil_msgs/msg/NavStatus.msg): the distance with no
# goal or odometry, a docking's figures before its first odometry, the VFO figures outside VFO.
NAN_WHEN_NONE = frozenset({"distance_to_goal", "e", "alpha", "theta", "lyapunov", "psi_z",
                           "chi_length", "chi_danger", "chi_control", "chi_smoothness"})


class ClockFeed:
    """Publishes ``/clock`` at 100 wall Hz from a thread: simulated time runs with the wall
    clock from 100 s, until frozen, resumed or set back."""

    def __init__(self, node: Any) -> None:
        self.pub = node.create_publisher(Clock, "/clock", qos_sensor())
        self.sim = 100.0
        self.running = True
        self.advanced_at = time.monotonic()
        self.bad_nanosec = False
        self._stop = threading.Event()
        self._lock = threading.Lock()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        last = time.monotonic()
        while not self._stop.wait(0.01):
            now = time.monotonic()
            with self._lock:
                if self.running:
                    self.sim += now - last
                    self.advanced_at = now
                last = now
                msg = Clock()
                msg.clock.sec = int(self.sim)
                msg.clock.nanosec = int((self.sim % 1.0) * 1e9)
                if self.bad_nanosec:
                    msg.clock.nanosec = 1_500_000_000
            self.pub.publish(msg)

    def freeze(self) -> float:
        """Stops simulated time; returns the monotonic time it last advanced (the thread's last
        step, which a loaded machine can delay past the 10 ms period)."""
        with self._lock:
            self.running = False
            return self.advanced_at

    def resume(self) -> None:
        with self._lock:
            self.running = True

    def back(self, seconds: float) -> None:
        with self._lock:
            self.sim -= seconds

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)


def is_zero(t: Twist) -> bool:
    return (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z) == (0,) * 6


@dataclasses.dataclass
class Feeds:
    clock: ClockFeed
    odom: OdomFeed
    scan: OpenSpaceScan


@contextlib.contextmanager
def fed(ros_node: Any) -> Iterator[Feeds]:
    """The test's ``/clock``, odometry of a robot standing at the origin and an empty scan, for
    as long as the block runs."""
    feeds = Feeds(ClockFeed(ros_node), OdomFeed(ros_node, odom_at(0.0)), OpenSpaceScan(ros_node))
    try:
        yield feeds
    finally:
        feeds.scan.stop()
        feeds.odom.stop()
        feeds.clock.stop()


def start_pair(start_node, *args: str):
    """local_nav and the planner on the test's clock, each with a cmd_vel of its own."""
    nav = start_node("local_nav_node", "-p", "use_sim_time:=true", "-r", "cmd_vel:=nav_cmd",
                     *args, params_file=PARAMS)
    plan = start_node("planner_node", "-p", "use_sim_time:=true", "-p", "world_file:=none",
                      "-r", "cmd_vel:=plan_cmd", *args, params_file=PARAMS)
    return nav, plan


def start_goals(ros_node, nav, plan) -> None:
    """A goal 3 m ahead for local_nav, a dock 2 m ahead for the planner, each sent until its
    node has taken it (a sample published before discovery is lost)."""
    goal_pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    dock_pub = ros_node.create_publisher(PoseStamped, "dock_pose", 10)
    for pub, msg, proc, taken in ((goal_pub, pose(3.0, 0.0), nav, "goal (goal_pose)"),
                                  (dock_pub, pose(2.0, 0.0), plan, "goal (dock_pose)")):
        def sent() -> bool:
            pub.publish(msg)
            return taken in proc.log_text()
        assert wait_until(sent, REPLY_TIMEOUT, interval=0.2), f"{proc.name} took no goal"


@pytest.mark.closed_loop  # timed in wall time: never beside a simulation at 5×
@pytest.mark.timeout(120)
def test_a_stopped_clock_stops_the_robot_and_a_clock_gone_back_ends_the_goal(start_node, ros_node):
    nav, plan = start_pair(start_node)
    with fed(ros_node) as feeds, subscribe(ros_node, Twist, "nav_cmd", qos=DEEP) as nav_cmd, \
            subscribe(ros_node, Twist, "plan_cmd", qos=DEEP) as plan_cmd, \
            subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as nav_status, \
            subscribe(ros_node, NavStatus, "planner/status", qos=qos_latched()) as plan_status:
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        start_goals(ros_node, nav, plan)
        for cmd in (nav_cmd, plan_cmd):
            cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT)
        marks = (len(nav_cmd), len(plan_cmd))
        frozen_at = feeds.clock.freeze()
        for cmd, mark in zip((nav_cmd, plan_cmd), marks):
            cmd.wait_for(is_zero, REPLY_TIMEOUT, start=mark)
            zero_at = cmd.times[next(i for i in range(mark, len(cmd)) if is_zero(cmd.messages[i]))]
            delay = zero_at - frozen_at
            assert delay <= CLOCK_TIMEOUT_S + WATCHDOG_PERIOD_S + SCHEDULING_S, \
                f"{cmd.topic}: zero {delay:.3f} s after the clock stopped"
            assert delay >= CLOCK_TIMEOUT_S - 0.1, f"{cmd.topic}: held after only {delay:.3f} s"
        time.sleep(0.5)
        for cmd, mark in zip((nav_cmd, plan_cmd), marks):
            held = cmd.snapshot()[mark:]
            first_zero = next(i for i, t in enumerate(held) if is_zero(t))
            assert all(is_zero(t) for t in held[first_zero:]), f"{cmd.topic} moved while held"
        for status in (nav_status, plan_status):
            s = status.wait_for(lambda s: "ROS time has not advanced" in s.reason, REPLY_TIMEOUT)
            assert s.state == NavStatus.ACTIVE and s.reason.startswith("STALE_INPUT: "), s.reason
        # Time moves again: both command again.
        marks = (len(nav_cmd), len(plan_cmd))
        feeds.clock.resume()
        for cmd, mark in zip((nav_cmd, plan_cmd), marks):
            cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT, start=mark)
        for proc in (nav, plan):
            proc.wait_for_log("ROS time moves again")
        # Back 5 s: each goal ends CLOCK_BACKWARDS, with its zero.
        marks = (len(nav_status), len(plan_status))
        feeds.clock.back(5.0)
        for status, mark in zip((nav_status, plan_status), marks):
            s = status.wait_for(lambda s: s.state == NavStatus.FAILED, REPLY_TIMEOUT, start=mark)
            assert s.reason.startswith("CLOCK_BACKWARDS: ROS time went back by "), s.reason
        for cmd in (nav_cmd, plan_cmd):
            assert wait_until(lambda: is_zero(cmd.latest), REPLY_TIMEOUT), f"{cmd.topic} left moving"


def send_action(node: Any, action_type: Any, name: str, goal: Any, feedback: list) -> None:
    """Sends ``goal`` until it is accepted (a goal response lost in discovery is sent again);
    its feedback goes to ``feedback``."""
    client = ActionClient(node, action_type, name)
    assert client.wait_for_server(timeout_sec=20.0), f"{name} not found"
    for _ in range(4):
        future = client.send_goal_async(goal, feedback_callback=lambda f: feedback.append(f.feedback))
        if wait_until(future.done, 3.0):
            assert future.result().accepted, f"{name} refused the goal"
            return
    raise AssertionError(f"{name}: no goal response")


def floats(msg: Any, path: str = "") -> list[tuple[str, float]]:
    """Every float in a message, with its path."""
    if isinstance(msg, float):
        return [(path, msg)]
    if isinstance(msg, (list, tuple)) or type(msg).__name__ == "ndarray":
        return [f for i, v in enumerate(msg) for f in floats(v, f"{path}[{i}]")]
    if hasattr(msg, "get_fields_and_field_types"):
        return [f for name in msg.get_fields_and_field_types()
                for f in floats(getattr(msg, name), f"{path}.{name}" if path else name)]
    return []


def not_finite(messages: list[Any], nan_allowed: frozenset[str] = frozenset()) -> list[str]:
    """The paths of the non-finite floats in ``messages`` (NaN allowed in the fields named)."""
    bad = []
    for m in messages:
        for path, v in floats(m):
            if not math.isfinite(v) and not (math.isnan(v) and path in nan_allowed):
                bad.append(f"{type(m).__name__}.{path} = {v}")
    return bad


@pytest.mark.timeout(120)
def test_odometry_too_far_to_compute_with_stops_the_robot_and_nothing_non_finite_goes_out(
        start_node, ros_node):
    nav, plan = start_pair(start_node)
    with fed(ros_node) as feeds, subscribe(ros_node, Twist, "nav_cmd", qos=DEEP) as nav_cmd, \
            subscribe(ros_node, Twist, "plan_cmd", qos=DEEP) as plan_cmd, \
            subscribe(ros_node, NavStatus, "local_nav/status", qos=DEEP) as nav_status, \
            subscribe(ros_node, NavStatus, "planner/status", qos=DEEP) as plan_status, \
            subscribe(ros_node, MarkerArray, "local_nav/markers", qos=DEEP) as nav_markers, \
            subscribe(ros_node, MarkerArray, "planner/markers", qos=DEEP) as plan_markers:
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        feedback: list[Any] = []
        send_action(ros_node, NavigateToPose, "navigate_to_pose",
                    NavigateToPose.Goal(pose=pose(3.0, 0.0)), feedback)
        send_action(ros_node, DockRobot, "dock_robot",
                    DockRobot.Goal(use_dock_id=False, dock_pose=pose(2.0, 0.0)), feedback)
        for cmd in (nav_cmd, plan_cmd):
            cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT)
        assert wait_until(lambda: len(feedback) > 10, REPLY_TIMEOUT), "no feedback"
        marks = (len(nav_cmd), len(plan_cmd))
        feeds.odom.msg = odom_at(1e308)
        for cmd, mark in zip((nav_cmd, plan_cmd), marks):
            cmd.wait_for(is_zero, REPLY_TIMEOUT, start=mark)
        for proc in (nav, plan):
            proc.wait_for_log(r"odom position \(1e308, 0\) beyond")
        time.sleep(1.0)  # the goals end STALE_INPUT; outputs keep coming meanwhile
        feeds.odom.msg = odom_at(0.0)
    outputs = {
        "cmd_vel": not_finite(nav_cmd.snapshot() + plan_cmd.snapshot()),
        "status": not_finite(nav_status.snapshot() + plan_status.snapshot(), NAN_WHEN_NONE),
        "markers": not_finite(nav_markers.snapshot() + plan_markers.snapshot()),
        "feedback": not_finite(feedback),
    }
    assert all(not bad for bad in outputs.values()), outputs
    assert feedback and nav_status.snapshot() and plan_markers.snapshot()


def log_lines(proc, since: int) -> list[str]:
    """The node's log lines after the first ``since`` characters."""
    return proc.log_text()[since:].splitlines()


# Each call site writes a burst of 10 lines, then one a second (mobil_ros::log): a flood of
# T seconds from K call sites leaves at most K·(10 + T) lines.
BURST, PER_SECOND = 10, 1.0


@pytest.mark.timeout(120)
def test_a_goal_storm_and_a_clock_with_bad_stamps_leave_few_log_lines(start_node, ros_node):
    nav, plan = start_pair(start_node)
    with fed(ros_node) as feeds, subscribe(ros_node, NavStatus, "local_nav/status", qos=DEEP) as nav_status, \
            subscribe(ros_node, NavStatus, "planner/status", qos=DEEP) as plan_status:
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        start_goals(ros_node, nav, plan)
        goal_pub = ros_node.create_publisher(PoseStamped, "goal_pose", DEEP)
        dock_pub = ros_node.create_publisher(PoseStamped, "dock_pose", DEEP)
        marks = {p.name: len(p.log_text()) for p in (nav, plan)}
        began = time.monotonic()
        # 300 goals each, as fast as rclpy sends them; the last ones 3.299 m and 2.299 m ahead.
        for k in range(300):
            goal_pub.publish(pose(3.0 + 0.001 * k, 0.0))
            dock_pub.publish(pose(2.0 + 0.001 * k, 0.0))
            if k % 50 == 49:
                time.sleep(0.05)  # within the nodes' reader depth (10): most goals arrive
        for status, x in ((nav_status, 3.299), (plan_status, 2.299)):
            status.wait_for(lambda s: abs(s.goal.position.x - x) < 1e-9, REPLY_TIMEOUT)
        time.sleep(0.5)
        storm = time.monotonic() - began
        for proc in (nav, plan):
            lines = log_lines(proc, marks[proc.name])
            print(f"{proc.name}: {len(lines)} lines in {storm:.2f} s")
            # Two lines per goal (taken, the one before ended) from two call sites, 600 lines
            # without a budget: at most 2 · (10 + a line a second) with it.
            assert len(lines) <= 2 * (BURST + PER_SECOND * storm) + 2, "\n".join(lines[-20:])
        # /clock at 100 Hz with nanosec 1.5e9 (invalid) for 3 s.
        marks = {p.name: len(p.log_text()) for p in (nav, plan)}
        feeds.clock.bad_nanosec = True
        time.sleep(3.0)
        feeds.clock.bad_nanosec = False
        for proc in (nav, plan):
            lines = log_lines(proc, marks[proc.name])
            print(f"{proc.name}, bad clock: {len(lines)} lines")
            assert len(lines) <= 2 * (BURST + 3), "\n".join(lines[-20:])


def test_a_node_stopped_while_it_starts_shuts_down_cleanly(start_node, tmp_path):
    """SIGINT the moment a node has logged a line of its start-up (the planner, its dock
    database, as tests/test_nav2_roles.py does), before its main loop waits for signals: the
    signal is remembered from the start, so the node goes through its shutdown (the participant
    leaves the domain, "shut down" is logged, exit code 0) within the harness's 5 s, rather than
    being ended by the signal's default action on the spot."""
    database = tmp_path / "dock_database.yaml"
    database.write_text("docks:\n  home:\n    type: charging_dock\n    frame: odom\n    pose: [0.3, -0.2, 3.0]\n")
    for i in range(3):
        proc = start_node("planner_node", "-p", f"dock_database:={database}", params_file="params/omr3.yaml",
                          name=f"planner_{i}")
        proc.wait_for_log(r"dock `home` \(charging_dock\)", timeout=15)
        started = time.monotonic()
        code = proc.stop()  # raises if the node had to be killed
        assert time.monotonic() - started < 5.0
        assert code == 0 and "shut down" in proc.log_text(), proc.log_text()[-1500:]
