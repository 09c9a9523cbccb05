"""planner_node's VFO waypoint following end to end, from real rclpy: sim_node (LIDAR on, the
built-in world) + chassis_node + planner_node with ``waypoint_method: vfo`` (params/omr3.yaml),
under the simulated clock at 5× real time (at least 2× asserted: harness.MIN_REAL_TIME_FACTOR).

An rclpy FollowWaypoints ActionClient sends four waypoints through the world's clutter: past the
pillar at (1, 1.5) (the first leg runs straight through it), toward the box at x ≥ 4.5, back
west, and north past the pillar again (the last leg passes 0.67 m from its centre, inside its
influence zone). The second waypoint, (3.6, 0.3), lies 0.9 m from the box's face, inside the
influence zones of the circles that cover it (R = r + 0.4 m), where Algorithm 3 may pass it
early (SPEC §5): the robot then stands still before the next segment is optimised, so the
virtual robots start where the real one really is (nodes/planner_node/tests/vfo_world.rs
reproduces the run that once ended there, without DDS). planner_node knows no map: the
obstacles come from the LIDAR.
Checked from ``ground_truth`` (sim_node's plant, not the odometry the node follows) and from the
action and topics:

* SUCCEEDED with no missed waypoint and error code NONE; the feedback's current_waypoint ran
  0 → 3 in order;
* no collision: the reference point's clearance from the world geometry (params/worlds/default.yaml,
  computed here, as in test_local_nav_scenarios.py) stayed above the robot radius (0.25 m) all
  the way; sim_node's own collision radius is 0.05 m so that its bumper does not hide a near miss;
* the end: odometry within ϵ = 0.05 m of the last waypoint (the follower's end test includes the
  heading), the truth within that plus 1 % of the path (odometry drift), at rest;
* planner/status in mode ``vfo`` carried a segment's optimisation (virtual robots, a finite Ψ_z),
  and planner/markers drew virtual robots' paths, the chosen path and obstacles with r and R.

Measured on the 2-core build machine with other builds running: about 46 simulated seconds of
driving (about 10 s of wall time).
"""

from __future__ import annotations

import math
import time

import pytest
import yaml

from action_client import ActionClient
from harness import MIN_REAL_TIME_FACTOR, ROOT, make_qos, qos_latched, subscribe, wait_until
from test_local_nav_scenarios import clearance, load_world

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import Odometry
from visualization_msgs.msg import Marker, MarkerArray

REAL_TIME_FACTOR = 5.0
MIN_FACTOR = MIN_REAL_TIME_FACTOR
PARAMS = "params/omr3.yaml"
# Watchdogs (steady clock) at 2 s: a machine busy with other builds stalls /clock for a moment
# now and then (test_scenario.py).
CHASSIS_ARGS = ("-p", "feedback_timeout_s:=2.0")
PLANNER_ARGS = ("-p", "use_sim_time:=true", "-p", "odom_timeout_s:=2.0", "-p", "clock_timeout_s:=2.0",
                "-p", "vfo.scan_timeout_s:=2.0",
                "-p", "status_rate_hz:=20.0", "-p", "markers_rate_hz:=2.0")
SIM_COLLISION_RADIUS = 0.05
# Through the clutter of the built-in world from (0, 0) facing east (see the module docstring).
WAYPOINTS = [(2.0, 2.6), (3.6, 0.3), (1.0, -0.3), (0.0, 2.2)]
FINAL_EPSILON = 0.05
ODOM_DRIFT_PER_M = 0.01
SIM_BUDGET_S = 90.0


def stamped(x: float, y: float) -> PoseStamped:
    g = PoseStamped()
    g.header.frame_id = "odom"
    g.pose.position.x, g.pose.position.y = float(x), float(y)
    g.pose.orientation.w = 1.0
    return g


def seconds(stamp) -> float:
    return stamp.sec + stamp.nanosec * 1e-9


