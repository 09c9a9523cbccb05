"""local_nav_node from real rclpy (ROS 2 Jazzy, Fast DDS): a goal from goal_pose driven in the
simulator, Nav2's NavigateToPose fed by a foreign LIDAR (a raycaster in this test), and the
refusals (goal frame, NaN, a stale scan).

The robot is OMR-III (params/omr3.yaml: noise-free encoders, so odometry and ground truth agree
to well under a millimetre here). Driving runs under the simulated clock at 5× real time (at
least 2× asserted: harness.MIN_REAL_TIME_FACTOR). Watchdogs run on the steady clock (the time
rule), so chassis_node's feedback watchdog gets 2 s, as in test_scenario.py.

Invariants checked on cmd_vel: nothing before the first goal; every command within OMR-III's
limits (speed ≤ v_max 0.5 m/s, |ω| ≤ omega_max 1.5 rad/s); exactly one zero command per goal
that ends (goals counted from local_nav_node's log, so that a goal sent twice while discovery
completes is counted as the two goals it is), plus one per run of refused input mid-goal, and
none after the last.
"""

from __future__ import annotations

import math
import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from foreign_lidar import WorldRaycaster

from action_client import ActionClient
from harness import (MIN_REAL_TIME_FACTOR, TESTS_DIR as TESTS, OdomFeed, OpenSpaceScan, make_qos,
                     odom_at, param_set, qos_latched, subscribe, wait_until)

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, Twist
from nav_msgs.msg import Odometry
from visualization_msgs.msg import Marker, MarkerArray

from mobil_msgs.msg import NavStatus
from nav2_msgs.action import NavigateToPose

PARAMS = "params/omr3.yaml"
REAL_TIME_FACTOR = 5.0
MIN_FACTOR = MIN_REAL_TIME_FACTOR
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


def check_commands(cmds: list[Twist], ends: int, v_max: float = V_MAX) -> None:
    """Limits; ``ends`` zero commands (one per goal end, none for a goal pre-empted by a newer
    one, which commands at once), and the last command is zero."""
    for t in cmds:
        assert math.isfinite(t.linear.x) and math.isfinite(t.linear.y) and math.isfinite(t.angular.z)
        assert math.hypot(t.linear.x, t.linear.y) <= v_max + 1e-9
        assert abs(t.angular.z) <= OMEGA_MAX + 1e-9
    zeros = [i for i, t in enumerate(cmds) if is_zero(t)]
    assert len(zeros) == ends, f"{len(zeros)} zero commands for {ends} goal end(s)"
    assert cmds and is_zero(cmds[-1]), "the last cmd_vel is not zero"


# local_nav_node's log line for each goal it starts ("goal (goal_pose): (2.000, 1.500) in odom").
STARTED = r"goal \((?:goal_pose|navigate_to_pose)\): \("
# ... and for each goal_pose it takes up (started or refused), and each action goal it answers.
GOAL_POSE_TAKEN = r"goal \(goal_pose\): \(|goal_pose refused"
ACTION_ANSWERED = r"navigate_to_pose: goal .*(?:accepted|rejected)"


def log_count(proc, pattern: str) -> int:
    return len(re.findall(pattern, proc.log_text()))


def goals_started(nav) -> int:
    return log_count(nav, STARTED)


def publish_until_taken(pub, nav, msg: PoseStamped, timeout: float = REPLY_TIMEOUT) -> None:
    """Publishes ``msg`` on goal_pose until local_nav_node's log shows it took it up (the first
    message after discovery may be lost); never again after that, so that no second copy
    pre-empts the goal."""
    before = log_count(nav, GOAL_POSE_TAKEN)
    deadline = time.monotonic() + timeout
    while log_count(nav, GOAL_POSE_TAKEN) == before:
        assert time.monotonic() < deadline, "goal_pose never taken up"
        pub.publish(msg)
        wait_until(lambda: log_count(nav, GOAL_POSE_TAKEN) > before, 1.0)


def ends_of(statuses: list[NavStatus]) -> list[NavStatus]:
    return [s for s in statuses if s.state in (NavStatus.SUCCEEDED, NavStatus.FAILED)]


