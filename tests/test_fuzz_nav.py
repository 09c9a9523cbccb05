"""Fuzz test of local_nav_node, planner_node, terrain_node and gait_node through real rclpy (ROS 2
Jazzy, Fast DDS), in the manner of tests/test_fuzz.py (the seed, ``MOBIL_FUZZ_SEED``, is printed
in every failure; fuzzing.py).

Each node gets hostile messages on every input (non-finite, huge and denormal numbers, wrong
frames and lengths, bad stamps, raw CDR buffers broken every way), random goals, abuse of its
action and service protocols (random and duplicate goal ids, cancels and results of ids never
seen), and parameter sets that must be refused. Checked throughout: every number it publishes is
finite (NaN only where NavStatus documents it), every command within the robot's limits; a
motion node's robot gets a zero command after every refused odometry or scan while it moves;
every request is answered. At the end each node still runs, never panicked, logged within its
budget, and still serves a valid goal or request. The motion nodes run without a simulator: the
test feeds the odometry of a robot standing at the origin and an empty scan.
"""

from __future__ import annotations

import math
import random
import time
import uuid
from typing import Any

import pytest

import harness
from fuzzing import (INF, NAN, PER_CALL_TIMEOUT, WRONG_TYPES, Fuzz, answers_parameter_get, mutate,
                     number, rng_for, same_type)
from harness import OdomFeed, OpenSpaceScan, odom_at, stamped_pose as pose, subscribe, wait_until
from rosutil import get_parameters, parameter_value_from_python, set_parameters

from action_msgs.msg import GoalInfo
from action_msgs.srv import CancelGoal
from geometry_msgs.msg import Point, PoseStamped, Twist
from nav_msgs.msg import Odometry, Path
from rclpy._rclpy_pybind11 import RCLError
from rclpy.serialization import serialize_message
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import MarkerArray

from mobil_msgs.msg import FootTouchdown, GaitPlan, NavStatus, TerrainAssessment
from mobil_msgs.srv import CheckRoute, PlanGait
from nav2_msgs.action import DockRobot, FollowWaypoints, NavigateToPose, UndockRobot

OMR3 = "params/omr3.yaml"
V_MAX, OMEGA_MAX = 0.5, 1.5  # params/omr3.yaml
DEEP = harness.make_qos("reliable", "volatile", 1000)
# A refused odometry or scan stops a moving robot at once: the node sends a zero command when it
# reads the input, before any further moving command. Checked in commands, not seconds: the zero
# must be among the first IN_FLIGHT + 1 commands received after the input was sent. The ones
# before it were computed from good inputs the node read first, or sent before the input and not
# yet taken by this process; both nodes send about 20 commands a second, so IN_FLIGHT allows half
# a second of such backlog, on either side, whatever the load. A node that ignored the refusal
# would send no zero at all while the good feeds keep its watchdog (0.5 s without a fresh input)
# quiet: REACTION_TIMEOUT only bounds the wait for the zero.
IN_FLIGHT = 10
REACTION_TIMEOUT = 5.0
# NavStatus fields documented as NaN while unknown (msgs/mobil_msgs/msg/NavStatus.msg).
NAN_WHEN_NONE = frozenset({"distance_to_goal", "e", "alpha", "theta", "lyapunov", "psi_z",
                           "chi_length", "chi_danger", "chi_control", "chi_smoothness"})


def hostile_pose(rng: random.Random) -> PoseStamped:
    """A goal pose with specials, far values, another frame, or a broken quaternion."""
    p = pose(number(rng, -5, 5, special=0.4), number(rng, -5, 5, special=0.4),
             rng.choice(["odom", "odom", "map", "", "/odom", "x" * 300]))
    if rng.random() < 0.3:
        q = p.pose.orientation
        q.x, q.y, q.z, q.w = (number(rng, -1, 1, special=0.5) for _ in range(4))
    return p


def hostile_odom(rng: random.Random) -> tuple[Odometry, str]:
    """Odometry the motion nodes must refuse: NaN/inf, beyond the 1000 km bound, another frame."""
    kind = rng.randrange(4)
    if kind == 0:
        return odom_at(rng.choice([NAN, INF, -INF])), "non-finite"
    if kind == 1:
        return odom_at(rng.choice([1e308, -1e308, 1.5e6])), "too far"
    if kind == 2:
        return odom_at(0.0, frame=rng.choice(["map", "base_link", "x" * 200])), "frame"
    m = odom_at(0.0)
    m.pose.pose.orientation.z = rng.choice([NAN, INF])
    return m, "quaternion"


