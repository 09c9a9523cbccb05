"""Goals in `map` from real rclpy (ROS 2 Jazzy, Fast DDS): a localiser stand-in publishes
`map → odom` on `/tf`, and local_nav_node and planner_node follow goals given in `map` on the
simulated OMR-III and MOBIL-II (the built-in world, simulated clock at 5× real time).

The localiser dates each transform ahead of the simulated clock it last saw (1.5 s; 5 s in the
docking test, which ages none), as AMCL dates its own ahead by its `transform_tolerance`, and
sends it every 20 ms of wall time.

The hand-worked frames: odom sits at (0.5, −1.0) in map, turned by π/2, so a point (x, y) in
odom is (0.5 − y, −1.0 + x) in map, and a point (X, Y) in map is (Y + 1.0, 0.5 − X) in odom. The
localiser's correction moves odom to (0.5, −0.7) in map: (X, Y) in map is then (Y + 0.7, 0.5 − X)
in odom, 0.3 m less along odom's x than before.
"""

from __future__ import annotations

import math
import re
import threading
import time

import pytest

from action_client import ActionClient
from harness import make_qos, qos_latched, subscribe, wait_until
from rosutil import wait_for_future

from action_msgs.msg import GoalStatus
from diagnostic_msgs.msg import DiagnosticArray, DiagnosticStatus
from geometry_msgs.msg import PoseStamped, TransformStamped, Twist
from nav_msgs.msg import Odometry
from tf2_msgs.msg import TFMessage

from mobil_msgs.msg import NavStatus
from nav2_msgs.action import DockRobot, NavigateToPose

REAL_TIME_FACTOR = 5.0
CHASSIS_ARGS = ("-p", "feedback_timeout_s:=2.0")
NODE_ARGS = ("-p", "use_sim_time:=true", "-p", "odom_timeout_s:=2.0", "-p", "clock_timeout_s:=2.0")
REPLY_TIMEOUT = 10.0
DEEP = make_qos("reliable", "volatile", 5000)
# odom's pose in map: before the correction, after it.
ODOM_IN_MAP = (0.5, -1.0, math.pi / 2)
CORRECTED = (0.5, -0.7, math.pi / 2)
# Dated ahead as AMCL dates its transforms (by its transform_tolerance, 1 s by default), a
# little more: a test process stalled for a moment must not let the transform age.
DATED_AHEAD = 1.5
# The docking test ages no transform on purpose, so it dates them further ahead: 5 s of simulated
# time is 1 s of the test's wall time at REAL_TIME_FACTOR 5 (1.5 s, 0.3 s of wall time, was
# seen outlived under load: a transform 0.12 s old refused a dock).
DOCK_DATED_AHEAD = 5.0


def in_map(frame, x: float, y: float) -> tuple[float, float]:
    """(x, y) in odom as seen in map, odom being at ``frame`` = (tx, ty, θ) in map."""
    tx, ty, th = frame
    return tx + x * math.cos(th) - y * math.sin(th), ty + x * math.sin(th) + y * math.cos(th)


def in_odom(frame, x: float, y: float) -> tuple[float, float]:
    """(x, y) in map as seen in odom."""
    tx, ty, th = frame
    dx, dy = x - tx, y - ty
    return dx * math.cos(th) + dy * math.sin(th), -dx * math.sin(th) + dy * math.cos(th)


def test_the_hand_worked_frames():
    """The module docstring's values, so the helpers the tests use are checked by hand."""
    assert in_map(ODOM_IN_MAP, 1.5, 0.0) == pytest.approx((0.5, 0.5))
    assert in_odom(ODOM_IN_MAP, 0.5, 2.0) == pytest.approx((3.0, 0.0))
    assert in_odom(CORRECTED, 0.5, 2.0) == pytest.approx((2.7, 0.0))