def statuses_index(rec, msg) -> int:
    return next(i for i, m in enumerate(rec.snapshot()) if m is msg)


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
    sim = start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR, lidar=True,
                         sim_args=("-p", f"world_file:={world}"), node_args=CHASSIS_ARGS)[0]
    nav = start_local_nav(start_node)
    goal = (2.0, 1.5)
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, MarkerArray, "local_nav/markers", qos=DEEP) as markers, \
            subscribe(ros_node, Odometry, "ground_truth") as truth:
        sim_clock.wait_started()
        # The latched IDLE status proves local_nav_node is up and matched; no goal yet, no cmd_vel.
        status.wait_for(lambda s: s.state == NavStatus.IDLE, REPLY_TIMEOUT)
        truth.wait_for(None, REPLY_TIMEOUT)
        assert len(cmd) == 0, "cmd_vel before any goal"
        # The first message after discovery may be lost: send until the goal is taken up.
        publish_until_taken(pub, nav, goal_pose(*goal))
        mark = sim_clock.mark()
        done = status.wait_for(lambda s: s.state in (NavStatus.SUCCEEDED, NavStatus.FAILED), 20.0)
        assert done.state == NavStatus.SUCCEEDED, done.reason
        assert done.reason.startswith("SUCCEEDED")
        # The zero command (reliable: it may take a repair), then 1 simulated second more, for
        # a stray command to show and the robot to come to rest (motor lag τ = 0.05 s).
        cmd.wait_for(is_zero, REPLY_TIMEOUT)
        # A finished goal clears its markers (RViz shows no sectors of it).
        markers.wait_for(lambda a: any(m.action == Marker.DELETEALL for m in a.markers), REPLY_TIMEOUT)
        sim_clock.wait_until(sim_clock.now() + 1.0)
        factor = sim_clock.factor(since=mark)
        rest = truth.wait_for(lambda m: speed(m) < 1e-3, REPLY_TIMEOUT, start=len(truth))
        started = goals_started(nav)
        # SIGINT while idle: no cmd_vel at exit (another node may be commanding the robot). A
        # final command was acknowledged by this reliable reader before the process exited.
        before_exit = len(cmd)
        nav.stop()
        time.sleep(0.5)  # acknowledged before the exit; this lets this reader's callback run
        assert len(cmd) == before_exit, "an idle local_nav_node sent a cmd_vel at exit"
        statuses, cmds, arrays = status.snapshot(), cmd.snapshot(), markers.snapshot()
        # sim_node first, so that no ground truth or clock is in flight when the readers close.
        sim.stop()

    assert factor >= MIN_FACTOR, f"{factor:.2f}× real time"
    # While active: the sector vectors (8 lines from the robot, base_link) and the goal's sphere
    # at G (odom); the goal's end clears them with DELETEALL.
    drawn = [m for a in arrays for m in a.markers if m.action == Marker.ADD]
    assert any(m.type == Marker.LINE_LIST and m.header.frame_id == "base_link" and len(m.points) == 16
               for m in drawn), arrays[:1]
    assert any(m.type == Marker.SPHERE and m.header.frame_id == "odom"
               and (m.pose.position.x, m.pose.position.y) == goal for m in drawn), "no marker at G"
    assert any(m.action == Marker.DELETEALL for m in arrays[-1].markers)
    x, y = position(rest)
    # The goal is reached when odometry is within 0.10 m; a noise-free odometry and the coast
    # toward the goal after the stop (≤ 0.083 m/s · τ) keep the ground truth inside it.
    assert math.hypot(x - goal[0], y - goal[1]) <= GOAL_TOLERANCE, (x, y)
    active = [s for s in statuses if s.state == NavStatus.ACTIVE]
    assert active and active[0].mode == "rotate"
    assert active[0].goal.position.x == goal[0] and active[0].goal.position.y == goal[1]
    # Distances while active (NaN before the first odometry): within the 2.5 m from the start.
    distances = [s.distance_to_goal for s in active if math.isfinite(s.distance_to_goal)]
    assert distances and max(distances) <= math.hypot(*goal) + 0.02
    assert statuses.index(active[0]) < statuses.index(done)
    assert done.distance_to_goal <= GOAL_TOLERANCE
    assert started >= 1
    check_commands(cmds, started)
    # Open space: the navigator went straight, nothing tracked.
    assert not done.has_hit_point


# --------------------------------------------------------------------------------------------
# A foreign LIDAR: tests/foreign_lidar.py, its own raycaster over the world file, fed by
# sim_node's ground truth, in its own process; sim_node's LIDAR off
# --------------------------------------------------------------------------------------------