def test_route_geometry_by_hand():
    """The first leg really runs through the pillar at (1, 1.5), r 0.3: its distance from the
    line (0, 0)–(2, 2.6) is |2.6·1 − 2·1.5| / √(2² + 2.6²) = 0.4 / 3.280 = 0.122 m; and every
    waypoint is free (clearance above the robot radius)."""
    shapes = load_world(ROOT / "params" / "worlds" / "default.yaml")
    ax, ay = WAYPOINTS[0]
    d = abs(ay * 1.0 - ax * 1.5) / math.hypot(ax, ay)
    assert d == pytest.approx(0.1220, abs=1e-4)
    assert d < 0.3
    # The last leg (1, −0.3)–(0, 2.2): |(−1)·(1.5 + 0.3) − 2.5·0| / √(1 + 6.25) = 1.8 / 2.693 = 0.668 m
    # from the pillar's centre, outside r = 0.3 + 0.25 and inside R = r + 0.4.
    (cx, cy), (dx, dy) = WAYPOINTS[2], WAYPOINTS[3]
    d = abs((dx - cx) * (1.5 - cy) - (dy - cy) * (1.0 - cx)) / math.hypot(dx - cx, dy - cy)
    assert d == pytest.approx(0.6685, abs=1e-4)
    assert 0.55 < d < 0.95
    for w in WAYPOINTS:
        assert clearance(shapes, w) > 0.25 + 0.2, w