def pose(frame_id: str, x: float, y: float, yaw: float = 0.0) -> PoseStamped:
    p = PoseStamped()
    p.header.frame_id = frame_id
    p.pose.position.x, p.pose.position.y = float(x), float(y)
    p.pose.orientation.z, p.pose.orientation.w = math.sin(yaw / 2), math.cos(yaw / 2)
    return p


def yaw_of(m: Odometry) -> float:
    q = m.pose.pose.orientation
    return math.atan2(2 * (q.w * q.z + q.x * q.y), 1 - 2 * (q.y * q.y + q.z * q.z))


def is_zero(t: Twist) -> bool:
    return t.linear.x == 0.0 and t.linear.y == 0.0 and t.angular.z == 0.0


class Localiser:
    """`map → odom` on `/tf` every 20 ms (wall), dated ``dated_ahead`` past the latest
    simulated time; ``frame`` may change while it runs (a correction)."""

    def __init__(self, node, sim_clock, dated_ahead: float = DATED_AHEAD) -> None:
        self.pub = node.create_publisher(TFMessage, "/tf", make_qos("reliable", "volatile", 100))
        self.clock, self.frame, self.dated_ahead = sim_clock, ODOM_IN_MAP, dated_ahead
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)

    def message(self) -> TFMessage:
        t = TransformStamped()
        stamp = self.clock.now() + self.dated_ahead
        t.header.stamp.sec, t.header.stamp.nanosec = int(stamp), int((stamp % 1.0) * 1e9)
        t.header.frame_id, t.child_frame_id = "map", "odom"
        x, y, th = self.frame
        t.transform.translation.x, t.transform.translation.y = x, y
        t.transform.rotation.z, t.transform.rotation.w = math.sin(th / 2), math.cos(th / 2)
        return TFMessage(transforms=[t])

    def _run(self) -> None:
        self.clock.wait_started(timeout=30.0)
        while not self._stop.wait(0.02):
            self.pub.publish(self.message())

    def __enter__(self) -> "Localiser":
        self._thread.start()
        return self

    def reached(self, timeout: float = 20.0) -> None:
        """Once the node under test subscribes `/tf`, and a few transforms later."""
        assert wait_until(lambda: self.pub.get_subscription_count() > 0, timeout), "nobody subscribes /tf"
        time.sleep(0.3)

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=5)

    def __exit__(self, *exc) -> None:
        self.stop()


def truth_xy(truth) -> tuple[float, float]:
    p = truth.latest.pose.pose.position
    return p.x, p.y


def publish_until_status(pub, msg, status, predicate, timeout: float = REPLY_TIMEOUT) -> tuple[NavStatus, int]:
    """Publishes ``msg`` once a second until a status after it satisfies ``predicate`` (the first
    message after discovery may be lost); a goal the node took is not sent again. The status,
    and the index after it."""
    start = len(status)
    deadline = time.monotonic() + timeout
    while True:
        pub.publish(msg)
        try:
            found = status.wait_for(predicate, 1.0, start=start)
            return found, start + [m is found for m in status.snapshot()[start:]].index(True) + 1
        except TimeoutError:
            assert time.monotonic() < deadline, "no status answered the goal"


def goal_response(client: ActionClient, goal, attempts: int = 4, feedback=None):
    for _ in range(attempts):
        future = client.send_goal_async(goal, feedback_callback=feedback)
        if wait_until(future.done, 3.0):
            return future.result()
    raise AssertionError("no goal response")


def correct_when(truth, localiser: Localiser, x_beyond: float, timeout: float = 30.0) -> None:
    """The localiser's correction once the robot is beyond ``x_beyond`` (odom x) under way."""
    assert wait_until(lambda: truth.latest is not None and truth_xy(truth)[0] > x_beyond, timeout), \
        "the robot never got under way"
    localiser.frame = CORRECTED


def finished(status, start: int, timeout: float = 40.0) -> NavStatus:
    return status.wait_for(lambda s: s.state in (NavStatus.SUCCEEDED, NavStatus.FAILED), timeout, start=start)