def start_foreign_lidar(start_node, tmp_path: Path, world: Path):
    """tests/foreign_lidar.py as a node process (stopped like the Rust nodes)."""
    wrapper = tmp_path / "foreign_lidar"
    wrapper.write_text(f'#!/bin/sh\nexec "{sys.executable}" "{TESTS / "foreign_lidar.py"}" "$@"\n')
    wrapper.chmod(0o755)
    proc = start_node(str(wrapper), args=(str(world),))
    proc.wait_for_log("foreign_lidar up", timeout=REPLY_TIMEOUT)
    return proc


def test_world_raycaster_by_hand(tmp_path):
    """The test's raycaster against distances worked out by hand."""
    world = tmp_path / "w.yaml"
    world.write_text("obstacles:\n"
                     "  - circle: { center: [2.0, 0.0], radius: 0.5 }\n"
                     "  - polygon: { points: [[-1, 3], [1, 3], [1, 4], [-1, 4]] }\n")
    c = WorldRaycaster(world, range_max=10.0)
    r = c.ranges(0.0, 0.0, np.array([0.0, math.pi / 2, math.pi, math.atan2(3.0, 1.0)]))
    # East: the circle's near side at 2 − 0.5 = 1.5; north: the box's edge y = 3; west: nothing;
    # toward the box's corner (1, 3): √10 = 3.1623.
    assert r[0] == pytest.approx(1.5) and r[1] == pytest.approx(3.0)
    assert math.isinf(r[2]) and r[3] == pytest.approx(math.sqrt(10.0))


def send_until_answered(client: ActionClient, goal, nav, attempts: int = 4):
    """Sends ``goal`` until a goal response arrives, each attempt 3 s. A request lost during
    discovery is sent again; a request the node answered (its log says so) is waited for 3 s
    more before it is sent again, since only a lost response (sent before discovery matched
    this client's reply reader; see test_actions.py) justifies a second goal, which then
    pre-empts the first (goals are counted from the log)."""
    for _ in range(attempts):
        before = log_count(nav, ACTION_ANSWERED)
        future = client.send_goal_async(goal)
        if wait_until(future.done, 3.0):
            return future.result()
        if log_count(nav, ACTION_ANSWERED) > before and wait_until(future.done, 3.0):
            return future.result()
    raise AssertionError(f"no goal response to {attempts} goals")


def cancel_until_answered(handle, attempts: int = 4) -> list:
    """Cancels until a cancel response arrives, each attempt 3 s, in case one is lost (rclpy's
    own client dropped a response that came back before it had filed the request, which a fast
    server on a loaded machine made happen now and then; tests/action_client.py fixes that).
    Returns every response that arrived (requests still open get 0.5 s more)."""
    futures = []
    for _ in range(attempts):
        futures.append(handle.cancel_goal_async())
        if wait_until(lambda: any(f.done() for f in futures), 3.0):
            wait_until(lambda: all(f.done() for f in futures), 0.5)
            return [f.result() for f in futures if f.done()]
    raise AssertionError(f"no cancel response to {attempts} requests")


def cancel_accepted(response, handle) -> bool:
    """The cancel response accepted ``handle``'s goal: return code 0 (ERROR_NONE), the goal
    among those canceling."""
    return response.return_code == 0 and any(
        bytes(g.goal_id.uuid) == bytes(handle.goal_id.uuid) for g in response.goals_canceling)


def result_of(handle, timeout: float = 30.0):
    """The goal's result; the request is repeated every 5 s while none came, as
    ``cancel_until_answered`` repeats its request."""
    deadline = time.monotonic() + timeout
    futures = []  # every request stays watched: the server may answer any of them
    while time.monotonic() < deadline:
        futures.append(handle.get_result_async())
        if wait_until(lambda: any(f.done() for f in futures),
                      min(5.0, max(0.1, deadline - time.monotonic()))):
            return next(f for f in futures if f.done()).result()
    raise AssertionError(f"no result within {timeout} s")


def nav_goal(x: float, y: float, frame: str = "odom", tree: str = "") -> NavigateToPose.Goal:
    g = NavigateToPose.Goal()
    g.pose = goal_pose(x, y, frame)
    g.behavior_tree = tree
    return g


def wait_future(future, what: str, timeout: float = REPLY_TIMEOUT):
    assert wait_until(future.done, timeout), f"no {what} within {timeout} s"
    return future.result()


PILLAR = (1.5, 0.0, 0.3)  # x, y, radius: on the line from the start to the first goal


