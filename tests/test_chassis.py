"""chassis_node and sim_node driven by real rclpy (ROS 2 Jazzy, Fast DDS).

Every expected number is worked out by hand from the SPEC's formulas (see the comments), not
taken from the nodes' output.
"""

from __future__ import annotations

import math
import os
import signal
import subprocess
import sys
import time

import pytest

import harness
import rosutil
from harness import collect, param_get, param_list, param_set, publish_until, subscribe, wait_for_message

from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import Twist
from mobil_msgs.msg import ChassisStatus
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState, LaserScan

ROBOTS = ["mobil2", "omr3", "tricycle"]
# No LIDAR where a test does not look at scans: keeps the 2-core test machine unloaded.
NO_LIDAR = ("-p", "lidar.enabled:=false")


def twist(vx: float = 0.0, vy: float = 0.0, wz: float = 0.0) -> Twist:
    t = Twist()
    t.linear.x, t.linear.y, t.angular.z = float(vx), float(vy), float(wz)
    return t


def yaw(msg: Odometry) -> float:
    q = msg.pose.pose.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def xy(msg: Odometry) -> tuple[float, float]:
    return msg.pose.pose.position.x, msg.pose.pose.position.y


def start_robot(start_node, robot: str, *extra: str, lidar: bool = False):
    params = f"params/{robot}.yaml"
    sim_args = extra if lidar else (*NO_LIDAR, *extra)
    sim = start_node("sim_node", *sim_args, params_file=params)
    chassis = start_node("chassis_node", *extra, params_file=params)
    return sim, chassis


# Commanded twist per robot (at base_link) and what the kinematics make of it at steady state.
# mobil2: v = 0.3, ω = 0.2 → radius 1.5 m ≥ 0.73 m: feasible, kept.
# omr3: vx = 0.2, vy = 0.1, ω = 0.3: an omni chassis follows all three.
# tricycle: v = 0.3, ω = 0.4 → radius 0.75 m ≥ 0.25 m and δ = atan(0.5·0.4/0.3) = 33.7° < 60°.
COMMANDS = {"mobil2": (0.3, 0.0, 0.2), "omr3": (0.2, 0.1, 0.3), "tricycle": (0.3, 0.0, 0.4)}
# Radius of the circle base_link (the point the topics report) then runs on, by hand:
# mobil2: a car-like chassis drops the sideways part, so its rear-axle centre runs at v = 0.3 on
#   R = v/ω = 1.5 m; base_link sits d = 0.30 m ahead of the axle, on the radius through the
#   rear axle's normal: R_ref = sqrt(R² + d²) = sqrt(2.25 + 0.09) = 1.52971 m (2 % more than R),
#   and moves sideways at ω·d = 0.06 m/s in its own frame;
# omr3: |v| / ω = sqrt(0.2² + 0.1²) / 0.3 = 0.223607 / 0.3 = 0.745356 m;
# tricycle: base_link is the rear-axle centre: 0.3 / 0.4 = 0.75 m.
RADIUS = {"mobil2": 1.529706, "omr3": 0.745356, "tricycle": 0.75}
SIDEWAYS = {"mobil2": 0.06, "omr3": 0.1, "tricycle": 0.0}


def stamp(msg) -> tuple[int, int]:
    return msg.header.stamp.sec, msg.header.stamp.nanosec


def seconds(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


# A real-time drive timed by the test: in the closed-loop group, never beside a simulation at 5×
# or the soak (a late odometry sample shortens the window it measures).
@pytest.mark.closed_loop
@pytest.mark.parametrize("robot", ROBOTS)
def test_cmd_vel_moves_odom_as_the_kinematics_predict(robot, start_node, ros_node):
    start_robot(start_node, robot)
    vx, vy, wz = COMMANDS[robot]
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, Odometry, "odom") as odom, subscribe(ros_node, Odometry, "ground_truth") as truth:
        # Drive until the wheels have settled on the command (motor lag τ = 0.05 s: within
        # 1e-4 after about 0.4 s; without noise the odometry's twist converges exactly).
        publish_until(ros_node, cmd, twist(vx, vy, wz),
                      lambda: odom.latest is not None
                      and abs(odom.latest.twist.twist.angular.z - wz) < 1e-4
                      and abs(odom.latest.twist.twist.linear.x - vx) < 1e-4,
                      rate_hz=20, timeout=15)
        start_odom = odom.latest
        t0 = time.monotonic()
        while time.monotonic() - t0 < 3.0:
            cmd.publish(twist(vx, vy, wz))
            time.sleep(0.05)
        end_odom = odom.latest
        cmd.publish(twist())
        # The truth at the same instants: sim_node stamps joint_states and ground_truth alike,
        # and the odometry republishes the feedback's stamps. rclpy on a loaded machine may
        # lose a ground_truth sample, so each end of the window moves inward to the nearest
        # odom sample that has a truth sample within 1 ms of its stamp (the sim period is
        # 20 ms, so that is the same instant).
        truth.wait_for(lambda m: seconds(m) >= seconds(end_odom), timeout=5)
        window = [m for m in odom.snapshot() if seconds(start_odom) <= seconds(m) <= seconds(end_odom)]
        truths = truth.snapshot()

    def same_instant(m):
        nearest = min(truths, key=lambda g: abs(seconds(g) - seconds(m)))
        return nearest if abs(seconds(nearest) - seconds(m)) <= 1e-3 else None

    pairs = [(m, g) for m in window if (g := same_instant(m)) is not None]
    assert len(pairs) >= 2, f"{len(window)} odom samples in the window, {len(pairs)} with a truth sample"
    (start_odom, start_truth), (end_odom, end_truth) = pairs[0], pairs[-1]

    # Steady-state twist at base_link equals the command ahead and in rotation (body frame);
    # sideways it is the command for the omni chassis, ω·d for MOBIL-II.
    tw = end_odom.twist.twist
    assert tw.linear.x == pytest.approx(vx, abs=1e-3)
    assert tw.angular.z == pytest.approx(wz, abs=1e-3)
    assert tw.linear.y == pytest.approx(SIDEWAYS[robot], abs=1e-3)
    assert end_truth.twist.twist.linear.y == pytest.approx(SIDEWAYS[robot], abs=1e-3)
    # Over the window, heading changes by ω·Δt and base_link moves along the chord of its
    # circle, 2·R_ref·sin(ω·Δt / 2), in the odometry and in the truth alike. Without noise both
    # agree to about 1e-5; 0.1 % catches a 1 % error in the model (or MOBIL-II's rear-axle
    # radius, 2 % short).
    dt = seconds(end_odom) - seconds(start_odom)
    # 3 s of commands; the ends move inward when rclpy, on a loaded machine, delivers odom late
    # or loses a truth sample (seen: 2.5 s with two builds running beside the test).
    assert dt > 2.0
    dyaw = math.remainder(yaw(end_odom) - yaw(start_odom), math.tau)
    assert dyaw == pytest.approx(wz * dt, rel=0.001)
    (ox0, oy0), (ox1, oy1) = xy(start_odom), xy(end_odom)
    (gx0, gy0), (gx1, gy1) = xy(start_truth), xy(end_truth)
    odom_step, truth_step = math.hypot(ox1 - ox0, oy1 - oy0), math.hypot(gx1 - gx0, gy1 - gy0)
    chord = 2 * RADIUS[robot] * math.sin(wz * dt / 2)
    assert odom_step == pytest.approx(chord, rel=0.001)
    assert truth_step == pytest.approx(chord, rel=0.001)