def stopped(cmd, start: int) -> None:
    """A zero command after index ``start``, and the latest command zero."""
    cmd.wait_for(is_zero, REPLY_TIMEOUT, start=start)
    assert is_zero(cmd.snapshot()[-1]), "the last command is not zero"


def status_named(array: DiagnosticArray, name: str):
    return next((s for s in array.status if s.name == name), None)


def values(status) -> dict:
    return {kv.key: kv.value for kv in status.values}


def no_motion_after(cmd, n: int, wall: float = 1.0) -> None:
    """No command but zero after the first ``n``, for ``wall`` seconds."""
    time.sleep(wall)
    assert all(is_zero(t) for t in cmd.snapshot()[n:]), "a refused goal moved the robot"


@pytest.mark.timeout(150)
@pytest.mark.parametrize("robot", ["omr3", "mobil2"])
def test_local_nav_follows_goals_in_map_through_the_localiser(robot, start_scenario, start_node, sim_clock,
                                                              ros_node):
    """goal_pose in map with odom fixed in map: the ground truth ends at the goal's odom point
    (1.5, 0) within xy_goal_tolerance (+ 5 cm). navigate_to_pose in map to odom (3, 0), the
    localiser moving odom by 0.3 m under way: the robot ends at the goal's new odom point
    (2.7, 0), its feedback in map. A goal in a frame no transform reaches, and one in map after
    the localiser stopped (transform older than transform_tolerance, 0.1 s), are refused
    TF_ERROR with no motion; a goal running when the localiser stops ends TF_ERROR, the robot
    stopped. /diagnostics: sim_node's `simulation` status with the factor asked; local_nav's
    `motion` status OK with its inputs' ages, and WARN once the simulation stops (odometry older
    than odom_timeout_s while idle)."""
    params = f"params/{robot}.yaml"
    sim = start_scenario(params, real_time_factor=REAL_TIME_FACTOR, lidar=True, node_args=CHASSIS_ARGS)[0]
    nav = start_node("local_nav_node", *NODE_ARGS, params_file=params)
    tolerance = {"omr3": 0.10, "mobil2": 0.15}[robot] + 0.05
    goal_pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    client = ActionClient(ros_node, NavigateToPose, "navigate_to_pose")
    feedback = []
    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, Odometry, "ground_truth", qos=DEEP) as truth, \
            subscribe(ros_node, DiagnosticArray, "/diagnostics", qos=DEEP) as diag, \
            Localiser(ros_node, sim_clock) as localiser:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        localiser.reached()
        # 1. odom fixed in map: (1.5, 0) in odom is (0.5, 0.5) in map.
        _, start = publish_until_status(goal_pub, pose("map", *in_map(ODOM_IN_MAP, 1.5, 0.0)), status,
                                        lambda s: s.state == NavStatus.ACTIVE)
        done = finished(status, start)
        assert done.state == NavStatus.SUCCEEDED, done.reason
        assert done.header.frame_id == "map"
        assert (done.goal.position.x, done.goal.position.y) == pytest.approx((0.5, 0.5))
        stopped(cmd, 0)
        sim_clock.wait_until(sim_clock.now() + 0.5)
        x, y = truth_xy(truth)
        assert math.hypot(x - 1.5, y - 0.0) < tolerance, (x, y)

        # 2. navigate_to_pose to (0.5, 2.0) in map, (3, 0) in odom; corrected to (2.7, 0).
        assert client.wait_for_server(timeout_sec=20.0)
        n_moving = len(cmd)
        handle = goal_response(client, NavigateToPose.Goal(pose=pose("map", 0.5, 2.0)),
                               feedback=lambda f: feedback.append(f.feedback))
        assert handle.accepted
        result = handle.get_result_async()
        correct_when(truth, localiser, 1.9)
        assert wait_for_future(result, 40.0), "no navigate_to_pose result"
        assert result.result().status == GoalStatus.STATUS_SUCCEEDED, result.result().result.error_msg
        stopped(cmd, n_moving)
        sim_clock.wait_until(sim_clock.now() + 0.5)
        x, y = truth_xy(truth)
        assert math.hypot(x - 2.7, y - 0.0) < tolerance, (x, y)
        assert feedback and all(f.current_pose.header.frame_id == "map" for f in feedback)
        # The feedback's pose is the robot seen from map, (0.5 − y, −0.7 + x) after the
        # correction: the last one sent is at the goal. rclpy's action client takes one feedback
        # message per turn of its executor, the result among them: on a loaded machine the last
        # feedback messages can still be queued when the result is in.

        def near_goal(f) -> bool:
            p = f.current_pose.pose.position
            return math.hypot(p.x - 0.5, p.y - 2.0) < tolerance + 0.05
        assert wait_until(lambda: any(near_goal(f) for f in feedback), REPLY_TIMEOUT), \
            [(f.current_pose.pose.position.x, f.current_pose.pose.position.y) for f in feedback[-3:]]

        # 3. A frame no transform reaches: refused, no motion.
        n = len(cmd)
        refused, _ = publish_until_status(goal_pub, pose("nowhere", 3.5, 0.0), status,
                                          lambda s: s.state == NavStatus.FAILED)
        assert refused.reason.startswith("TF_ERROR: goal frame `nowhere` has no usable transform to `odom`: "
                                         "frame `nowhere` does not exist"), refused.reason
        no_motion_after(cmd, n, 0.5)

        # 4. A goal under way when the localiser stops: TF_ERROR (stale), the robot stopped.
        # (5.2, 0) in odom: still far when the transform ages out, 1.6 s after the last one.
        _, start = publish_until_status(goal_pub, pose("map", 0.5, 4.5), status,
                                        lambda s: s.state == NavStatus.ACTIVE)
        cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT, start=n)
        n = len(cmd)
        localiser.stop()
        ended = status.wait_for(lambda s: s.state == NavStatus.FAILED, REPLY_TIMEOUT, start=start)
        assert re.match(r"TF_ERROR: goal frame `map` has no usable transform to `odom`: the transform from "
                        r"`odom` to `map` is [0-9.]+ s old", ended.reason), ended.reason
        stopped(cmd, n)

        # 5. A goal in map now, the transform older than transform_tolerance: refused.
        n = len(cmd)
        stale, _ = publish_until_status(goal_pub, pose("map", 0.5, 3.0), status,
                                        lambda s: s.state == NavStatus.FAILED)
        assert stale.reason.startswith("TF_ERROR: goal frame `map`") and " s old" in stale.reason, stale.reason
        no_motion_after(cmd, n, 0.5)

        # 6. /diagnostics, once a second from each node.
        n = len(diag)
        motion = diag.wait_for(lambda a: (s := status_named(a, "/local_nav: motion")) is not None
                               and s.level == DiagnosticStatus.OK, REPLY_TIMEOUT, start=n)
        ok = status_named(motion, "/local_nav: motion")
        assert ok.level == DiagnosticStatus.OK and ok.message == "idle", ok
        assert values(ok)["last end"] == "TF_ERROR" and float(values(ok)["odom age [s]"]) < 2.0, values(ok)
        simulation = diag.wait_for(lambda a: status_named(a, "/sim: simulation") is not None, REPLY_TIMEOUT)
        assert values(status_named(simulation, "/sim: simulation"))["real_time_factor asked"] == "5.000"
        # The simulation stops: odometry ages past odom_timeout_s (2 s) and the idle node warns.
        n = len(diag)
        sim.stop()
        warned = diag.wait_for(lambda a: (s := status_named(a, "/local_nav: motion")) is not None
                               and s.level == DiagnosticStatus.WARN and "odom" in s.message, 6.0, start=n)
        text = status_named(warned, "/local_nav: motion").message
        assert re.match(r"idle; (scan [0-9.]+ s old \(timeout [0-9.]+ s\), )?odom [0-9.]+ s old \(timeout 2\.00 s\): "
                        r"a goal would fail \(stale input\)$", text), text