def test_foreign_lidar_with_navigate_to_pose_and_cancel(start_scenario, start_node, sim_clock,
                                                         ros_node, tmp_path):
    """sim_node's LIDAR off; this test's raycaster feeds ``scan``. NavigateToPose round a pillar
    on the straight line: feedback arrives, SUCCEEDED, the ground truth never nearer the pillar
    than the robot radius and within the tolerance of the goal. A second goal is canceled mid-way:
    CANCELED, the robot at rest within 1 simulated second, the last cmd_vel zero."""
    world = tmp_path / "pillar.yaml"
    world.write_text("obstacles:\n"
                     f"  - circle: {{ center: [{PILLAR[0]}, {PILLAR[1]}], radius: {PILLAR[2]} }}\n"
                     "  - polygon: { points: [[-2, -3], [6, -3], [6, -2.9], [-2, -2.9]] }\n")
    sim = start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR,
                         sim_args=("-p", f"world_file:={world}"), node_args=CHASSIS_ARGS)[0]
    nav = start_local_nav(start_node)
    lidar = start_foreign_lidar(start_node, tmp_path, world)
    feedback = []
    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, Odometry, "ground_truth", qos=make_qos("reliable", "volatile", 500)) as truth:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        client = ActionClient(ros_node, NavigateToPose, "navigate_to_pose")
        assert client.wait_for_server(timeout_sec=20.0), "navigate_to_pose not found"
        # A goal in `map`, which no transform joins to `odom`, is rejected (it also proves goal
        # responses arrive).
        rejected = send_until_answered(client, nav_goal(3.0, 0.0, frame="map"), nav)
        assert not rejected.accepted
        # The cancel service answers too (a cancel naming no active goal is refused): its
        # first request may be lost during discovery, which must not delay the real cancel.
        cancel_until_answered(rejected)
        nan = wait_future(client.send_goal_async(nav_goal(float("nan"), 0.0)), "goal response")
        assert not nan.accepted
        assert len(cmd) == 0, "cmd_vel before any accepted goal"
        # The foreign scans reach local_nav_node (a goal gets one scan_timeout for them).
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)

        goal = (3.0, 0.0)
        mark = sim_clock.mark()
        handle = wait_future(client.send_goal_async(
            nav_goal(*goal, tree="ignored.xml"), feedback_callback=feedback.append), "goal response")
        assert handle.accepted
        t_start = len(truth)
        res = result_of(handle)
        factor = sim_clock.factor(since=mark)
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        assert res.result.error_code == 0
        rest1 = truth.wait_for(lambda m: speed(m) < 1e-3, REPLY_TIMEOUT, start=len(truth))
        run = truth.snapshot()[t_start:]

        # The second goal, 6 m north, canceled once the robot is under way.
        handle2 = wait_future(client.send_goal_async(nav_goal(3.0, 6.0)), "goal response")
        assert handle2.accepted
        # Mid-way: 0.5 m on, under way at more than 0.2 m/s.
        truth.wait_for(lambda m: position(m)[1] > 0.5 and speed(m) > 0.2, REPLY_TIMEOUT,
                       start=len(truth))
        # The stop is timed from before the first cancel request, whatever answers it.
        t_cancel = sim_clock.now()
        answers = cancel_until_answered(handle2)
        assert sum(cancel_accepted(a, handle2) for a in answers) == 1, \
            [(a.return_code, len(a.goals_canceling)) for a in answers]
        res2 = result_of(handle2)
        assert res2.status == GoalStatus.STATUS_CANCELED
        rest = truth.wait_for(lambda m: speed(m) < 1e-3, REPLY_TIMEOUT, start=len(truth))
        stopped_after = rest.header.stamp.sec + rest.header.stamp.nanosec * 1e-9 - t_cancel
        wait_until(lambda: cmd.latest is not None and is_zero(cmd.latest), REPLY_TIMEOUT)
        sim_clock.wait_until(sim_clock.now() + 0.5)
        assert "first scan published" in lidar.log_text()

        # SIGINT mid-goal: the goal ends ABORTED (SHUTDOWN, 100), and its zero cmd_vel is the
        # only command after the last moving one.
        handle3 = wait_future(client.send_goal_async(nav_goal(0.0, 6.0)), "goal response")
        assert handle3.accepted
        moving_from = len(cmd)
        cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT, start=moving_from)
        result3 = handle3.get_result_async()  # asked before the exit, answered at it
        started = goals_started(nav)
        nav.stop()
        res3 = wait_future(result3, "result at shutdown")
        # Acknowledged before the exit, but this reader's callback may still be behind.
        cmd.wait_for(is_zero, REPLY_TIMEOUT, start=moving_from)
        statuses, cmds = status.snapshot(), cmd.snapshot()
        # sim_node first, so that no ground truth or clock is in flight when the readers close.
        sim.stop()

    assert factor >= MIN_FACTOR, f"{factor:.2f}× real time"
    # Feedback: in odom, the distance remaining falling toward the goal.
    assert len(feedback) >= 2
    first, last = feedback[0].feedback, feedback[-1].feedback
    assert first.current_pose.header.frame_id == "odom"
    # Feedback comes at 20 Hz of wall time (the watchdog tick).
    assert 0.0 < last.distance_remaining < first.distance_remaining <= 3.0 + 0.01
    assert last.navigation_time.sec + last.navigation_time.nanosec * 1e-9 > 0.0
    # Round the pillar: never nearer its surface than the robot radius; the goal reached.
    clearance = min(math.hypot(x - PILLAR[0], y - PILLAR[1]) for x, y in map(position, run)) - PILLAR[2]
    assert clearance >= ROBOT_RADIUS, f"clearance {clearance:.3f} m"
    assert max(abs(position(m)[1]) for m in run) > 0.3, "went through the pillar's place"
    x, y = position(rest1)
    assert math.hypot(x - goal[0], y - goal[1]) <= GOAL_TOLERANCE
    # Canceled: at rest within 1 simulated second of the cancel response (motor lag τ = 0.05 s).
    assert stopped_after <= 1.0, f"stopped {stopped_after:.2f} s after the cancel"
    reasons = [s.reason.split(":")[0] for s in ends_of(statuses)]
    assert "SUCCEEDED" in reasons and "CANCELED" in reasons, reasons
    assert res3.status == GoalStatus.STATUS_ABORTED
    assert (res3.result.error_code, res3.result.error_msg.split(":")[0]) == (100, "SHUTDOWN")
    last_moving = max(i for i, t in enumerate(cmds) if not is_zero(t))
    assert last_moving >= moving_from and len(cmds) - 1 - last_moving == 1, \
        f"{len(cmds) - 1 - last_moving} command(s) after the last moving one at shutdown"
    check_commands(cmds, started)