def hostile_scan(rng: random.Random, good: LaserScan) -> tuple[LaserScan, str]:
    """A scan the checked Scan refuses."""
    m = LaserScan()
    for name in ("header", "angle_min", "angle_max", "angle_increment", "range_min", "range_max", "ranges"):
        setattr(m, name, getattr(good, name))
    kind = rng.randrange(6)
    if kind == 0:
        m.ranges = []
    elif kind == 1:
        m.angle_increment = rng.choice([NAN, -0.01, 0.0, INF])
    elif kind == 2:
        m.angle_min = rng.choice([NAN, -INF])
    elif kind == 3:
        m.ranges = [1.0] * rng.choice([2, 900, 5000])
    elif kind == 4:
        m.range_min, m.range_max = rng.choice([(20.0, 10.0), (NAN, 10.0), (0.1, NAN)])
    else:
        m.intensities = [1.0] * rng.choice([1, 3, 540])
    return m, f"scan defect {kind}"


def is_zero(t: Twist) -> bool:
    return (t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z) == (0,) * 6


def within_limits(t: Twist) -> list[str]:
    out = []
    if math.hypot(t.linear.x, t.linear.y) > V_MAX * (1 + 1e-9):
        out.append(f"speed beyond v_max {V_MAX}: {t.linear.x}, {t.linear.y}")
    if abs(t.angular.z) > OMEGA_MAX * (1 + 1e-9):
        out.append(f"|ω| beyond {OMEGA_MAX}: {t.angular.z}")
    return out


def call(fuzz: Fuzz, client: Any, request: Any, what: str) -> Any:
    """A service call that must be answered within PER_CALL_TIMEOUT (None when it was not)."""
    future = client.call_async(request)
    if not wait_until(future.done, PER_CALL_TIMEOUT):
        fuzz.fail(f"{what}: no answer within {PER_CALL_TIMEOUT} s")
        return None
    return future.result()


def abuse_actions(fuzz: Fuzz, rng: random.Random, node: Any, name: str, action_type: Any,
                  goals: list[Any], rounds: int) -> None:
    """Raw requests on an action's services: random goals with fresh and reused ids, cancels of
    random, known, zero and stamped ids, results of random and known ids. Every one answered; a
    reused id refused; an unknown id's result STATUS_UNKNOWN."""
    impl = action_type.Impl
    send = node.create_client(impl.SendGoalService, f"{name}/_action/send_goal")
    cancel = node.create_client(CancelGoal, f"{name}/_action/cancel_goal")
    result = node.create_client(impl.GetResultService, f"{name}/_action/get_result")
    for c in (send, cancel, result):
        assert c.wait_for_service(timeout_sec=20.0), f"{name}: {c.srv_name} not found"
    used: list[bytes] = []
    for k in range(rounds):
        kind = rng.randrange(5)
        fuzz.case = f"{name} protocol round {k} kind {kind}"
        if kind in (0, 1):
            reuse = kind == 1 and used
            gid = rng.choice(used) if reuse else uuid.uuid4().bytes
            req = impl.SendGoalService.Request()
            req.goal_id.uuid = list(gid)
            req.goal = rng.choice(goals)
            r = call(fuzz, send, req, f"{name} send_goal")
            if r is not None:
                if reuse:
                    fuzz.check(not r.accepted, f"{name}: a goal id in use was accepted")
                elif r.accepted:
                    used.append(gid)
                fuzz.count(f"{name} goals {'accepted' if r is not None and r.accepted else 'refused'}")
        elif kind == 2:
            info = GoalInfo()
            pick = rng.randrange(4)
            if pick == 0 and used:
                info.goal_id.uuid = list(rng.choice(used))
            elif pick == 1:
                info.goal_id.uuid = list(uuid.uuid4().bytes)
            elif pick == 2:
                info.stamp.sec, info.stamp.nanosec = rng.choice([(1, 0), (2**31 - 1, 999_999_999)])
            r = call(fuzz, cancel, CancelGoal.Request(goal_info=info), f"{name} cancel_goal")
            if r is not None:
                fuzz.check(r.return_code in (0, 2, 3), f"{name}: cancel answered {r.return_code}")
                if pick == 1:
                    fuzz.check(r.return_code == 2, f"{name}: cancel of an unknown id answered {r.return_code}")
        else:
            unknown = kind == 3 or not used
            gid = uuid.uuid4().bytes if unknown else rng.choice(used)
            req = impl.GetResultService.Request()
            req.goal_id.uuid = list(gid)
            if unknown:
                r = call(fuzz, result, req, f"{name} get_result")
                if r is not None:
                    fuzz.check(r.status == 0, f"{name}: result of an unknown id has status {r.status}")
            else:
                result.call_async(req)  # a running goal's result comes at its end
    # Whatever runs ends: a cancel of all goals.
    call(fuzz, cancel, CancelGoal.Request(goal_info=GoalInfo()), f"{name} cancel all")


