"""sim_node alone, driven by real rclpy (ROS 2 Jazzy, Fast DDS): what it does with wheel
commands beyond the chassis' limits or not numbers at all.

Every expected number is worked out by hand (see the comments), not taken from the node.
"""

from __future__ import annotations

import math
import time

import pytest

from harness import publish_until, subscribe

from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState


def omni_command(w1: float, w2: float, w3: float) -> JointState:
    js = JointState()
    js.name = ["wheel_1", "wheel_2", "wheel_3"]
    js.velocity = [float(w1), float(w2), float(w3)]
    return js


def stamp_s(msg: Odometry) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def test_wheel_commands_are_held_to_the_limits_and_nan_stops_the_wheels_at_once(start_node, ros_node):
    sim = start_node("sim_node", "-p", "lidar.enabled:=false", params_file="params/omr3.yaml")
    pub = ros_node.create_publisher(JointState, "wheel_commands", 10)
    with subscribe(ros_node, Odometry, "ground_truth") as truth:
        # Wheel 1 at 1e308 is held to max_wheel_speed = 12 rad/s: r·12 = 0.05·12 = 0.6 m/s on
        # wheel 1 alone (rolling along body x), so v_x = ⅔·0.6 = 0.4 m/s and
        # ω = 0.6 / (3·R) = 0.6 / 0.6 = 1 rad/s (check: 0.4 + 0.2·1 = 0.6 on wheel 1,
        # −½·0.4 + 0.2·1 = 0 on the others): a circle of radius 0.4 m through the start.
        publish_until(ros_node, pub, omni_command(1e308, 0.0, 0.0),
                      lambda: truth.latest is not None and abs(truth.latest.twist.twist.angular.z - 1.0) < 1e-6,
                      rate_hz=20, timeout=15)
        held = truth.latest.twist.twist
        assert held.linear.x == pytest.approx(0.4, abs=1e-6)
        assert held.linear.y == pytest.approx(0.0, abs=1e-6)
        sim.wait_for_log("held to them")

        # NaN on one wheel: refused, and the wheels stop now, not after command_timeout_s (1 s).
        first_nan = time.time()
        publish_until(ros_node, pub, omni_command(math.nan, 0.0, 0.0),
                      lambda: abs(truth.latest.twist.twist.angular.z) < 1e-3, rate_hz=20, timeout=10)
        sim.wait_for_log("wheels stopped")
        messages = truth.snapshot()

    turning = [m for m in messages if m.twist.twist.angular.z > 0.99]
    stopped = [m for m in messages if stamp_s(m) > stamp_s(turning[-1]) and m.twist.twist.angular.z < 0.01]
    # Stamps are wall-clock time in real-time mode: the stop began within DDS latency of the
    # first NaN, well before the 1 s driver timeout.
    assert stamp_s(turning[-1]) - first_nan < 0.7
    # The motors then coast down with τ = 0.05 s: from 0.99 to 0.01 rad/s in τ·ln(99) = 0.2298 s.
    # ground_truth comes every 20 ms, so the last sample above 0.99 is up to 20 ms before that
    # crossing and the first below 0.01 up to 20 ms after the other: 0.2298 to 0.2698 s.
    decay = stamp_s(stopped[0]) - stamp_s(turning[-1])
    assert 0.05 * math.log(99) - 1e-6 <= decay <= 0.05 * math.log(99) + 0.04 + 1e-6, decay
    # The truth stayed finite, and on the 0.4 m circle: never more than 0.8 m from the start.
    for m in messages:
        p = m.pose.pose.position
        assert math.isfinite(p.x) and math.isfinite(p.y)
        assert math.hypot(p.x, p.y) <= 0.8 + 1e-6