def test_refusals_preemption_and_stale_scan(start_scenario, start_node, sim_clock, ros_node, tmp_path):
    """An empty scan from this test (open space). goal_pose in `map` and with NaN: status
    FAILED INVALID_GOAL, nothing moves. An action goal pre-empted by a goal_pose goal ends
    ABORTED with the reason PREEMPTED, as does an action goal pre-empted by an action goal (its
    status says so, the running goal keeps going). The progress checker, made impossible to satisfy by
    parameters set at run time, ends a goal ABORTED. Then only defective scans (each a defect the checked Scan
    refuses), then none: within the scan timeout (0.5 s, steady clock) plus a tick of the last
    valid scan the goal fails STALE_INPUT naming the scan, the last cmd_vel is zero, the robot
    comes to rest, and local_nav_node exits cleanly at the end (checked at teardown)."""
    world = tmp_path / "empty.yaml"
    world.write_text("obstacles: []\n")
    sim = start_scenario(PARAMS, real_time_factor=REAL_TIME_FACTOR,
                         sim_args=("-p", f"world_file:={world}"), node_args=CHASSIS_ARGS)[0]
    nav = start_local_nav(start_node)
    lidar = OpenSpaceScan(ros_node)
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)

    def publish_until_status(msg: PoseStamped, predicate) -> NavStatus:
        start = len(status)
        publish_until_taken(pub, nav, msg)
        return status.wait_for(predicate, REPLY_TIMEOUT, start=start)

    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd, \
            subscribe(ros_node, Odometry, "ground_truth") as truth:
        sim_clock.wait_started()
        status.wait_for(lambda s: s.state == NavStatus.IDLE, REPLY_TIMEOUT)
        truth.wait_for(None, REPLY_TIMEOUT)
        in_map = publish_until_status(goal_pose(1.0, 0.0, frame="map"),
                                      lambda s: s.state == NavStatus.FAILED)
        assert in_map.reason.startswith("TF_ERROR: goal frame `map` has no usable transform to `odom`"), \
            in_map.reason
        nan = publish_until_status(goal_pose(float("nan"), 0.0),
                                   lambda s: s.state == NavStatus.FAILED)
        assert nan.reason == "INVALID_GOAL: goal is not finite"
        assert len(cmd) == 0, "a refused goal moved the robot"

        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        client = ActionClient(ros_node, NavigateToPose, "navigate_to_pose")
        assert client.wait_for_server(timeout_sec=20.0), "navigate_to_pose not found"
        first = send_until_answered(client, nav_goal(50.0, 0.0), nav)
        assert first.accepted
        cmd.wait_for(lambda t: t.linear.x > 0.1, REPLY_TIMEOUT)
        # An action goal pre-empts the running action goal: ABORTED, PREEMPTED by the action.
        first_result = first.get_result_async()
        handle = send_until_answered(client, nav_goal(50.0, 0.5), nav)
        assert handle.accepted
        res0 = wait_future(first_result, "result of the pre-empted action goal")
        assert res0.status == GoalStatus.STATUS_ABORTED
        assert res0.result.error_msg == "PREEMPTED: preempted by a newer goal (navigate_to_pose)"
        status.wait_for(lambda s: s.state == NavStatus.ACTIVE and s.goal.position.y == 0.5,
                        REPLY_TIMEOUT)
        # A rejected action goal leaves the running goal alone. Its FAILED TF_ERROR status
        # is followed at once by the running goal's ACTIVE, so that the latched status (depth 1:
        # the FAILED is usually superseded before it reaches a reader) is the running goal's: a
        # reader joining right after the rejection gets ACTIVE for (50, 0.5).
        rejected = send_until_answered(client, nav_goal(1.0, 0.0, frame="map"), nav)
        assert not rejected.accepted
        nav.wait_for_log("navigate_to_pose goal rejected: TF_ERROR: goal frame `map`")
        with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as late:
            latched = late.wait_for(None, REPLY_TIMEOUT)
        assert (latched.state, latched.goal.position.y) == (NavStatus.ACTIVE, 0.5), latched
        cmd.wait_for(lambda t: t.linear.x > 0.1, REPLY_TIMEOUT, start=len(cmd))
        active = publish_until_status(goal_pose(0.0, 2.0), lambda s: s.state == NavStatus.ACTIVE
                                      and s.goal.position.y == 2.0)
        assert active.mode == "rotate"
        res = result_of(handle)
        assert res.status == GoalStatus.STATUS_ABORTED
        assert res.result.error_msg == "PREEMPTED: preempted by a newer goal (goal_pose)"
        assert res.result.error_code == 0

        # The progress checker, with Nav2's parameters set at run time: 5 m within 1 simulated
        # second is more than OMR-III's 0.5 m/s can do, so the running goal (restarted with the
        # new parameters) ends ABORTED once more than 1 s of ROS time passed without it.
        assert param_set(ros_node, "/local_nav", "required_movement_radius", 5.0).successful
        assert param_set(ros_node, "/local_nav", "movement_time_allowance", 1.0).successful
        aborted = status.wait_for(lambda s: s.state == NavStatus.FAILED
                                  and s.reason.startswith("ABORTED"), REPLY_TIMEOUT)
        assert param_set(ros_node, "/local_nav", "movement_time_allowance", 10.0).successful
        assert param_set(ros_node, "/local_nav", "required_movement_radius", 0.5).successful
        publish_until_status(goal_pose(0.0, -2.0), lambda s: s.state == NavStatus.ACTIVE
                             and s.goal.position.y == -2.0)
        # Under way before the scans break, so that the refused scans have a robot to stop.
        cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT, start=len(cmd))
        refusals_from = len(cmd)

        stopped = lidar.break_scans()
        stale = status.wait_for(lambda s: s.state == NavStatus.FAILED and s.reason.startswith("STALE"),
                                REPLY_TIMEOUT)
        # Every defect again after the goal ended: refused without a panic (the node's exit code
        # at teardown is checked), then no scan at all.
        assert wait_until(lambda: lidar.defects_sent >= 2 * len(lidar.defects), REPLY_TIMEOUT)
        lidar.stop()
        after = status.times[statuses_index(status, stale)] - stopped
        rest = truth.wait_for(lambda m: speed(m) < 1e-3, REPLY_TIMEOUT, start=len(truth))
        # The zero command, then a simulated second for a stray command to show.
        wait_until(lambda: cmd.latest is not None and is_zero(cmd.latest), REPLY_TIMEOUT)
        sim_clock.wait_until(sim_clock.now() + 1.0)
        started = goals_started(nav)
        statuses, cmds = status.snapshot(), cmd.snapshot()
        # sim_node first, so that no ground truth or clock is in flight when the readers close.
        sim.stop()

    # Checked on the scan after 1 s: 20 wall Hz is 0.25 simulated s at 5×, and a loaded machine
    # may delay a scan further.
    prefix = "ABORTED: no progress: moved less than 5 m in "
    assert aborted.reason.startswith(prefix) and aborted.reason.endswith(" s"), aborted.reason
    # The checker fires on the first check past the allowance: at least 1 s (two decimals).
    assert 1.0 <= float(aborted.reason[len(prefix):-2]) <= 2.0, aborted.reason
    assert stale.reason == "STALE_INPUT: scan stale: robot stopped"
    # 0.5 s of scan timeout from the last scan, a 50 ms tick, and DDS and scheduling on a loaded
    # machine.
    assert 0.45 <= after <= 1.5, f"STALE_INPUT {after:.2f} s after the last scan"
    assert speed(rest) < 1e-3
    # The goals ended: the action goals (PREEMPTED, in their results: the status is latched with
    # depth 1, so the new goal's ACTIVE may supersede it before it reaches this reader) and the
    # goal_pose goals (ABORTED, STALE_INPUT); the refused goals started and stopped nothing.
    assert [s.reason.split(":")[0] for s in ends_of(statuses)][-2:] == ["ABORTED", "STALE_INPUT"]
    # The first refused scan stopped the moving robot (one zero), the goal's end another one.
    assert len(cmds) >= refusals_from + 2
    assert not is_zero(cmds[-3]) and is_zero(cmds[-2]) and is_zero(cmds[-1]), cmds[-3:]
    assert started >= 4
    # Two goals ended pre-empted (the first action goal by the second, that one by a goal_pose):
    # no zero between a goal and the one that replaces it. The others' ends, and the refusal.
    check_commands(cmds, started - 2 + 1)