def fuzz_parameters(fuzz: Fuzz, rng: random.Random, node: Any, target: str, count: int) -> None:
    """Random refused sets: wrong types, NaN/inf, unknown names; each leaves the old value."""
    names = harness.param_list(node, target, timeout=10)
    old = {n: v for n, v in zip(names, get_parameters(node, target, names, timeout=10))}
    from rosutil import parameter_value_to_python
    old = {n: parameter_value_to_python(v) for n, v in old.items()}
    for k in range(count):
        name = rng.choice(names)
        value = old[name]
        choices = [w for w in WRONG_TYPES if not same_type(w, value)]
        if isinstance(value, float):
            choices += [NAN, INF, -INF]
        bad = rng.choice(choices)
        if k % 5 == 4:
            name, bad = f"no_such_parameter_{k}", 1.0
        fuzz.case = f"{target} {name}={bad!r}"
        try:
            res = set_parameters(node, target, {name: parameter_value_from_python(bad)}, timeout=PER_CALL_TIMEOUT)[0]
        except TimeoutError as exc:
            fuzz.fail(f"no answer: {exc}")
            continue
        fuzz.check(not res.successful, "accepted")
        fuzz.count(f"{target} refused sets")
        if name in old:
            now = parameter_value_to_python(get_parameters(node, target, [name], timeout=PER_CALL_TIMEOUT)[0])
            fuzz.check(now == old[name] or (isinstance(now, float) and math.isnan(now) and math.isnan(old[name])),
                       f"refused, but the value is now {now!r}")


def raw_flood(fuzz: Fuzz, rng: random.Random, node: Any, topics: list[tuple[Any, Any]], n: int) -> None:
    """``n`` broken CDR buffers on each topic (publisher, a valid message)."""
    for _ in range(n):
        for pub, valid in topics:
            buf, kind = mutate(rng, serialize_message(valid))
            try:
                pub.publish(buf)
                fuzz.count(f"raw {kind}")
            except RCLError:
                fuzz.count("raw refused by rclpy")
        time.sleep(0.002)


def stops_on_refusals(fuzz: Fuzz, rng: random.Random, cmd: Any, restart_goal, bad_inputs: int,
                      odom_pub: Any, scan_pub: Any | None, good_scan: LaserScan | None) -> None:
    """While the robot moves, one refused odometry (or scan) at a time: a zero command must
    follow, before more than IN_FLIGHT moving ones; the good feeds go on and the robot moves
    again."""
    for i in range(bad_inputs):
        fuzz.case = f"refusal {i}"
        try:
            cmd.wait_for(lambda t: not is_zero(t), 3.0, start=len(cmd))
        except TimeoutError:
            restart_goal()
            try:
                cmd.wait_for(lambda t: not is_zero(t), 3.0, start=len(cmd))
            except TimeoutError:
                fuzz.fail("the robot does not move on a valid goal")
                if fuzz.repeated(3):
                    return
                continue
        if scan_pub is not None and good_scan is not None and rng.random() < 0.5:
            msg, kind, pub = *hostile_scan(rng, good_scan), scan_pub
        else:
            msg, kind, pub = *hostile_odom(rng), odom_pub
        mark = len(cmd)
        pub.publish(msg)
        fuzz.case = f"refusal {i}: {kind}"
        fuzz.count(f"refused {kind}")
        try:
            cmd.wait_for(is_zero, REACTION_TIMEOUT, start=mark)
        except TimeoutError:
            fuzz.fail(f"no zero command within {REACTION_TIMEOUT} s of a refused input ({kind})")
            continue
        moving = next(i for i, t in enumerate(cmd.snapshot()[mark:]) if is_zero(t))
        if moving > IN_FLIGHT:
            fuzz.fail(f"{moving} moving commands after a refused input before its zero ({kind})")