@pytest.mark.timeout(150)
def test_omr3_follows_waypoints_through_clutter_by_vfo(start_scenario, start_node, sim_clock, ros_node):
    from mobil_msgs.msg import NavStatus
    from nav2_msgs.action import FollowWaypoints

    shapes = load_world(ROOT / "params" / "worlds" / "default.yaml")
    data = yaml.safe_load((ROOT / PARAMS).read_text())
    radius = float(data["/**"]["ros__parameters"]["robot_radius"])
    assert data["planner"]["ros__parameters"]["waypoint_method"] == "vfo"
    start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR, lidar=True,
                   sim_args=("-p", f"robot_radius:={SIM_COLLISION_RADIUS}"), node_args=CHASSIS_ARGS)
    planner = start_node("planner_node", *PLANNER_ARGS, params_file=PARAMS)
    client = ActionClient(ros_node, FollowWaypoints, "follow_waypoints")
    deep = make_qos("reliable", "volatile", 5000)
    feedback: list[int] = []
    with subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth, \
            subscribe(ros_node, Odometry, "odom", qos=deep) as odom, \
            subscribe(ros_node, NavStatus, "planner/status", qos=make_qos("reliable", "transient_local", 5000)) \
            as status, \
            subscribe(ros_node, MarkerArray, "planner/markers", qos=make_qos("reliable", "volatile", 100)) \
            as markers:
        sim_clock.wait_started(timeout=10)
        truth.wait_for(None, timeout=10)
        # The planner has odometry and has put a scan's obstacles into its map: a goal now starts.
        planner.wait_for_log(r"first scan: \d+ beams", timeout=20)
        assert client.wait_for_server(timeout_sec=10)
        goal = FollowWaypoints.Goal()
        goal.poses = [stamped(x, y) for x, y in WAYPOINTS]
        handle = None
        for _ in range(4):
            future = client.send_goal_async(goal, feedback_callback=lambda f: feedback.append(
                f.feedback.current_waypoint))
            if wait_until(future.done, 3.0):
                handle = future.result()
                break
        assert handle is not None and handle.accepted, "goal not accepted"
        t_goal = sim_clock.now()
        mark = sim_clock.mark()
        result = None
        deadline = time.monotonic() + SIM_BUDGET_S / MIN_FACTOR + 10.0
        futures = []
        while result is None and time.monotonic() < deadline:
            futures.append(handle.get_result_async())
            if wait_until(lambda: any(f.done() for f in futures), 5.0):
                result = next(f for f in futures if f.done()).result()
        assert result is not None, "no result in time"
        t_end = sim_clock.now()
        factor = sim_clock.factor(since=mark)
        t_rest = t_end + 1.0
        sim_clock.wait_until(t_rest, timeout=10)
        rest = truth.wait_for(lambda m: seconds(m.header.stamp) >= t_rest, timeout=5)
        odom_end = odom.wait_for(lambda m: seconds(m.header.stamp) >= t_rest, timeout=5)
        truths = truth.snapshot()
        statuses = status.snapshot()
        arrays = markers.snapshot()

    xy = [(m.pose.pose.position.x, m.pose.pose.position.y) for m in truths]
    path = sum(math.dist(a, b) for a, b in zip(xy, xy[1:]))
    closest = min(xy, key=lambda p: clearance(shapes, p))
    min_clear = clearance(shapes, closest)
    end = xy[-1]
    vfo = [s for s in statuses if s.mode == "vfo" and s.virtual_robots > 0]
    print(f"vfo route: {result.result.error_msg} after {t_end - t_goal:.1f} simulated s at {factor:.2f}× "
          f"real time; path {path:.1f} m; closest {min_clear:.3f} m at ({closest[0]:.2f}, {closest[1]:.2f}); "
          f"end ({end[0]:.3f}, {end[1]:.3f}); most virtual robots {max((s.virtual_robots for s in vfo), default=0)}")

    assert result.status == GoalStatus.STATUS_SUCCEEDED, result.result.error_msg
    assert result.result.error_code == 0
    assert list(result.result.missed_waypoints) == []
    assert factor >= MIN_FACTOR, f"{factor:.2f}× real time, asked {REAL_TIME_FACTOR}×"
    assert t_end - t_goal <= SIM_BUDGET_S
    assert min_clear > radius, f"ground truth {min_clear:.3f} m from an obstacle at {closest}"
    # Feedback: every waypoint in order, none skipped.
    seen = [w for i, w in enumerate(feedback) if i == 0 or w != feedback[i - 1]]
    assert seen == [0, 1, 2, 3], seen
    # The end: odometry within ϵ of the last waypoint, the truth within ϵ plus the drift.
    last = WAYPOINTS[-1]
    o = odom_end.pose.pose.position
    assert math.dist((o.x, o.y), last) <= FINAL_EPSILON + 1e-3
    assert math.dist(end, last) <= FINAL_EPSILON + ODOM_DRIFT_PER_M * path
    tw = rest.twist.twist
    assert math.hypot(tw.linear.x, tw.linear.y) < 0.01 and abs(tw.angular.z) < 0.02, tw
    # The status carried the segments' optimisations; the markers drew them.
    assert vfo, "no vfo status with an optimisation"
    assert any(math.isfinite(s.psi_z) and s.candidates >= 1 for s in vfo)
    assert {s.waypoint_index for s in vfo} == {0, 1, 2, 3}
    assert statuses[-1].state == NavStatus.SUCCEEDED
    namespaces = {m.ns for a in arrays for m in a.markers}
    assert {"vfo_robots", "vfo_chosen", "vfo_forbidden", "vfo_influence"} <= namespaces, namespaces
    for a in arrays:
        discs = {m.ns: m for m in a.markers if m.type == Marker.CYLINDER}
        if "vfo_forbidden" in discs:
            # R = r + influence_margin (0.4 m): the influence disc is 0.8 m wider.
            r_disc = next(m for m in a.markers if m.ns == "vfo_forbidden")
            big = next(m for m in a.markers if m.ns == "vfo_influence" and m.id == r_disc.id)
            assert big.scale.x - r_disc.scale.x == pytest.approx(0.8, abs=1e-9)
            # r = the fitted radius + the robot's 0.25 m: at least 0.25 m.
            assert r_disc.scale.x / 2 >= radius