@pytest.mark.timeout(150)
@pytest.mark.parametrize("robot", ["omr3", "mobil2"])
def test_planner_docks_in_map_through_the_localiser(robot, start_scenario, start_node, sim_clock, ros_node):
    """dock_pose in map with odom fixed in map: the ground truth ends at the dock's odom pose
    (1.5, −0.5, 0). dock_robot to a pose in map, (3, −0.5, 0) in odom, the localiser moving odom
    by 0.3 m under way: the robot ends at the dock's new odom pose (2.7, −0.5, 0). OMR-III docks
    within 0.05 m and 0.1 rad; MOBIL-II, which cannot turn in place, ends RESIDUAL within
    0.15 m. A dock in a frame no transform reaches is refused TF_ERROR with no motion."""
    params = f"params/{robot}.yaml"
    start_scenario(params, real_time_factor=REAL_TIME_FACTOR, node_args=CHASSIS_ARGS)
    start_node("planner_node", *NODE_ARGS, "-p", "world_file:=none", params_file=params)
    position_tolerance = {"omr3": 0.05, "mobil2": 0.15}[robot]
    dock_pub = ros_node.create_publisher(PoseStamped, "dock_pose", 10)
    client = ActionClient(ros_node, DockRobot, "dock_robot")
    ends = {"omr3": (NavStatus.SUCCEEDED,), "mobil2": (NavStatus.SUCCEEDED, NavStatus.FAILED)}[robot]
    with subscribe(ros_node, NavStatus, "planner/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, Odometry, "ground_truth", qos=DEEP) as truth, \
            Localiser(ros_node, sim_clock, dated_ahead=DOCK_DATED_AHEAD) as localiser:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        status.wait_for(lambda s: s.state == NavStatus.IDLE, REPLY_TIMEOUT)
        localiser.reached()

        def check_end(done: NavStatus, x: float, y: float, n: int) -> None:
            assert done.state in ends and (done.state == NavStatus.SUCCEEDED or done.reason.startswith("RESIDUAL")), \
                done.reason
            stopped(cmd, n)
            sim_clock.wait_until(sim_clock.now() + 0.5)
            tx, ty = truth_xy(truth)
            assert math.hypot(tx - x, ty - y) < position_tolerance, (tx, ty)
            if robot == "omr3":
                assert abs(math.remainder(yaw_of(truth.latest), math.tau)) < 0.1

        # 1. (1.5, −0.5, 0) in odom is (1.0, 0.5, π/2) in map.
        _, start = publish_until_status(dock_pub, pose("map", *in_map(ODOM_IN_MAP, 1.5, -0.5), math.pi / 2),
                                        status, lambda s: s.state == NavStatus.ACTIVE)
        done = finished(status, start)
        assert done.header.frame_id == "map"
        check_end(done, 1.5, -0.5, 0)

        # 2. dock_robot to (1.0, 2.0, π/2) in map: (3, −0.5, 0) in odom, corrected to (2.7, −0.5, 0).
        assert client.wait_for_server(timeout_sec=20.0)
        goal = DockRobot.Goal()
        goal.use_dock_id, goal.dock_pose = False, pose("map", 1.0, 2.0, math.pi / 2)
        n, n_cmd = len(status), len(cmd)
        handle = goal_response(client, goal)
        assert handle.accepted
        result = handle.get_result_async()
        correct_when(truth, localiser, 2.0)
        assert wait_for_future(result, 40.0), "no dock_robot result"
        check_end(finished(status, n, REPLY_TIMEOUT), 2.7, -0.5, n_cmd)

        # 3. A dock in a frame no transform reaches: refused TF_ERROR, no motion.
        n = len(cmd)
        refused, _ = publish_until_status(dock_pub, pose("nowhere", 1.0, 0.0), status,
                                          lambda s: s.state == NavStatus.FAILED)
        assert refused.reason.startswith("TF_ERROR: goal frame `nowhere`"), refused.reason
        no_motion_after(cmd, n, 0.5)