@pytest.mark.closed_loop  # a real-time drive against 0.5 s watchdogs (test_actions.py, RUNNING_ALONE)
def test_car_like_turn_tighter_than_the_minimum_radius_is_clamped(start_node, ros_node):
    start_robot(start_node, "mobil2")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    # v = 0.3 with ω = 1.0 asks for a 0.3 m radius. MOBIL-II's effective limit is R_min = 0.73 m
    # (δ_eff = atan(0.60/0.73) = 39.4°, SPEC §1), so ω becomes 0.3/0.73 = 0.41096 rad/s.
    with subscribe(ros_node, ChassisStatus, "chassis/status") as status, subscribe(ros_node, Odometry, "odom") as odom:
        publish_until(ros_node, cmd, twist(0.3, 0.0, 1.0),
                      lambda: odom.latest is not None and odom.latest.twist.twist.angular.z > 0.40
                      and abs(odom.latest.twist.twist.angular.z - 0.41096) < 0.005,
                      rate_hz=20, timeout=15)
        # A status while the wheels turn (before the first joint_states the gate holds them,
        # the request's clamp flagged all the same).
        st = status.wait_for(lambda s: s.clamped & ChassisStatus.CLAMP_MIN_RADIUS
                             and not s.feedback_stale and not s.watchdog_expired, timeout=5)
        assert st.commanded.angular.z == pytest.approx(0.3 / 0.73, abs=1e-6)
        assert st.commanded.linear.x == pytest.approx(0.3, abs=1e-9)
        # A lateral request on a car is dropped and flagged.
        publish_until(ros_node, cmd, twist(0.2, 0.2, 0.0),
                      lambda: status.latest is not None and status.latest.clamped & ChassisStatus.CLAMP_LATERAL,
                      rate_hz=20, timeout=5)
        assert status.latest.commanded.linear.y == 0.0
        cmd.publish(twist())


def circle_through(a, b, c) -> tuple[float, float, float]:
    """Centre (x, y) and radius of the circle through three points."""
    (ax, ay), (bx, by), (cx, cy) = a, b, c
    d = 2 * (ax * (by - cy) + bx * (cy - ay) + cx * (ay - by))
    ux = ((ax * ax + ay * ay) * (by - cy) + (bx * bx + by * by) * (cy - ay) + (cx * cx + cy * cy) * (ay - by)) / d
    uy = ((ax * ax + ay * ay) * (cx - bx) + (bx * bx + by * by) * (ax - cx) + (cx * cx + cy * cy) * (bx - ax)) / d
    return ux, uy, math.hypot(ax - ux, ay - uy)


