"""The suite's own messages (mobil_msgs) between rclpy and the Rust nodes, both ways.

rclpy publishes with the type support built from msgs/mobil_msgs by CMake (as colcon would), the Rust
relay (`mobil_msgs_relay`, types generated from the same .msg files) republishes, and rclpy must
get back exactly what it sent: every field, fixed arrays, nested sequences, constants.
"""

from __future__ import annotations

import sys
from pathlib import Path

import mobil_msgs
import nav2_msgs
from geometry_msgs.msg import Point, Pose2D
from mobil_msgs.msg import GaitPlan, GaitStep, TerrainAssessment

from harness import ROOT, publish_until, subscribe


def test_the_type_support_is_this_pythons_own():
    """mobil_msgs and nav2_msgs come from the install tests/setup_env.sh built for this Python
    (the other Python's round, tests/test_other_python.py, must not load this one's)."""
    install = ROOT / "target" / f"msgs-install-py{sys.version_info.major}.{sys.version_info.minor}"
    for package in (mobil_msgs, nav2_msgs):
        assert Path(package.__file__).resolve().is_relative_to(install.resolve()), package.__file__


def terrain() -> TerrainAssessment:
    m = TerrainAssessment()
    m.header.frame_id = "body"
    m.header.stamp.sec, m.header.stamp.nanosec = 17, 250_000_000
    for i, z in enumerate([0.02, -0.01, -0.02, 0.0, 0.01, 0.0]):
        m.feet[i] = Point(x=0.1 * i, y=-0.2 * i, z=z)
    m.sigma = 0.0129
    m.alpha12, m.alpha23, m.alpha13 = 0.05, 0.1, 0.15
    m.planes[2].theta_x = -0.2
    m.planes[2].downhill = 3.0
    m.tilt = 0.2
    m.terrain_class = TerrainAssessment.UNEVEN
    m.advised_gait = TerrainAssessment.GAIT_WAVE
    m.rejected_touchdowns, m.failed_assessments = 3, 4_000_000_000
    return m


def plan() -> GaitPlan:
    m = GaitPlan()
    m.rule_set, m.evaluation, m.success, m.reason = "B", 3, True, "goal reached"
    m.states_expanded, m.states_generated = 36672, 123456
    for k in range(3):
        s = GaitStep(rule=k + 4, rule_name=f"leg {k} to max length and max angle", moving_leg=k - 1,
                     evaluation=0.5 * k, body=Pose2D(x=1.0 * k, y=-2.0, theta=0.25))
        s.feet[3] = Point(x=2.5, y=-1.5, z=0.0)
        m.steps.append(s)
    return m


def test_mobil_msgs_survive_a_round_trip_through_rust(start_node, ros_node):
    start_node("mobil_msgs_relay")
    t_pub = ros_node.create_publisher(TerrainAssessment, "terrain/assessment_in", 10)
    p_pub = ros_node.create_publisher(GaitPlan, "gait/plan_in", 10)
    sent_t, sent_p = terrain(), plan()
    with subscribe(ros_node, TerrainAssessment, "terrain/assessment_out", qos=10) as t_back, \
            subscribe(ros_node, GaitPlan, "gait/plan_out", qos=10) as p_back:
        publish_until(ros_node, t_pub, sent_t, lambda: len(t_back) > 0, rate_hz=10, timeout=15)
        publish_until(ros_node, p_pub, sent_p, lambda: len(p_back) > 0, rate_hz=10, timeout=15)
        assert t_back.latest == sent_t
        assert p_back.latest == sent_p
        assert p_back.latest.steps[2].moving_leg == 1
        assert list(t_back.latest.feet)[2].z == -0.02
