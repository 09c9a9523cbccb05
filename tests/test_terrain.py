"""terrain_node and hexapod_sim from real rclpy (ROS 2 Jazzy, Fast DDS), through exactly the
interfaces other programs rely on: `terrain/touchdown` (mobil_msgs/FootTouchdown, reliable depth
10) in, `terrain/assessment` (mobil_msgs/TerrainAssessment, latched) out.

Expected values are worked out by hand, not taken from the node:
* Table 1 (cm) at the default footholds of params/hexapod.yaml, 0.10 m below the body. Every
  column has mean 0, so σ² = Σz²/6: zero → 0; small [2, −1, −2, 0, 1, 0], Σz² = 10 →
  √(10/6) = 1.2910 cm; large [4, −3, 1, −4, 0, 2], Σz² = 46 → √(46/6) = 2.7689 cm (the paper's
  3.02 is a misprint, see docs/experiments/terrain-table1.md). α12 by Cramer's rule on the
  planes z = p·x + q·y + r: small 7.590°, large 19.276° (both > ε_α = 3°: UNEVEN); advice
  ripple up to σ_wave = 2.5 cm, wave above.
* A 10° slope rising ahead, walked with a level body: every foot on one plane, so α12 = 0 and
  α13 = α23 = 10°; the normal (−tan 10°, 0, 1) points downhill toward −x (180°); σ = tan 10° ·
  sd(foothold x) = 0.176327 · √0.015 = 2.1596 cm (the stride shifts every foot alike): SLOPE,
  ripple (σ ≤ σ_wave = 2.5 cm).
"""

from __future__ import annotations

import math

from geometry_msgs.msg import Point

from harness import make_qos, qos_latched, subscribe, wait_for_message, wait_until

from mobil_msgs.msg import FootTouchdown, TerrainAssessment

PARAMS = "params/hexapod.yaml"
LEGS = ["KP", "KV", "KG", "DP", "DV", "DG"]
# params/hexapod.yaml, /** footholds.
FOOTHOLDS = {"KP": (0.15, 0.12), "KV": (0.0, 0.16), "KG": (-0.15, 0.12),
             "DP": (0.15, -0.12), "DV": (0.0, -0.16), "DG": (-0.15, -0.12)}
TOUCHDOWN_QOS = make_qos("reliable", "volatile", 10)
# Matches the latched publisher, deep enough to keep every assessment of a burst.
RECORD_QOS = make_qos("reliable", "transient_local", 100)
ZERO = [0, 0, 0, 0, 0, 0]
SMALL = [2, -1, -2, 0, 1, 0]
LARGE = [4, -3, 1, -4, 0, 2]


def touchdown(leg: str, z_cm: float, sec: int, nanosec: int = 0, frame: str = "base_link",
              x: float | None = None, y: float | None = None) -> FootTouchdown:
    m = FootTouchdown()
    m.header.frame_id = frame
    m.header.stamp.sec, m.header.stamp.nanosec = sec, nanosec
    m.leg = leg
    fx, fy = FOOTHOLDS.get(leg, (0.0, 0.1))
    m.position = Point(x=fx if x is None else x, y=fy if y is None else y, z=-0.10 + z_cm / 100.0)
    return m


def send_column(pub, z_cm: list[float], sec: int) -> None:
    """The six feet of a column; the last (DG) is stamped (sec, 5)."""
    for k, (leg, z) in enumerate(zip(LEGS, z_cm)):
        pub.publish(touchdown(leg, z, sec, k))


def is_last_of(sec: int):
    return lambda a: (a.header.stamp.sec, a.header.stamp.nanosec) == (sec, 5)


def start_terrain(start_node, ros_node):
    start_node("terrain_node", params_file=PARAMS)
    pub = ros_node.create_publisher(FootTouchdown, "terrain/touchdown", TOUCHDOWN_QOS)
    wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
    return pub


def send_first_column(pub, rec, z_cm: list[float], sec: int):
    """The first column, sent again (same stamps, so the same assessment) until assessed: our
    writer sees the node's reader before the node's reader has matched our writer, and a
    volatile reader does not get what was written before it matched. Once one assessment is
    back, both sides are matched and no later touchdown is lost (reliable)."""
    for _ in range(20):
        send_column(pub, z_cm, sec)
        try:
            return rec.wait_for(is_last_of(sec), timeout=0.5)
        except TimeoutError:
            continue
    return rec.wait_for(is_last_of(sec), timeout=5)