# Closed loop in real time: the route's legs are timed by this process's sleeps, so a worker
# beside it that takes the CPU shortens the drive (4.62 m of 5.07 once, beside the fuzz test).
@pytest.mark.closed_loop
def test_odometry_within_half_a_percent_of_ground_truth_over_a_5_m_route(start_node, ros_node):
    """An rclpy program drives the simulated MOBIL-II over 5 m with cmd_vel (no noise).

    By hand: the rear-axle centre runs 2 m straight along y = 0, a quarter turn of radius
    R = v/ω = 0.4/0.4 = 1 m about a centre 1 m to its left (y = 1), then straight on. base_link,
    the point the topics report, sits d = 0.30 m ahead of the axle: on the turn it keeps
    R_ref = sqrt(R² + d²) = sqrt(1.09) = 1.04403 m from the same centre (not R: 4.4 % more), so
    it drives 2 + (π/2)·1.04403 + (3 − π/2) = 5.0691 m in all, plus the little it covers before
    the test sees it move. The turn's circle does not depend on timing, so it is checked
    tightly, on the truth and on the odometry: 0.3 % on the radius, 3 mm on the centre line.
    """
    start_robot(start_node, "mobil2")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    # 2 m straight, a quarter turn on a 1 m radius (π/2 m), then straight to 5 m in all.
    route = [(0.4, 0.0, 2.0 / 0.4), (0.4, 0.4, (math.pi / 2) / 0.4), (0.4, 0.0, (3.0 - math.pi / 2) / 0.4)]
    with subscribe(ros_node, Odometry, "odom") as odom, subscribe(ros_node, Odometry, "ground_truth") as truth:
        odom.wait_for(None, 10)
        truth.wait_for(None, 10)
        # The route starts once the commands demonstrably arrive (the first ones may be lost
        # while discovery completes).
        publish_until(ros_node, cmd, twist(0.4, 0.0, 0.0),
                      lambda: truth.latest is not None and truth.latest.pose.pose.position.x > 0.01,
                      rate_hz=50, timeout=15)
        for v, w, duration in route:
            t0 = time.monotonic()
            while time.monotonic() - t0 < duration:
                cmd.publish(twist(v, 0.0, w))
                time.sleep(0.02)
        t0 = time.monotonic()
        while time.monotonic() - t0 < 1.0:
            cmd.publish(twist())
            time.sleep(0.05)
        truths, odoms = truth.snapshot(), odom.snapshot()
        final_odom, final_truth = xy(odom.latest), xy(truth.latest)
    path = [xy(m) for m in truths]
    driven = sum(math.dist(a, b) for a, b in zip(path, path[1:]))
    # Timing-dependent (Python's sleeps, DDS latency): a sanity check only.
    assert driven == pytest.approx(5.07, rel=0.05)
    # On the turn, well clear of the steering transients (0.5 s = 10 τ after its start and
    # before its end, at ω = 0.4 rad/s: headings 0.2 to π/2 − 0.2), base_link stays on the
    # hand-worked circle.
    for name, msgs in (("ground_truth", truths), ("odom", odoms)):
        turn = [xy(m) for m in msgs if 0.2 < yaw(m) < math.pi / 2 - 0.2]
        assert len(turn) > 50, f"{name}: {len(turn)} samples on the turn"
        cx, cy, radius = circle_through(turn[0], turn[len(turn) // 2], turn[-1])
        assert radius == pytest.approx(math.sqrt(1.0 + 0.3 ** 2), rel=0.001), name
        assert cy == pytest.approx(1.0, abs=0.001), name
        assert max(abs(math.dist(p, (cx, cy)) - radius) for p in turn) < 0.001, name
    # Noise-free odometry ends where the truth does, within 0.5 % of the distance (in-process
    # it is within 0.15 %; see nodes/sim/tests/odometry_vs_truth.rs).
    error = math.dist(final_odom, final_truth)
    assert error < 0.005 * driven, f"odometry off by {error:.4f} m over {driven:.2f} m"


def test_watchdog_zeroes_wheel_commands_when_cmd_vel_stops(start_node, ros_node):
    # chassis_node alone, as on a robot whose feedback is not wired yet: the feedback watchdog
    # off, the cmd_vel watchdog at its 0.5 s default.
    start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file="params/omr3.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands") as wheels:
        # OMR-III, body-x at 0.3 m/s with r = 0.05: Ω = (0.3/0.05)·[1, −½, −½] = [6, −3, −3] rad/s.
        publish_until(ros_node, cmd, twist(0.3), lambda: wheels.latest is not None
                      and wheels.latest.velocity[0] == pytest.approx(6.0, abs=1e-9), rate_hz=20, timeout=10)
        assert list(wheels.latest.velocity) == pytest.approx([6.0, -3.0, -3.0], abs=1e-9)
        last_cmd = time.monotonic()
        start = len(wheels)
        stopped = wheels.wait_for(lambda m: all(v == 0.0 for v in m.velocity), timeout=3, start=start)
        elapsed = time.monotonic() - last_cmd
        assert stopped.name == ["wheel_1", "wheel_2", "wheel_3"]
    # 0.5 s timeout checked at the 50 Hz control rate, plus DDS latency.
    assert 0.45 < elapsed < 0.9, f"wheels stopped {elapsed:.3f} s after the last cmd_vel"
    st = wait_for_message(ros_node, ChassisStatus, "chassis/status", lambda s: s.watchdog_expired, timeout=5)
    assert st.commanded.linear.x == 0.0


def test_nan_twist_stops_at_once_and_is_counted(start_node, ros_node):
    chassis = start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file="params/omr3.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands") as wheels, \
            subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        publish_until(ros_node, cmd, twist(0.3), lambda: wheels.latest is not None
                      and wheels.latest.velocity[0] > 5.9, rate_hz=20, timeout=10)
        start = len(wheels)
        cmd.publish(twist(float("nan"), 0.0, 0.1))
        stopped = wheels.wait_for(lambda m: all(v == 0.0 for v in m.velocity), timeout=0.3, start=start)
        assert all(math.isfinite(v) for v in stopped.velocity)
        st = status.wait_for(lambda s: s.rejected_messages >= 1 and s.clamped & ChassisStatus.CLAMP_NON_FINITE, timeout=3)
        assert st.commanded.linear.x == 0.0
        cmd.publish(twist(float("inf")))
    assert chassis.running
    chassis.wait_for_log("NaN/inf", timeout=5)


def joint_state(stamp_s: float, names, positions, velocities) -> JointState:
    js = JointState()
    js.header.stamp.sec = int(stamp_s)
    js.header.stamp.nanosec = int(round((stamp_s - int(stamp_s)) * 1e9))
    js.name = list(names)
    js.position = [float(p) for p in positions]
    js.velocity = [float(v) for v in velocities]
    return js


OMNI_WHEELS = ["wheel_1", "wheel_2", "wheel_3"]


def prime_feedback(ros_node, fb, odom, t0: float, positions_only: bool = False) -> None:
    """Play an OMR-III at rest (stamps t0−1, t0−0.99, …) until chassis_node answers on odom,
    then one sample at rest stamped exactly t0, so that motion can start from there."""
    def rest(t: float) -> JointState:
        zeros = [0.0, 0.0, 0.0]
        return joint_state(t, OMNI_WHEELS, zeros, []) if positions_only else joint_state(t, OMNI_WHEELS, [], zeros)

    stamps = iter(t0 - 1.0 + 0.01 * k for k in range(100))
    publish_until(ros_node, fb, lambda: rest(next(stamps)), lambda: odom.latest is not None, rate_hz=10, timeout=9)
    fb.publish(rest(t0))


