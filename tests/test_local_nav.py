"""local_nav_node from real rclpy (ROS 2 Jazzy, Fast DDS): a goal from goal_pose driven in the
simulator, Nav2's NavigateToPose fed by a foreign LIDAR (a raycaster in this test), and the
refusals (goal frame, NaN, a stale scan).

The robot is OMR-III (params/omr3.yaml: noise-free encoders, so odometry and ground truth agree
to well under a millimetre here). Driving runs under the simulated clock at 5× real time (≥ 4×
asserted). Watchdogs run on the steady clock (the time rule), so chassis_node's feedback watchdog
gets 2 s, as in test_scenario.py.

Invariants checked on cmd_vel: nothing before the first goal; every command within OMR-III's
limits (speed ≤ v_max 0.5 m/s, |ω| ≤ omega_max 1.5 rad/s); exactly one zero command per goal
that ends (each end is a status with a reason), and none after the last.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np
import pytest
import yaml

from harness import make_qos, qos_latched, qos_sensor, subscribe, wait_until

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, Twist
from nav_msgs.msg import Odometry
from rclpy.action import ActionClient
from sensor_msgs.msg import LaserScan

from mobil_msgs.msg import NavStatus
from nav2_msgs.action import NavigateToPose

PARAMS = "params/omr3.yaml"
REAL_TIME_FACTOR = 5.0
MIN_FACTOR = 4.0
CHASSIS_ARGS = ("-p", "feedback_timeout_s:=2.0")
V_MAX, OMEGA_MAX = 0.5, 1.5  # params/omr3.yaml
ROBOT_RADIUS = 0.25  # params/omr3.yaml
GOAL_TOLERANCE = 0.10  # xy_goal_tolerance in params/omr3.yaml
REPLY_TIMEOUT = 10.0
# Every cmd_vel is counted: a reliable reader deep enough for seconds of commands.
DEEP = make_qos("reliable", "volatile", 1000)


def goal_pose(x: float, y: float, frame: str = "odom") -> PoseStamped:
    g = PoseStamped()
    g.header.frame_id = frame
    g.pose.position.x, g.pose.position.y = float(x), float(y)
    g.pose.orientation.w = 1.0
    return g


def is_zero(t: Twist) -> bool:
    return (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z) == (0.0,) * 6


def check_commands(cmds: list[Twist], ends: int) -> None:
    """Limits; one zero command per goal end, and the last command is zero."""
    for t in cmds:
        assert math.isfinite(t.linear.x) and math.isfinite(t.linear.y) and math.isfinite(t.angular.z)
        assert math.hypot(t.linear.x, t.linear.y) <= V_MAX + 1e-9
        assert abs(t.angular.z) <= OMEGA_MAX + 1e-9
    zeros = [i for i, t in enumerate(cmds) if is_zero(t)]
    assert len(zeros) == ends, f"{len(zeros)} zero commands for {ends} goal end(s)"
    assert cmds and is_zero(cmds[-1]), "the last cmd_vel is not zero"


def ends_of(statuses: list[NavStatus]) -> list[NavStatus]:
    return [s for s in statuses if s.state in (NavStatus.SUCCEEDED, NavStatus.FAILED)]


def speed(m: Odometry) -> float:
    return math.hypot(m.twist.twist.linear.x, m.twist.twist.linear.y)


def position(m: Odometry) -> tuple[float, float]:
    return m.pose.pose.position.x, m.pose.pose.position.y


def start_local_nav(start_node, *args: str):
    return start_node("local_nav_node", "-p", "use_sim_time:=true", *args, params_file=PARAMS)


def test_goal_pose_in_open_space(start_scenario, start_node, sim_clock, ros_node, tmp_path):
    """A goal 2.5 m away in an empty world: ACTIVE then SUCCEEDED, the ground truth within the
    goal tolerance at rest, no cmd_vel before the goal, one zero cmd_vel after."""
    world = tmp_path / "empty.yaml"
    world.write_text("obstacles: []\n")
    start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR, lidar=True,
                   sim_args=("-p", f"world_file:={world}"), node_args=CHASSIS_ARGS)
    start_local_nav(start_node)
    goal = (2.0, 1.5)
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, Odometry, "ground_truth") as truth:
        sim_clock.wait_started()
        # The latched IDLE status proves local_nav_node is up and matched; no goal yet, no cmd_vel.
        status.wait_for(lambda s: s.state == NavStatus.IDLE, REPLY_TIMEOUT)
        truth.wait_for(None, REPLY_TIMEOUT)
        assert len(cmd) == 0, "cmd_vel before any goal"
        # The first message after discovery may be lost: send until the goal is taken up.
        deadline = time.monotonic() + REPLY_TIMEOUT
        while not any(s.state == NavStatus.ACTIVE for s in status.snapshot()):
            assert time.monotonic() < deadline, "goal_pose never taken up"
            pub.publish(goal_pose(*goal))
            wait_until(lambda: any(s.state == NavStatus.ACTIVE for s in status.snapshot()), 1.0)
        mark = sim_clock.mark()
        done = status.wait_for(lambda s: s.state in (NavStatus.SUCCEEDED, NavStatus.FAILED), 20.0)
        assert done.state == NavStatus.SUCCEEDED, done.reason
        assert done.reason.startswith("SUCCEEDED")
        # At rest: 1 simulated second after the end (motor lag τ = 0.05 s).
        sim_clock.wait_until(sim_clock.now() + 1.0)
        factor = sim_clock.factor(since=mark)
        rest = truth.wait_for(lambda m: speed(m) < 1e-3, REPLY_TIMEOUT, start=len(truth))
        statuses, cmds = status.snapshot(), cmd.snapshot()

    assert factor >= MIN_FACTOR, f"{factor:.2f}× real time"
    x, y = position(rest)
    # The goal is reached when odometry is within 0.10 m; a noise-free odometry and the coast
    # toward the goal after the stop (≤ 0.083 m/s · τ) keep the ground truth inside it.
    assert math.hypot(x - goal[0], y - goal[1]) <= GOAL_TOLERANCE, (x, y)
    active = [s for s in statuses if s.state == NavStatus.ACTIVE]
    assert active and active[0].mode == "rotate"
    assert active[0].goal.position.x == goal[0] and active[0].goal.position.y == goal[1]
    # The first ACTIVE status came before the first step: distance from the start, 2.5 m.
    assert active[0].distance_to_goal == pytest.approx(math.hypot(*goal), abs=0.02)
    assert statuses.index(active[0]) < statuses.index(done)
    assert done.distance_to_goal <= GOAL_TOLERANCE
    check_commands(cmds, len(ends_of(statuses)))
    # Open space: the navigator went straight, nothing tracked.
    assert not done.has_hit_point