def moves_on(fuzz: Fuzz, node: Any, pub: Any, goal: Any, cmd: Any, what: str) -> None:
    """After the fuzz: ``goal`` on ``pub`` still moves the robot."""
    fuzz.case = f"{what} after the fuzz"
    try:
        harness.publish_until(node, pub, goal, lambda: cmd.latest is not None and not is_zero(cmd.latest),
                              rate_hz=2, timeout=10)
    except TimeoutError as exc:
        fuzz.fail(f"{what} no longer moves the robot: {exc}")


@pytest.mark.timeout(150)
def test_fuzz_local_nav(start_node, ros_node):
    rng = rng_for("local_nav")
    fuzz = Fuzz("local_nav")
    nav = start_node("local_nav_node", params_file=OMR3)
    feed = OdomFeed(ros_node, odom_at(0.0))
    lidar = OpenSpaceScan(ros_node)
    fuzz.watch(ros_node, Twist, "cmd_vel", within_limits)
    fuzz.watch(ros_node, NavStatus, "local_nav/status", nan_allowed=NAN_WHEN_NONE)
    fuzz.watch(ros_node, MarkerArray, "local_nav/markers")
    odom_pub = ros_node.create_publisher(Odometry, "odom", 10)
    scan_pub = ros_node.create_publisher(LaserScan, "scan", harness.qos_sensor())
    goal_pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    try:
        answers_parameter_get(fuzz, ros_node, "/local_nav", "sector_count", 8)
        nav.wait_for_log("first scan", timeout=10)
        with subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd:
            def restart() -> None:
                goal_pub.publish(pose(3.0, rng.uniform(-1, 1)))
            stops_on_refusals(fuzz, rng, cmd, restart, 16, odom_pub, scan_pub, lidar.msg)
            fuzz.case = "goal storm"
            for _ in range(150):
                goal_pub.publish(hostile_pose(rng))
            raw_flood(fuzz, rng, ros_node, [(odom_pub, odom_at(0.0)), (scan_pub, lidar.msg),
                                            (goal_pub, pose(1.0, 1.0))], 100)
            nav_goals = [NavigateToPose.Goal(pose=hostile_pose(rng)) for _ in range(6)]
            nav_goals.append(NavigateToPose.Goal(pose=pose(3.0, 0.0)))
            abuse_actions(fuzz, rng, ros_node, "navigate_to_pose", NavigateToPose, nav_goals, 60)
            fuzz_parameters(fuzz, rng, ros_node, "/local_nav", 25)
            moves_on(fuzz, ros_node, goal_pub, pose(3.0, 0.0), cmd, "a valid goal")
    finally:
        lidar.stop()
        feed.stop()
    answers_parameter_get(fuzz, ros_node, "/local_nav", "sector_count", 8)
    fuzz.finish(nav)