def test_diagnostics_report_stale_feedback_as_an_error_and_recover(start_node, ros_node):
    """/diagnostics, once a second and sooner when the level gets worse: OK while rclpy plays
    the wheels at rest, ERROR when joint_states stop, sent as the feedback watchdog (0.5 s)
    fires, so its own joint_states age is under 0.8 s (once a second alone: up to 1.5 s); OK
    again once they return."""
    start_node("chassis_node", "-p", "feedback_timeout_s:=0.5", params_file="params/omr3.yaml")
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    feeding = {"on": True, "ns": 100_000_000_000}

    def rest() -> None:
        if feeding["on"]:
            # Integer nanoseconds: a float sum would round a stamp to nanosec = 1e9 (refused).
            feeding["ns"] += 20_000_000
            js = joint_state(0.0, OMNI_WHEELS, [], [0.0, 0.0, 0.0])
            js.header.stamp.sec, js.header.stamp.nanosec = divmod(feeding["ns"], 1_000_000_000)
            fb.publish(js)

    timer = ros_node.create_timer(0.02, rest)
    ours = lambda m: next((s for s in m.status if s.name == "/chassis: watchdogs"), None)  # noqa: E731
    try:
        with subscribe(ros_node, DiagnosticArray, "/diagnostics", qos=harness.qos_default()) as diag:
            ok = diag.wait_for(lambda m: (s := ours(m)) is not None and s.level == DiagnosticStatus.OK, timeout=10)
            status = ours(ok)
            assert status.hardware_id == "omni" and status.message.startswith("idle"), status
            assert {"cmd_vel age [s]", "joint_states age [s]", "feedback watchdog"} <= {v.key for v in status.values}
            feeding["on"] = False
            stopped, seen = time.monotonic(), len(diag.snapshot())
            err = diag.wait_for(lambda m: (s := ours(m)) is not None and s.level == DiagnosticStatus.ERROR,
                                timeout=5, start=seen)
            assert time.monotonic() - stopped < 3.0, "no ERROR within 3 s"
            assert "joint_states" in ours(err).message, ours(err).message
            age = float(next(v.value for v in ours(err).values if v.key == "joint_states age [s]"))
            assert 0.5 <= age < 0.8, age
            feeding["on"], seen = True, len(diag.snapshot())
            diag.wait_for(lambda m: (s := ours(m)) is not None and s.level == DiagnosticStatus.OK, timeout=5,
                          start=seen)
    finally:
        ros_node.destroy_timer(timer)


def test_bad_joint_states_are_dropped_and_do_not_move_odometry(start_node, ros_node):
    """rclpy plays the robot: valid feedback, then mismatched arrays and time going backwards."""
    chassis = start_node("chassis_node", params_file="params/omr3.yaml")
    names = ["wheel_1", "wheel_2", "wheel_3"]
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.qos_default()) as odom, \
            subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        # At rest until t = 100 s, then body-x at 0.3 m/s (Ω = [6, −3, −3]) for 1 s in 0.1 s
        # steps: x = 0.3 m.
        t = 100.0
        prime_feedback(ros_node, fb, odom, t)
        for i in range(1, 11):
            fb.publish(joint_state(t + 0.1 * i, names, [], [6.0, -3.0, -3.0]))
        good = odom.wait_for(lambda m: m.header.stamp.sec == 101 and m.header.stamp.nanosec == 0, timeout=5)
        assert good.pose.pose.position.x == pytest.approx(0.3, abs=1e-9)
        rejected_before = status.wait_for(None, timeout=5).rejected_messages
        count_before = len(odom)
        # Three arrays of different lengths, a missing joint, NaN, then time going backwards
        # (0.2 s: an out-of-order sample; a jump beyond the feedback timeout restarts the clock).
        fb.publish(joint_state(101.1, names, [0.0], [6.0, -3.0, -3.0]))
        fb.publish(joint_state(101.2, names[:2], [], [6.0, -3.0]))
        fb.publish(joint_state(101.3, names, [], [float("nan"), -3.0, -3.0]))
        fb.publish(joint_state(100.8, names, [], [6.0, -3.0, -3.0]))
        status.wait_for(lambda s: s.rejected_messages >= rejected_before + 4, timeout=5)
        assert len(odom) == count_before, "a rejected sample published odometry"
        assert odom.latest.pose.pose.position.x == pytest.approx(0.3, abs=1e-9)
    assert chassis.running
    log = chassis.log_text()
    for reason in ("mismatched array lengths", "is missing", "non-finite value", "is not after the previous"):
        assert reason in log, f"no log line for {reason!r}"