@pytest.mark.timeout(120)
def test_vfo_goal_needs_a_fresh_scan_and_ends_stale_when_scans_stop(start_scenario, start_node, sim_clock,
                                                                    ros_node):
    """The scans reach planner_node only through a relay in this test (``scan`` remapped to
    ``scan_relay``). A goal sent before any scan arrived is refused STALE_INPUT; with the relay
    on the goal starts; when the relay stops
    mid-route, the goal ends STALE_INPUT within vfo.scan_timeout_s (0.5 s, steady clock) plus
    the 20 Hz watchdog, the robot is sent the zero command, and the waypoints not reached are
    listed (code 105)."""
    from geometry_msgs.msg import Twist
    from mobil_msgs.msg import NavStatus
    from nav2_msgs.action import FollowWaypoints
    from rclpy.qos import qos_profile_sensor_data
    from sensor_msgs.msg import LaserScan

    start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR, lidar=True,
                   sim_args=("-p", f"robot_radius:={SIM_COLLISION_RADIUS}"), node_args=CHASSIS_ARGS)
    planner = start_node("planner_node", "-p", "use_sim_time:=true", "-p", "odom_timeout_s:=2.0",
                         "-p", "clock_timeout_s:=2.0",
                         "-p", "vfo.scan_timeout_s:=0.5", "-r", "scan:=scan_relay", params_file=PARAMS)
    relay_on = [False]
    relay_pub = ros_node.create_publisher(LaserScan, "scan_relay", qos_profile_sensor_data)
    relay_sub = ros_node.create_subscription(
        LaserScan, "scan", lambda m: relay_pub.publish(m) if relay_on[0] else None, qos_profile_sensor_data)
    client = ActionClient(ros_node, FollowWaypoints, "follow_waypoints")
    goal = FollowWaypoints.Goal()
    goal.poses = [stamped(x, y) for x, y in WAYPOINTS]

    def run_goal():
        handle = None
        for _ in range(4):
            future = client.send_goal_async(goal)
            if wait_until(future.done, 3.0):
                handle = future.result()
                break
        assert handle is not None and handle.accepted, "goal not accepted"
        return handle

    def result_of(handle, timeout: float):
        future = handle.get_result_async()
        assert wait_until(future.done, timeout), "no result in time"
        return future.result()

    try:
        with subscribe(ros_node, NavStatus, "planner/status", qos=make_qos("reliable", "transient_local", 5000)) \
                as status, subscribe(ros_node, Twist, "cmd_vel", qos=make_qos("reliable", "volatile", 5000)) as cmd:
            sim_clock.wait_started(timeout=10)
            planner.wait_for_log(r"chassis, pre-check world", timeout=20)
            assert client.wait_for_server(timeout_sec=10)
            # No scan yet: refused at once (the robot never moved).
            r = result_of(run_goal(), 10.0)
            assert r.status == GoalStatus.STATUS_ABORTED, r
            assert r.result.error_msg.startswith("STALE_INPUT: scan stale"), r.result.error_msg
            assert not cmd.snapshot() or all(m.linear.x == 0.0 for m in cmd.snapshot())
            # Scans flow: the goal starts and the robot drives.
            relay_on[0] = True
            planner.wait_for_log(r"first scan: \d+ beams", timeout=20)
            handle = run_goal()
            status.wait_for(lambda s: s.mode == "vfo" and s.state == NavStatus.ACTIVE and s.virtual_robots > 0,
                            timeout=15)
            cmd.wait_for(lambda m: abs(m.linear.x) > 0.05, timeout=15)
            # The scans stop mid-route.
            seen = len(status)
            relay_on[0] = False
            t_stop = time.monotonic()
            r = result_of(handle, 10.0)
            waited = time.monotonic() - t_stop
            assert r.status == GoalStatus.STATUS_ABORTED, r
            assert r.result.error_msg.startswith("STALE_INPUT: scan stale"), r.result.error_msg
            missed = [m.index for m in r.result.missed_waypoints]
            assert missed and missed == list(range(missed[0], 4)), missed
            assert {m.error_code for m in r.result.missed_waypoints} == {105}
            # 0.5 s of timeout, the 50 ms watchdog tick, the result's round trip.
            assert waited < 0.5 + 1.5, f"{waited:.2f} s"
            end = status.wait_for(lambda s: s.state == NavStatus.FAILED, timeout=5, start=seen)
            assert "STALE_INPUT" in end.reason, end.reason
            time.sleep(0.3)
            last = cmd.snapshot()[-1]
            assert (last.linear.x, last.linear.y, last.angular.z) == (0.0, 0.0, 0.0), last
    finally:
        ros_node.destroy_subscription(relay_sub)
        ros_node.destroy_publisher(relay_pub)