def test_refused_odometry_stops_the_robot(start_node, ros_node):
    """No simulator: this test feeds ``scan`` (open space) and ``odom`` (the robot standing at the
    origin) and sends a goal 3 m ahead. Odometry with a NaN position, and later odometry in
    frame ``map``, are refused: the moving robot gets one zero command at once, no moving
    command after it, and the goal ends STALE_INPUT (odom) with its own zero."""
    nav = start_node("local_nav_node", params_file=PARAMS)
    lidar = OpenSpaceScan(ros_node)
    feed = OdomFeed(ros_node, odom_at())
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    bad_odoms = [odom_at(x=math.nan), odom_at(frame="map")]
    logs = ["odom with a non-finite pose", "odom in frames `map` → `base_link`"]
    with subscribe(ros_node, NavStatus, "local_nav/status", qos=qos_latched()) as status, \
            subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd:
        status.wait_for(lambda s: s.state == NavStatus.IDLE, REPLY_TIMEOUT)
        nav.wait_for_log("first scan", timeout=REPLY_TIMEOUT)
        for bad, log in zip(bad_odoms, logs):
            feed.msg = odom_at()
            publish_until_taken(pub, nav, goal_pose(3.0, 0.0))
            cmd.wait_for(lambda t: not is_zero(t), REPLY_TIMEOUT, start=len(cmd))
            mark, mark_status = len(cmd), len(status)
            feed.msg = bad
            stale = status.wait_for(lambda s: s.state == NavStatus.FAILED, REPLY_TIMEOUT,
                                    start=mark_status)
            assert stale.reason == "STALE_INPUT: odom stale: robot stopped"
            assert wait_until(lambda: sum(map(is_zero, cmd.snapshot()[mark:])) >= 2, REPLY_TIMEOUT)
            time.sleep(0.2)  # for a stray command to show
            after = cmd.snapshot()[mark:]
            first_zero = next(i for i, t in enumerate(after) if is_zero(t))
            # Moving commands in flight before the switch, then: zero (refused odometry), zero
            # (the goal's end), nothing else.
            assert after[first_zero:] == [Twist(), Twist()], after[first_zero:]
            nav.wait_for_log(log)
        feed.stop()
        lidar.stop()