def test_parameters_list_get_set_and_invalid_set_refused(start_node, ros_node, ros2cli):
    start_robot(start_node, "mobil2")
    assert harness.wait_for_node(ros_node, "/chassis", timeout=10)
    assert harness.wait_for_node(ros_node, "/sim", timeout=10)
    names = param_list(ros_node, "/chassis")
    for expected in ("model", "v_max", "cmd_vel_timeout_s", "wheelbase", "use_sim_time"):
        assert expected in names
    # params/mobil2.yaml sets v_max 0.5 and the wheelbase 0.60.
    assert param_get(ros_node, "/chassis", "v_max") == 0.5
    assert param_get(ros_node, "/chassis", "wheelbase") == 0.6
    ok = param_set(ros_node, "/chassis", "v_max", 0.3)
    assert ok.successful, ok.reason
    assert param_get(ros_node, "/chassis", "v_max") == 0.3
    for name, value, why in [("v_max", -1.0, "minimum"), ("v_max", "fast", "type"),
                             ("model", "omni", "read-only"), ("no_such_parameter", 1.0, "")]:
        res = param_set(ros_node, "/chassis", name, value)
        assert not res.successful, f"{name}={value!r} was accepted"
        assert why.lower() in res.reason.lower() or not why, res.reason
    assert param_get(ros_node, "/chassis", "v_max") == 0.3
    assert param_get(ros_node, "/chassis", "model") == "car_like"
    # The new limit is in force: 0.45 m/s is clamped to 0.3.
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        publish_until(ros_node, cmd, twist(0.45), lambda: status.latest is not None
                      and status.latest.commanded.linear.x == pytest.approx(0.3), rate_hz=20, timeout=10)
        assert status.latest.clamped & ChassisStatus.CLAMP_SPEED
        cmd.publish(twist())
    # The command-line tool does the same as `ros2 param get/set`.
    out = ros2cli("param", "get", "/chassis", "v_max")
    assert out.returncode == 0 and "0.3" in out.stdout, out.stdout + out.stderr
    out = ros2cli("param", "set", "/chassis", "cmd_vel_timeout_s", "-2")
    assert out.returncode == 1 and "failed" in out.stdout.lower() + out.stderr.lower()
    # describe_parameters answers from the same declarations (nodes/chassis_node/src/lib.rs):
    # v_max > 0, unbounded above; model read-only, one of three; an unknown name is NOT_SET.
    from rcl_interfaces.msg import ParameterType
    from rcl_interfaces.srv import DescribeParameters
    response = rosutil.call_service(ros_node, DescribeParameters, "/chassis/describe_parameters",
                                    DescribeParameters.Request(names=["v_max", "model", "no_such"]))
    v_max, model, unknown = response.descriptors
    assert (v_max.name, v_max.type, v_max.description) == ("v_max", ParameterType.PARAMETER_DOUBLE,
                                                           "speed limit [m/s]")
    assert not v_max.read_only
    assert len(v_max.floating_point_range) == 1 and not v_max.integer_range
    fp = v_max.floating_point_range[0]
    assert (fp.from_value, fp.to_value, fp.step) == (0.0, sys.float_info.max, 0.0)
    assert v_max.additional_constraints == "(0, ∞)", "the open lower bound, in words"
    assert model.read_only and model.type == ParameterType.PARAMETER_STRING
    assert model.additional_constraints == "one of tricycle, car_like, omni"
    assert not model.floating_point_range and not model.integer_range
    assert unknown.type == ParameterType.PARAMETER_NOT_SET


def test_sim_scan_sees_the_built_in_world(start_node, ros_node):
    start_robot(start_node, "mobil2", lidar=True)
    scan = wait_for_message(ros_node, LaserScan, "scan", timeout=10)
    assert len(scan.ranges) == 1081
    assert scan.angle_min == pytest.approx(-math.radians(135), abs=1e-6)
    assert scan.angle_increment == pytest.approx(math.radians(0.25), abs=1e-7)
    assert scan.header.frame_id == "laser"

    def beam(angle_deg: float) -> float:
        return scan.ranges[round((math.radians(angle_deg) - scan.angle_min) / scan.angle_increment)]

    # Robot at the origin facing +x (params/worlds/default.yaml): the box's west face at x = 4.5,
    # the north wall's inner face at y = 5.5, and the pillar of radius 0.3 at (1.0, 1.5) seen at
    # atan2(1.5, 1.0) = 56.31° from √(1 + 2.25) − 0.3 = 1.5028 m.
    assert beam(0.0) == pytest.approx(4.5, abs=1e-3)
    assert beam(90.0) == pytest.approx(5.5, abs=1e-3)
    assert beam(math.degrees(math.atan2(1.5, 1.0))) == pytest.approx(math.sqrt(3.25) - 0.3, abs=0.01)


def test_namespace_remap_moves_every_topic(start_node, ros_node):
    start_robot(start_node, "omr3", "-r", "__ns:=/robot1")
    odom = wait_for_message(ros_node, Odometry, "/robot1/odom", timeout=10)
    assert odom.child_frame_id == "base_link"
    assert harness.wait_for_node(ros_node, "/robot1/chassis", timeout=10)
    assert param_get(ros_node, "/robot1/chassis", "model") == "omni"


def test_help_lists_parameters_and_bad_arguments_fail():
    for exe in ("chassis_node", "sim_node"):
        out = subprocess.run([str(harness.resolve_executable(exe)), "--help"], capture_output=True, text=True, timeout=10)
        assert out.returncode == 0
        assert "--params-file" in out.stdout and "v_max" in out.stdout
    out = subprocess.run([str(harness.resolve_executable("chassis_node")), "--ros-args", "-p", "v_max:=-3"],
                         capture_output=True, text=True, timeout=10, env=harness.rosutil.ros_environ())
    assert out.returncode != 0 and "v_max" in out.stderr


def test_sigint_and_sigterm_stop_cleanly(start_node, ros_node):
    sim, chassis = start_robot(start_node, "mobil2")
    wait_for_message(ros_node, Odometry, "odom", timeout=10)
    chassis.proc.send_signal(signal.SIGTERM)
    assert chassis.wait(5) == 0
    sim.proc.send_signal(signal.SIGINT)
    assert sim.wait(5) == 0
    # The participants announced their departure: rclpy forgets the nodes.
    assert harness.wait_until(lambda: "/chassis" not in harness.rosutil.node_names(ros_node), timeout=5)


def test_use_sim_time_follows_a_clock_published_by_rclpy(start_node, ros_node):
    """A simulator's /clock (rosgraph_msgs/Clock from Fast DDS) drives the node's time."""
    from rosgraph_msgs.msg import Clock
    start_node("chassis_node", "-p", "use_sim_time:=true", params_file="params/omr3.yaml")
    clock = ros_node.create_publisher(Clock, "/clock", 10)

    def at(sec: int) -> Clock:
        c = Clock()
        c.clock.sec = sec
        return c

    with subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        publish_until(ros_node, clock, at(1000), lambda: status.latest is not None
                      and status.latest.header.stamp.sec == 1000, rate_hz=20, timeout=10)
        publish_until(ros_node, clock, at(2000), lambda: status.latest.header.stamp.sec == 2000,
                      rate_hz=20, timeout=10)