def test_table1_columns_give_the_papers_sigma_and_a_late_subscriber_gets_the_last(start_node, ros_node):
    pub = start_terrain(start_node, ros_node)
    with subscribe(ros_node, TerrainAssessment, "terrain/assessment", qos=RECORD_QOS) as rec:
        got = {}
        got[1] = send_first_column(pub, rec, ZERO, 1)
        for sec, column in [(2, SMALL), (3, LARGE)]:
            send_column(pub, column, sec)
            got[sec] = rec.wait_for(is_last_of(sec), timeout=10)
    zero, small, large = got[1], got[2], got[3]
    assert zero.sigma == 0.0
    assert max(zero.alpha12, zero.alpha13, zero.alpha23) < 1e-12
    assert (zero.terrain_class, zero.advised_gait) == (TerrainAssessment.FLAT, TerrainAssessment.GAIT_TRIPOD)
    assert abs(small.sigma - math.sqrt(10 / 6) / 100) < 1e-9
    assert round(small.sigma * 100, 2) == 1.29
    assert abs(math.degrees(small.alpha12) - 7.590) < 1e-3
    assert (small.terrain_class, small.advised_gait) == (TerrainAssessment.UNEVEN, TerrainAssessment.GAIT_RIPPLE)
    assert abs(large.sigma - math.sqrt(46 / 6) / 100) < 1e-9
    assert abs(large.sigma * 100 - 2.769) < 5e-4
    assert abs(math.degrees(large.alpha12) - 19.276) < 1e-3
    assert (large.terrain_class, large.advised_gait) == (TerrainAssessment.UNEVEN, TerrainAssessment.GAIT_WAVE)
    assert large.header.frame_id == "base_link"
    # The feet in the message's order KP, KV, KG, DP, DV, DG: KG of the large column at
    # (−0.15, 0.12, −0.10 + 0.01).
    kg = large.feet[2]
    assert (kg.x, kg.y) == (-0.15, 0.12) and abs(kg.z + 0.09) < 1e-12
    # A subscriber created after the last publish gets the last assessment (latched).
    late = wait_for_message(ros_node, TerrainAssessment, "terrain/assessment", timeout=10,
                            qos=qos_latched())
    assert (late.header.stamp.sec, late.header.stamp.nanosec) == (3, 5)
    assert late.sigma == large.sigma
    assert (late.rejected_touchdowns, late.failed_assessments) == (0, 0)


def test_an_unknown_leg_a_nan_a_foreign_frame_and_collinear_feet_are_counted(start_node, ros_node):
    pub = start_terrain(start_node, ros_node)
    with subscribe(ros_node, TerrainAssessment, "terrain/assessment", qos=RECORD_QOS) as rec:
        good = send_first_column(pub, rec, SMALL, 1)
        pub.publish(touchdown("XY", 0.0, 2))
        after_leg = rec.wait_for(lambda a: a.rejected_touchdowns == 1, timeout=10)
        pub.publish(touchdown("KP", 0.0, 3, x=math.nan))
        after_nan = rec.wait_for(lambda a: a.rejected_touchdowns == 2, timeout=10)
        pub.publish(touchdown("KP", 0.0, 4, frame="odom"))
        after_frame = rec.wait_for(lambda a: a.rejected_touchdowns == 3, timeout=10)
        # KP on the line through KG (−0.15, 0.12, −0.12) and DV (0, −0.16, −0.09), one more
        # step beyond DV: (0.15, −0.44, −0.06). Plane 1 is undefined: the foot is stored, the
        # failure counted, the last good assessment kept.
        pub.publish(touchdown("KP", 4.0, 5, x=0.15, y=-0.44))
        after_line = rec.wait_for(lambda a: a.failed_assessments == 1, timeout=10)
    for a in (after_leg, after_nan, after_frame, after_line):
        # The last good assessment stays: its stamp and values.
        assert (a.header.stamp.sec, a.header.stamp.nanosec) == (1, 5)
        assert a.sigma == good.sigma and a.alpha12 == good.alpha12
        assert a.terrain_class == TerrainAssessment.UNEVEN
    assert (good.rejected_touchdowns, good.failed_assessments) == (0, 0)
    assert after_frame.failed_assessments == 0
    assert (after_line.rejected_touchdowns, after_line.failed_assessments) == (3, 1)


def test_hexapod_sim_on_a_10_degree_slope_gives_slope(start_node, ros_node):
    start_node("terrain_node", params_file=PARAMS)
    start_node("hexapod_sim", "-p", "ground:=slope", "-p", "slope_deg:=10.0", "-p",
               "wait_for_subscriber:=true", params_file=PARAMS)
    with subscribe(ros_node, TerrainAssessment, "terrain/assessment", qos=RECORD_QOS) as rec:
        # Real time: a tripod (three assessments) lands every 0.5 s. By the eighth assessment
        # both tripods have stepped at least once, whether or not the standing feet at t = 0
        # were lost in discovery, so every stored foot lands half a stride ahead.
        seen = rec.wait_count(8, timeout=15)
    for a in seen:
        assert a.terrain_class == TerrainAssessment.SLOPE
        assert math.degrees(a.alpha12) < 1e-6
        assert abs(math.degrees(a.alpha13) - 10.0) < 1e-6
        assert abs(math.degrees(a.alpha23) - 10.0) < 1e-6
        for plane in a.planes[:2]:
            assert abs(abs(plane.downhill) - math.pi) < 1e-6, "downhill is −x, behind"
            assert abs(math.degrees(plane.theta_x) + 10.0) < 1e-6
    last = seen[-1]
    assert abs(last.sigma - math.tan(math.radians(10)) * math.sqrt(0.015)) < 1e-6
    assert last.advised_gait == TerrainAssessment.GAIT_RIPPLE