@pytest.mark.timeout(150)
def test_fuzz_planner(start_node, ros_node):
    rng = rng_for("planner")
    fuzz = Fuzz("planner")
    plan = start_node("planner_node", "-p", "world_file:=none", "-p", "waypoint_method:=approach",
                      params_file=OMR3)
    feed = OdomFeed(ros_node, odom_at(0.0))
    lidar = OpenSpaceScan(ros_node)
    fuzz.watch(ros_node, Twist, "cmd_vel", within_limits)
    fuzz.watch(ros_node, NavStatus, "planner/status", nan_allowed=NAN_WHEN_NONE)
    fuzz.watch(ros_node, MarkerArray, "planner/markers")
    odom_pub = ros_node.create_publisher(Odometry, "odom", 10)
    dock_pub = ros_node.create_publisher(PoseStamped, "dock_pose", 10)
    route_pub = ros_node.create_publisher(Path, "waypoints", 10)
    check = ros_node.create_client(CheckRoute, "planner/check_route")
    try:
        answers_parameter_get(fuzz, ros_node, "/planner", "gamma", 0.5)
        assert check.wait_for_service(timeout_sec=20.0)
        with subscribe(ros_node, Twist, "cmd_vel", qos=DEEP) as cmd:
            def restart() -> None:
                dock_pub.publish(pose(2.0, rng.uniform(-1, 1)))
            stops_on_refusals(fuzz, rng, cmd, restart, 16, odom_pub, None, None)

            def hostile_path() -> Path:
                p = Path()
                p.header.frame_id = rng.choice(["odom", "map", ""])
                p.poses = [hostile_pose(rng) for _ in range(rng.choice([0, 1, 3, 250]))]
                return p
            fuzz.case = "goal storm"
            for _ in range(100):
                dock_pub.publish(hostile_pose(rng))
                route_pub.publish(hostile_path())
            for k in range(30):
                fuzz.case = f"check_route {k}"
                req = CheckRoute.Request(route=hostile_path(), use_start=rng.random() < 0.5,
                                         start=hostile_pose(rng).pose)
                r = call(fuzz, check, req, "check_route")
                if r is not None:
                    fuzz.check(all(math.isfinite(v) for v in (r.length,)) or r.length == 0.0,
                               f"check_route length {r.length}")
                    fuzz.count(f"check_route {'feasible' if r.feasible else 'refused or infeasible'}")
            raw_flood(fuzz, rng, ros_node, [(odom_pub, odom_at(0.0)), (dock_pub, pose(1.0, 1.0)),
                                            (route_pub, Path())], 100)
            docks = [DockRobot.Goal(use_dock_id=rng.random() < 0.2, dock_pose=hostile_pose(rng)) for _ in range(5)]
            abuse_actions(fuzz, rng, ros_node, "dock_robot", DockRobot, docks, 30)
            undocks = [UndockRobot.Goal(max_undocking_time=number(rng, -5, 60)) for _ in range(5)]
            abuse_actions(fuzz, rng, ros_node, "undock_robot", UndockRobot, undocks, 20)
            routes = [FollowWaypoints.Goal(poses=[hostile_pose(rng) for _ in range(rng.choice([0, 1, 3]))],
                                           goal_index=rng.choice([0, 1, 7]), number_of_loops=rng.choice([0, 2]))
                      for _ in range(5)]
            abuse_actions(fuzz, rng, ros_node, "follow_waypoints", FollowWaypoints, routes, 30)
            fuzz_parameters(fuzz, rng, ros_node, "/planner", 25)
            moves_on(fuzz, ros_node, dock_pub, pose(2.0, 0.0), cmd, "a valid dock")
    finally:
        lidar.stop()
        feed.stop()
    answers_parameter_get(fuzz, ros_node, "/planner", "gamma", 0.5)
    fuzz.finish(plan)


LEGS = ["KP", "KV", "KG", "DP", "DV", "DG"]
FOOTHOLDS = {"KP": (0.15, 0.12), "KV": (0.0, 0.16), "KG": (-0.15, 0.12),
             "DP": (0.15, -0.12), "DV": (0.0, -0.16), "DG": (-0.15, -0.12)}


def touchdown(leg: str, sec: int, nanosec: int, x: float, y: float, z: float,
              frame: str = "base_link") -> FootTouchdown:
    m = FootTouchdown()
    m.header.frame_id = frame
    m.header.stamp.sec, m.header.stamp.nanosec = sec, nanosec
    m.leg = leg
    m.position = Point(x=x, y=y, z=z)
    return m