def test_a_stamp_far_in_the_future_costs_one_sample_not_the_odometry(start_node, ros_node):
    start_node("chassis_node", params_file="params/omr3.yaml")
    names = ["wheel_1", "wheel_2", "wheel_3"]
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.qos_default()) as odom:
        prime_feedback(ros_node, fb, odom, 60.0)
        # 0.3 m/s for 0.5 s, one sample stamped 1e6 s ahead, then 0.5 s more on the real clock.
        for i in range(1, 6):
            fb.publish(joint_state(60.0 + 0.1 * i, names, [], [6.0, -3.0, -3.0]))
        fb.publish(joint_state(1e6, names, [], [6.0, -3.0, -3.0]))
        fb.publish(joint_state(60.6, names, [], [6.0, -3.0, -3.0]))
        for i in range(7, 12):
            fb.publish(joint_state(60.0 + 0.1 * i, names, [], [6.0, -3.0, -3.0]))
        last = odom.wait_for(lambda m: m.header.stamp.sec == 61 and m.header.stamp.nanosec == 100_000_000, timeout=5)
    # 0.15 m before the bad stamp; after it the clock restarts at 60.6 and 60.7…61.1 add 0.15 m.
    assert last.pose.pose.position.x == pytest.approx(0.30, abs=1e-6)


def test_an_atomic_set_inconsistent_as_a_whole_leaves_a_consistent_node(start_node, ros_node):
    """Each value alone is valid; together (R_min 0.35 with track 1.2: the inner front wheel would
    steer past 90°, R_min must exceed B/2) they are not."""
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParametersAtomically
    start_node("chassis_node", params_file="params/mobil2.yaml")
    client = ros_node.create_client(SetParametersAtomically, "/chassis/set_parameters_atomically")
    assert client.wait_for_service(timeout_sec=10)

    def double(name: str, v: float) -> Parameter:
        return Parameter(name=name, value=ParameterValue(type=ParameterType.PARAMETER_DOUBLE, double_value=v))

    req = SetParametersAtomically.Request(parameters=[double("min_turning_radius", 0.35), double("track", 1.2)])
    future = None
    for _ in range(5):  # the first call after discovery can be lost (ROS2-NOTES)
        future = client.call_async(req)
        if harness.wait_until(future.done, timeout=2):
            break
    assert not future.result().result.successful
    # Whatever was applied, the node is consistent: R_min > B/2, and later sets still work.
    r_min = param_get(ros_node, "/chassis", "min_turning_radius")
    track = param_get(ros_node, "/chassis", "track")
    assert track == 0.62 and r_min > track / 2
    ok = param_set(ros_node, "/chassis", "v_max", 0.4)
    assert ok.successful, ok.reason


def test_position_only_encoders_are_differentiated(start_node, ros_node):
    """A driver that publishes wheel angles only (no velocity array): SPEC §1 allows either."""
    start_node("chassis_node", params_file="params/omr3.yaml")
    names = ["wheel_1", "wheel_2", "wheel_3"]
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.qos_default()) as odom:
        prime_feedback(ros_node, fb, odom, 30.0, positions_only=True)
        # Wheel angles growing at Ω = [6, −3, −3] rad/s (body-x at 0.3 m/s) for 1 s in 0.1 s steps.
        for i in range(1, 11):
            fb.publish(joint_state(30.0 + 0.1 * i, names, [0.6 * i, -0.3 * i, -0.3 * i], []))
        last = odom.wait_for(lambda m: m.header.stamp.sec == 31 and m.header.stamp.nanosec == 0, timeout=5)
    assert last.pose.pose.position.x == pytest.approx(0.3, abs=1e-6)
    assert last.twist.twist.linear.x == pytest.approx(0.3, abs=1e-6)


def test_topics_use_the_qos_of_the_interface_contract(start_node, ros_node):
    """Subscribe with the QoS INTERFACES.md promises (not the publishers' own): every topic
    delivers, and the latched status reaches a subscriber that joins late."""
    start_robot(start_node, "mobil2", lidar=True)
    reliable, sensor, latched = harness.qos_default(), harness.qos_sensor(), harness.qos_latched()
    for msg_type, topic, qos in [(Odometry, "odom", reliable), (Odometry, "ground_truth", reliable),
                                 (JointState, "joint_states", reliable), (JointState, "wheel_commands", reliable),
                                 (LaserScan, "scan", sensor), (ChassisStatus, "chassis/status", latched)]:
        wait_for_message(ros_node, msg_type, topic, timeout=10, qos=qos)


def test_watchdog_holds_under_use_sim_time_without_a_clock(start_node, ros_node):
    """With use_sim_time and no /clock at all, the cmd_vel watchdog still stops the wheels."""
    start_node("chassis_node", "-p", "use_sim_time:=true", "-p", "feedback_timeout_s:=0.0",
               params_file="params/omr3.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands") as wheels:
        publish_until(ros_node, cmd, twist(0.3), lambda: wheels.latest is not None
                      and wheels.latest.velocity[0] > 5.9, rate_hz=20, timeout=10)
        start = len(wheels)
        wheels.wait_for(lambda m: all(v == 0.0 for v in m.velocity), timeout=3, start=start)


def test_sim_publishes_the_world_for_rviz(start_node, ros_node):
    from visualization_msgs.msg import Marker, MarkerArray
    start_node("sim_node", *NO_LIDAR, params_file="params/mobil2.yaml")
    # Latched: a subscriber that joins after start-up still gets it.
    markers = wait_for_message(ros_node, MarkerArray, "sim/markers", timeout=10, qos=harness.qos_latched())
    # params/worlds/default.yaml: 4 walls, 3 pillars, a box, an L-shaped block, a triangle.
    kinds = [m.type for m in markers.markers]
    assert kinds.count(Marker.CYLINDER) == 3 and kinds.count(Marker.LINE_STRIP) == 7
    pillar = next(m for m in markers.markers if m.type == Marker.CYLINDER)
    assert (pillar.pose.position.x, pillar.pose.position.y, pillar.scale.x) == (1.0, 1.5, pytest.approx(0.6))


