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
    # The motors coast down with τ = 0.05 s from ω0 = 1 rad/s, each wheel by the same exact
    # first-order lag, so the body's turn rate does too: ω(t) = ω0·e^(−(t − t0)/τ) from the
    # instant t0 the stop took effect. Each sample of the decay therefore extrapolates back to
    # the same start, t0 = t + τ·ln(ω/ω0) (ln < 0: t0 is before t). Samples lost on the way do
    # not matter; the stamps are the simulated time in nanoseconds, so the estimates agree far
    # inside 1 ms (a wrong τ of 10 % would spread them by 0.1·(t − t0), up to 23 ms).
    decaying = [m for m in messages
                if stamp_s(m) > stamp_s(turning[0]) and 0.01 < m.twist.twist.angular.z < 0.99]
    assert len(decaying) >= 2, [m.twist.twist.angular.z for m in messages]
    starts = [stamp_s(m) + 0.05 * math.log(m.twist.twist.angular.z / 1.0) for m in decaying]
    assert max(starts) - min(starts) < 1e-3, starts
    # Stamps are wall-clock time in real-time mode: the stop began within DDS latency of the
    # first NaN, well before the 1 s driver timeout.
    assert min(starts) - first_nan < 0.7, min(starts) - first_nan
    # The truth stayed finite, and on the 0.4 m circle: never more than 0.8 m from the start.
    for m in messages:
        p = m.pose.pose.position
        assert math.isfinite(p.x) and math.isfinite(p.y)
        assert math.hypot(p.x, p.y) <= 0.8 + 1e-6


def test_the_drivers_stop_the_wheels_when_wheel_commands_stop(start_node, ros_node):
    # params/omr3.yaml: command_timeout_s 1.0, motor_time_constant 0.05.
    start_node("sim_node", "-p", "lidar.enabled:=false", params_file="params/omr3.yaml")
    pub = ros_node.create_publisher(JointState, "wheel_commands", 10)
    with subscribe(ros_node, Odometry, "ground_truth") as truth:
        # Equal wheels at 4 rad/s: a turn on the spot at r·Σω / (3R) = 0.05·12 / 0.6 = 1 rad/s.
        publish_until(ros_node, pub, omni_command(4.0, 4.0, 4.0),
                      lambda: truth.latest is not None and abs(truth.latest.twist.twist.angular.z - 1.0) < 1e-6,
                      rate_hz=20, timeout=15)
        # A few more commands at 20 Hz, then silence.
        for _ in range(6):
            pub.publish(omni_command(4.0, 4.0, 4.0))
            last_sent = time.time()
            time.sleep(0.05)
        deadline = time.monotonic() + 5.0
        while abs(truth.latest.twist.twist.angular.z) >= 1e-3:
            assert time.monotonic() < deadline, "still turning 5 s after the last wheel_commands"
            time.sleep(0.02)
        messages = truth.snapshot()

    # As in the NaN test: the coast-down ω0·e^(−(t − t0)/τ) from ω0 = 1 rad/s, τ = 0.05 s, dates
    # the stop: t0 = t + τ·ln(ω/ω0) for every decaying sample. The drivers stop when the last
    # command is more than 1 s old: not before last_sent + 1 s (its arrival is later still), and
    # within a physics step plus scheduling after it (stamps are wall-clock time in real-time mode,
    # through the simulated clock, which may trail the wall by a late step on a loaded machine:
    # 0.1 s of slack below; a stop for any other reason, e.g. the first or a lost command, would
    # be far outside).
    turning = [m for m in messages if m.twist.twist.angular.z > 0.99]
    decaying = [m for m in messages
                if stamp_s(m) > stamp_s(turning[-1]) and 0.01 < m.twist.twist.angular.z < 0.99]
    assert len(decaying) >= 2, [m.twist.twist.angular.z for m in messages]
    starts = [stamp_s(m) + 0.05 * math.log(m.twist.twist.angular.z / 1.0) for m in decaying]
    assert max(starts) - min(starts) < 1e-3, starts
    waited = min(starts) - last_sent
    assert 1.0 - 0.1 <= waited <= 1.0 + 0.3, waited
    # Stopped (|ω| < 1e-3 after τ·ln(1000) = 0.35 s of coasting) within timeout + lag.
    stopped = next(m for m in messages
                   if stamp_s(m) > min(starts) and abs(m.twist.twist.angular.z) < 1e-3)
    assert stamp_s(stopped) - last_sent <= 1.0 + 0.35 + 0.3, stamp_s(stopped) - last_sent