@pytest.mark.timeout(120)
def test_fuzz_terrain(start_node, ros_node):
    rng = rng_for("terrain")
    fuzz = Fuzz("terrain")
    terrain = start_node("terrain_node", params_file="params/hexapod.yaml")
    fuzz.watch(ros_node, TerrainAssessment, "terrain/assessment")
    fuzz.watch(ros_node, MarkerArray, "terrain/markers")
    pub = ros_node.create_publisher(FootTouchdown, "terrain/touchdown", harness.make_qos("reliable", "volatile", 10))
    assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
    sec = 1
    for k in range(600):
        leg = rng.choice(LEGS + ["XY", "", "kp", "x" * 200])
        fx, fy = FOOTHOLDS.get(leg, (0.0, 0.1))
        x, y = fx + number(rng, -0.02, 0.02, 0.2), fy + number(rng, -0.02, 0.02, 0.2)
        z = number(rng, -0.14, -0.06, 0.2)
        stamp = rng.randrange(8)
        if stamp == 0:
            sec, nano = 0, 0
        elif stamp == 1:
            sec, nano = sec - rng.choice([1, 100]), 0
        elif stamp == 2:
            nano = rng.choice([1_000_000_000, 2**32 - 1])
        else:
            sec, nano = sec + 1, 0
        fuzz.case = f"touchdown {k}"
        pub.publish(touchdown(leg, max(-(2**31), min(sec, 2**31 - 1)), nano, x, y, z,
                              rng.choice(["base_link"] * 4 + ["odom", ""])))
        if k % 100 == 99:
            time.sleep(0.05)
    raw_flood(fuzz, rng, ros_node, [(pub, touchdown("KP", 1, 0, 0.15, 0.12, -0.1))], 200)
    fuzz.case = "a valid column after the fuzz"
    with subscribe(ros_node, TerrainAssessment, "terrain/assessment",
                   qos=harness.make_qos("reliable", "transient_local", 100)) as rec:
        # A flat column far in the future: stamped after everything the fuzz sent.
        def sent() -> bool:
            for j, leg in enumerate(LEGS):
                x, y = FOOTHOLDS[leg]
                pub.publish(touchdown(leg, 2_000_000_000, j, x, y, -0.10))
            return any(a.header.stamp.sec == 2_000_000_000 and a.sigma == 0.0 for a in rec.snapshot())
        fuzz.check(wait_until(sent, 10.0, interval=0.5), "a flat column is no longer assessed")
    fuzz.finish(terrain)


@pytest.mark.timeout(150)
def test_fuzz_gait(start_node, ros_node):
    rng = rng_for("gait")
    fuzz = Fuzz("gait")
    gait = start_node("gait_node", params_file="params/quadruped.yaml")
    fuzz.watch(ros_node, GaitPlan, "gait/plan")
    fuzz.watch(ros_node, MarkerArray, "gait/markers")
    fuzz.watch(ros_node, PoseStamped, "gait/body")
    client = ros_node.create_client(PlanGait, "gait/compute_plan")
    assert client.wait_for_service(timeout_sec=20.0)
    goal_pub = ros_node.create_publisher(PoseStamped, "goal_pose", 10)
    terrain_pub = ros_node.create_publisher(TerrainAssessment, "terrain/assessment",
                                            harness.qos_latched())
    for k in range(40):
        fuzz.case = f"compute_plan {k}"
        r = PlanGait.Request()
        r.start.x, r.start.y = number(rng, -20, 20, 0.3), number(rng, -20, 20, 0.3)
        r.start.theta = number(rng, -7, 7, 0.3)
        r.goal.x, r.goal.y, r.goal.z = (number(rng, -20, 20, 0.3) for _ in range(3))
        r.rule_set = rng.choice(["A", "B", "", "C", "a", "x" * 500])
        r.evaluation = rng.choice([0, 1, 2, 3, 4, 255])
        r.max_expansions = rng.choice([0, 1, 50, 2**32 - 1])
        reply = call(fuzz, client, r, "compute_plan")
        if reply is not None:
            fuzz.count("plans found" if reply.plan.success else "plans refused or not found")
            bad = [p for p in ("states_expanded",) if getattr(reply.plan, p) < 0]
            fuzz.check(not bad, f"negative {bad}")
    for k in range(60):
        fuzz.case = f"goal_pose / assessment {k}"
        goal_pub.publish(hostile_pose(rng))
        a = TerrainAssessment()
        a.sigma, a.alpha12, a.alpha13, a.alpha23, a.tilt = (number(rng, -1, 1, 0.4) for _ in range(5))
        a.terrain_class = rng.choice([0, 1, 2, 3, 9, 255])
        a.advised_gait = rng.choice([0, 1, 2, 3, 200])
        terrain_pub.publish(a)
        time.sleep(0.01)
    raw_flood(fuzz, rng, ros_node, [(goal_pub, pose(1.0, 1.0)), (terrain_pub, TerrainAssessment())], 100)
    terrain_pub.publish(TerrainAssessment())  # flat again, so the valid request below is planned as usual
    goal_pub.publish(pose(0.0, 0.0))
    fuzz.case = "a valid request after the fuzz"
    r = PlanGait.Request()
    r.start.theta = math.pi / 4
    r.goal.x, r.goal.y, r.rule_set, r.evaluation = -10.0, 10.0, "A", 1
    reply = call(fuzz, client, r, "the paper's request")
    fuzz.check(reply is not None and reply.plan.success, f"a valid request is no longer planned: {reply}")
    fuzz.finish(gait)