@pytest.mark.closed_loop
def test_sim_runs_faster_than_real_time_on_a_simulated_clock(start_node, ros_node):
    from rosgraph_msgs.msg import Clock
    start_node("sim_node", *NO_LIDAR, "-p", "publish_clock:=true", "-p", "real_time_factor:=4.0",
               params_file="params/mobil2.yaml")
    with subscribe(ros_node, Clock, "/clock", qos=harness.qos_sensor()) as clock:
        clock.wait_for(None, timeout=10)
        t0, c0 = time.monotonic(), clock.latest.clock
        time.sleep(2.0)
        t1, c1 = time.monotonic(), clock.latest.clock
    sim_dt = (c1.sec - c0.sec) + (c1.nanosec - c0.nanosec) * 1e-9
    factor = sim_dt / (t1 - t0)
    # Never ahead of the factor asked (15 % for the arrival times' jitter), and at least
    # harness.MIN_REAL_TIME_FACTOR however busy the machine (harness.py says why).
    assert harness.MIN_REAL_TIME_FACTOR <= factor <= 4.0 * 1.15, f"{factor:.2f}× real time, 4× asked"


def test_node_logs_reach_rosout(start_node, ros_node):
    """rqt_console and `ros2 topic echo /rosout` see the nodes' log lines, as rclcpp's."""
    from rcl_interfaces.msg import Log
    start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file="params/mobil2.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, Log, "/rosout") as rosout:
        publish_until(ros_node, cmd, twist(0.3, 0.0, 2.0),
                      lambda: any(m.name == "chassis" and "clamped" in m.msg for m in rosout.snapshot()),
                      rate_hz=10, timeout=10)
        line = next(m for m in rosout.snapshot() if "clamped" in m.msg)
        cmd.publish(twist())
    assert line.level == Log.WARN
    assert line.file.endswith("chassis_node/src/main.rs") and line.line > 0


CAR_JOINTS = ["front_left_steering", "front_right_steering", "rear_left_wheel", "rear_right_wheel"]


def stamp_s(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


@pytest.mark.parametrize("robot", ["omr3", "mobil2"])
def test_cmd_vel_without_any_joint_states_never_turns_a_wheel(robot, start_node, ros_node):
    """No joint_states at all: the odometry is blind, so no cmd_vel may reach the wheels."""
    start_node("chassis_node", params_file=f"params/{robot}.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands") as wheels, \
            subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        # 0.8 m/s is above v_max (0.5 m/s on both robots): CLAMP_SPEED in the status proves that
        # the node has the request.
        publish_until(ros_node, cmd, twist(0.8), lambda: status.latest is not None
                      and status.latest.clamped & ChassisStatus.CLAMP_SPEED, rate_hz=10, timeout=10)
        start = len(wheels)
        # 2 s more of cmd_vel at 10 Hz (each one used to be sent to the wheels as it was).
        t0 = time.monotonic()
        while time.monotonic() - t0 < 2.0:
            cmd.publish(twist(0.8))
            time.sleep(0.1)
        received = wheels.snapshot()
        assert status.latest.feedback_stale
        assert status.latest.commanded.linear.x == 0.0
    # The 50 Hz tick gives about 100 messages in 2 s (45 on a machine 2-3 times slower with the
    # other pytest worker busy): 20 show that the node went on sending while cmd_vel came.
    assert len(received) - start >= 20, f"only {len(received) - start} wheel_commands in 2 s"
    moving = [m for m in received if any(v != 0.0 for v in m.velocity)]
    assert not moving, f"{len(moving)} of {len(received)} wheel_commands were not zero: {moving[0]}"
    # Decision (docs/chassis_node.md): a stop holds the steering angles last sent; never sent, they are straight.
    assert all(p == 0.0 for m in received for p in m.position)


def test_wheels_stop_within_the_feedback_timeout_when_joint_states_stop(start_node, ros_node):
    """MOBIL-II driving on a curve; joint_states stop while cmd_vel goes on: the rear wheels stop
    within feedback_timeout_s (0.5 s) + one control period (20 ms) of the last feedback, and the
    steering holds its angles."""
    start_node("chassis_node", params_file="params/mobil2.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    # v = 0.3, ω = 0.2: R = 1.5 m (≥ 0.73 m). Ackermann (L 0.60, B 0.62): inner (left) wheel
    # atan(0.6/(1.5 − 0.31)) = 0.467003 rad, outer atan(0.6/(1.5 + 0.31)) = 0.320092 rad; rear
    # wheels (0.3 ∓ 0.2·0.31)/0.1 = 2.38 and 3.62 rad/s.
    left, right = math.atan(0.6 / (1.5 - 0.31)), math.atan(0.6 / (1.5 + 0.31))
    assert (left, right) == (pytest.approx(0.467003, abs=1e-6), pytest.approx(0.320092, abs=1e-6))

    def feedback() -> JointState:
        # Stamped with the system clock, as the node stamps wheel_commands (no use_sim_time).
        return joint_state(time.time(), CAR_JOINTS, [0.0] * 4, [0.0] * 4)

    with subscribe(ros_node, JointState, "wheel_commands") as wheels:
        k = 0

        def drive() -> JointState:
            nonlocal k
            k += 1
            if k % 5 == 0:
                cmd.publish(twist(0.3, 0.0, 0.2))
            return feedback()

        publish_until(ros_node, fb, drive, lambda: wheels.latest is not None
                      and wheels.latest.velocity[2] == pytest.approx(2.38, abs=1e-9), rate_hz=50, timeout=10)
        moving = wheels.latest
        assert list(moving.position[:2]) == pytest.approx([left, right], abs=1e-9)
        assert list(moving.velocity[2:]) == pytest.approx([2.38, 3.62], abs=1e-9)
        # The feedback stops; cmd_vel goes on at 10 Hz for 1.5 s.
        last = feedback()
        fb.publish(last)
        start = len(wheels)
        t0 = time.monotonic()
        while time.monotonic() - t0 < 1.5:
            cmd.publish(twist(0.3, 0.0, 0.2))
            time.sleep(0.1)
        after = wheels.snapshot()[start:]
    stopped_at = next(i for i, m in enumerate(after) if m.velocity[2] == 0.0 and m.velocity[3] == 0.0)
    # The node's watchdog counts from its receipt of the last sample, which the sample's stamp
    # precedes: at least the 0.5 s timeout (the behaviour); at most that, one 20 ms tick and slack
    # for DDS latency and scheduling on a loaded machine.
    delay = stamp_s(after[stopped_at]) - stamp_s(last)
    assert 0.49 < delay < 0.5 + 0.02 + 0.4, f"wheels stopped {delay:.3f} s after the last joint_states"
    # From then on every command is a stop, with the steering held where it was.
    for m in after[stopped_at:]:
        assert list(m.velocity[2:]) == [0.0, 0.0]
        assert list(m.position[:2]) == pytest.approx([left, right], abs=1e-9)
    assert len(after) - stopped_at >= 30, "too few wheel_commands after the stop to judge"


def test_a_nan_cmd_vel_is_logged_as_a_nan_not_as_a_timeout(start_node, ros_node):
    chassis = start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file="params/omr3.yaml")
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands") as wheels, \
            subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        # Drive until the control tick has seen the running command (watchdog not expired).
        publish_until(ros_node, cmd, twist(0.3), lambda: status.latest is not None
                      and not status.latest.watchdog_expired and status.latest.commanded.linear.x == 0.3,
                      rate_hz=20, timeout=10)
        cmd.publish(twist(float("nan")))
        status.wait_for(lambda s: s.clamped & ChassisStatus.CLAMP_NON_FINITE, timeout=3)
        # 75 more status messages at 50 Hz: 1.5 s, three times the 0.5 s cmd_vel timeout.
        status.wait_for(None, timeout=5, start=len(status) + 75)
        st = status.latest
    # The status still reports the stop.
    assert st.watchdog_expired and st.clamped & ChassisStatus.CLAMP_NON_FINITE
    assert (st.commanded.linear.x, st.commanded.angular.z) == (0.0, 0.0)
    assert all(v == 0.0 for v in wheels.latest.velocity)
    chassis.wait_for_log("NaN/inf", timeout=5)
    log = chassis.log_text()
    assert "no cmd_vel for" not in log, chassis.log_tail()


@pytest.mark.parametrize("robot,huge", [("omr3", [1e308, -1e308, 0.0]), ("mobil2", [0.0, 0.0, 1e308, 0.0])])
def test_impossible_wheel_speeds_are_refused_and_odometry_stays_finite(robot, huge, start_node, ros_node):
    chassis = start_node("chassis_node", params_file=f"params/{robot}.yaml")
    names = OMNI_WHEELS if robot == "omr3" else CAR_JOINTS
    rest = [0.0] * len(names)
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.qos_default()) as odom, \
            subscribe(ros_node, ChassisStatus, "chassis/status") as status:
        stamps = iter(50.0 + 0.02 * k for k in range(1000))
        publish_until(ros_node, fb, lambda: joint_state(next(stamps), names, rest, rest),
                      lambda: odom.latest is not None, rate_hz=20, timeout=10)
        # One marker sample: once its odom is in, no earlier one can follow (reliable, in order).
        mark = next(stamps)
        fb.publish(joint_state(mark, names, rest, rest))
        before = odom.wait_for(lambda m: stamp_s(m) == pytest.approx(mark, abs=1e-6), timeout=5)
        count = len(odom)
        status.wait_for(None, timeout=5)
        rejected = status.latest.rejected_messages
        t = next(stamps)
        fb.publish(joint_state(t, names, rest, huge))
        status.wait_for(lambda s: s.rejected_messages >= rejected + 1, timeout=5)
        # An ordinary sample after it is used again: the odometry is where it was, and finite.
        fb.publish(joint_state(t + 0.02, names, rest, rest))
        after = odom.wait_for(lambda m: stamp_s(m) == pytest.approx(t + 0.02, abs=1e-6), timeout=5, start=count)
    assert stamp_s(odom.snapshot()[count]) == pytest.approx(t + 0.02, abs=1e-6), "the huge sample published odom"
    assert (after.pose.pose.position.x, after.pose.pose.position.y) == (before.pose.pose.position.x,
                                                                        before.pose.pose.position.y)
    assert all(math.isfinite(v) for v in after.pose.covariance)
    assert list(after.pose.covariance) == list(before.pose.covariance)
    chassis.wait_for_log("beyond what the chassis can do", timeout=5)


def test_position_only_encoders_keep_the_distance_driven_during_a_dropout(start_node, ros_node):
    """OMR-III publishing wheel angles only; 2 s without joint_states while it drives 1 m along x:
    wheel 1 (rolling along x) turns 1/0.05 = 20 rad, wheels 2 and 3 −10 rad each."""
    chassis = start_node("chassis_node", params_file="params/omr3.yaml")
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.qos_default()) as odom:
        prime_feedback(ros_node, fb, odom, 40.0, positions_only=True)
        fb.publish(joint_state(42.0, OMNI_WHEELS, [20.0, -10.0, -10.0], []))
        last = odom.wait_for(lambda m: m.header.stamp.sec == 42 and m.header.stamp.nanosec == 0, timeout=5)
    assert last.pose.pose.position.x == pytest.approx(1.0, abs=1e-6)
    assert last.pose.pose.position.y == pytest.approx(0.0, abs=1e-6)
    chassis.wait_for_log("cover the gap", timeout=5)
