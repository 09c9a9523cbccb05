"""Nav2's roles from real rclpy (ROS 2 Jazzy, Fast DDS). The controller role: ``follow_path``
(nav2_msgs/action/FollowPath) driven as Nav2's navigator drives a controller server, a new path
about every second, on the simulated OMR-III and MOBIL-II in the built-in world, by
local_nav_node (the vector-distance function) and planner_node (the goal approach, and VFO on
OMR-III). The behavior role (drive_node), stamped commands and the dock database follow.

The navigator stand-in re-plans as a global planner would: every simulated second a path from
the robot's odometry pose straight to the next corner of the route not yet passed, then along
the rest, poses 5 cm apart (as Nav2's planners space them).
"""

from __future__ import annotations

import math
import threading

import pytest

from action_client import ActionClient
from harness import make_qos, run_ros2cli, subscribe, wait_until
from rosutil import wait_for_future

from action_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped, Twist
from nav2_msgs.action import FollowPath
from nav_msgs.msg import Odometry, Path

REAL_TIME_FACTOR = 3.0
CHASSIS_ARGS = ("-p", "feedback_timeout_s:=2.0")
NODE_ARGS = ("-p", "use_sim_time:=true", "-p", "odom_timeout_s:=2.0", "-p", "clock_timeout_s:=2.0")
REPLY_TIMEOUT = 10.0
# Around the pillar at (1, 1.5) of the built-in world (sim_node's): 3 m east, 3 m north. The
# box east starts at x = 4.5, the triangle south below y = -1.2.
ROUTE = [(0.0, 0.0), (3.0, 0.0), (3.0, 3.0)]
# A corner is passed once the robot is this near it.
CORNER_PASSED = 0.6


def path_msg(points, frame: str = "odom", spacing: float = 0.05) -> Path:
    """A path through ``points``, poses every ``spacing`` metres (the corners included)."""
    msg = Path()
    msg.header.frame_id = frame
    dense = []
    for (x0, y0), (x1, y1) in zip(points, points[1:]):
        n = max(1, int(math.dist((x0, y0), (x1, y1)) / spacing))
        dense += [(x0 + (x1 - x0) * k / n, y0 + (y1 - y0) * k / n) for k in range(n)]
    dense.append(points[-1])
    for x, y in dense:
        pose = PoseStamped()
        pose.header.frame_id = frame
        pose.pose.position.x, pose.pose.position.y = float(x), float(y)
        pose.pose.orientation.w = 1.0
        msg.poses.append(pose)
    return msg


def follow_goal(points, controller: str = "") -> FollowPath.Goal:
    goal = FollowPath.Goal()
    goal.path = path_msg(points) if points else Path()
    goal.path.header.frame_id = "odom"
    goal.controller_id = controller
    return goal


def accepted(client: ActionClient, goal, attempts: int = 4, feedback=None):
    for _ in range(attempts):
        future = client.send_goal_async(goal, feedback_callback=feedback)
        if wait_until(future.done, 3.0):
            handle = future.result()
            assert handle.accepted, "follow_path goal rejected"
            return handle
    raise AssertionError("no answer to a follow_path goal")


def result_of(handle, timeout: float = REPLY_TIMEOUT):
    future = handle.get_result_async()
    assert wait_for_future(future, timeout), "no follow_path result"
    return future.result()


def is_zero(t: Twist) -> bool:
    return t.linear.x == 0.0 and t.linear.y == 0.0 and t.angular.z == 0.0


class Navigator:
    """Nav2's navigator as a controller server sees it: a FollowPath goal along the rest of
    ``route`` every simulated second, from the robot's odometry pose."""

    def __init__(self, client: ActionClient, odom, sim_clock, route, controller: str = "") -> None:
        self.client, self.odom, self.clock, self.route = client, odom, sim_clock, route
        self.controller = controller
        self.handles: list = []
        self.feedback: list = []  # (distance_to_goal, speed) of every goal
        self.next_corner = 1
        self._stop = threading.Event()
        self.failure: BaseException | None = None
        self._thread = threading.Thread(target=self._run, daemon=True)

    def passed(self, x: float, y: float) -> bool:
        """Whether the robot at (x, y) has passed the next corner: near it, or beyond it along
        the leg after it (a controller may cut a corner by up to half its lookahead)."""
        (cx, cy), (nx, ny) = self.route[self.next_corner], self.route[self.next_corner + 1]
        beyond = (x - cx) * (nx - cx) + (y - cy) * (ny - cy) > 0.0
        return beyond or math.dist((x, y), (cx, cy)) < CORNER_PASSED

    def path_from(self, x: float, y: float) -> list:
        while self.next_corner < len(self.route) - 1 and self.passed(x, y):
            self.next_corner += 1
        return [(x, y), *self.route[self.next_corner:]]

    def send(self) -> None:
        p = self.odom.latest.pose.pose.position
        if self.handles and math.dist((p.x, p.y), self.route[-1]) < CORNER_PASSED:
            return  # at the end: a navigator re-plans no more (the last goal finishes the route)
        path = follow_goal(self.path_from(p.x, p.y), controller=self.controller)
        keep = lambda f: self.feedback.append((f.feedback.distance_to_goal, f.feedback.speed))  # noqa: E731
        self.handles.append(accepted(self.client, path, feedback=keep))

    def _run(self) -> None:
        try:
            while not self._stop.is_set():
                t = self.clock.now()
                self.clock.wait_until(t + 1.0)
                if not self._stop.is_set():
                    self.send()
        except BaseException as e:  # noqa: BLE001 (reported by the test)
            self.failure = e

    def start(self) -> "Navigator":
        self.send()
        self._thread.start()
        return self

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(timeout=10)


@pytest.mark.timeout(150)
@pytest.mark.parametrize("node,robot,controller", [
    ("local_nav_node", "omr3", ""),
    ("local_nav_node", "mobil2", ""),
    ("planner_node", "omr3", "approach"),
    ("planner_node", "mobil2", ""),  # its waypoint_method: the goal approach
    ("planner_node", "omr3", ""),  # its waypoint_method: VFO
])
def test_follow_path_replanned_every_second_reaches_the_end_without_a_stop(
        node, robot, controller, start_scenario, start_node, sim_clock, ros_node):
    params = f"params/{robot}.yaml"
    start_scenario(params, real_time_factor=REAL_TIME_FACTOR, lidar=True, node_args=CHASSIS_ARGS)
    nav = start_node(node, *NODE_ARGS, params_file=params)
    client = ActionClient(ros_node, FollowPath, "follow_path")
    deep = make_qos("reliable", "volatile", 5000)
    with subscribe(ros_node, Odometry, "odom", qos=deep) as odom, \
            subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth, \
            subscribe(ros_node, Twist, "cmd_vel", qos=deep) as cmd, \
            subscribe(ros_node, Path, "plan", qos=deep) as plans, \
            subscribe(ros_node, Path, "local_plan", qos=deep) as local_plans:
        sim_clock.wait_started()
        odom.wait_for(None, REPLY_TIMEOUT)
        assert client.wait_for_server(timeout_sec=20.0)
        # Goals that cannot be followed: accepted, ended at once with Nav2's codes.
        for goal, code in ((follow_goal([]), FollowPath.Result.INVALID_PATH),
                           (follow_goal([(1.0, 0.0)], controller="dwb"), FollowPath.Result.INVALID_CONTROLLER)):
            res = result_of(accepted(client, goal))
            assert res.status == GoalStatus.STATUS_ABORTED and res.result.error_code == code, \
                (res.status, res.result.error_code, res.result.error_msg)
        # local_nav steps on scans, VFO needs one: wait for the first one before the route starts.
        nav.wait_for_log(r"first scan", REPLY_TIMEOUT)
        assert len(cmd) == 0, "cmd_vel before a goal that can be followed"

        navigator = Navigator(client, odom, sim_clock, ROUTE, controller).start()
        t0 = sim_clock.now()
        final = None
        try:
            # About 6 m at up to 0.5 m/s, with the corners: 20 simulated seconds at most. The
            # last goal sent ends the route; one replaced meanwhile ends PREEMPTED.
            while final is None:
                assert sim_clock.now() - t0 < 40.0, "the route did not end within 40 simulated s"
                assert navigator.failure is None, navigator.failure
                future = navigator.handles[-1].get_result_async()
                if wait_until(future.done, 0.5) and not future.result().result.error_msg.startswith("PREEMPTED"):
                    final = future.result()
        finally:
            navigator.stop()
        handles = list(navigator.handles)
        sim_clock.wait_until(sim_clock.now() + 1.0)
        commands = cmd.snapshot()
        end = truth.latest.pose.pose.position
        plan_msgs, local_msgs = plans.snapshot(), local_plans.snapshot()

    assert final.status == GoalStatus.STATUS_SUCCEEDED, (final.status, final.result.error_msg)
    assert final.result.error_code == FollowPath.Result.NONE
    # Feedback: the distance along the route to its end (6 m at the start) and the speed.
    feedback = list(navigator.feedback)
    assert len(feedback) > 20, len(feedback)
    assert 5.0 < feedback[0][0] <= 6.1 and feedback[-1][0] < 0.5, (feedback[0], feedback[-1])
    assert max(v for _, v in feedback) > 0.2 and all(v >= 0.0 for _, v in feedback)
    assert len(handles) >= 8, f"only {len(handles)} paths sent: the stand-in did not re-plan every second"
    # Every replaced goal ended ABORTED with no error, as controller_server ends a preempted one.
    for h in handles[:-2]:
        r = result_of(h)
        assert r.status == GoalStatus.STATUS_ABORTED and r.result.error_code == FollowPath.Result.NONE
    zeros = [i for i, c in enumerate(commands) if is_zero(c)]
    if node == "planner_node":
        law = "vfo" if controller == "" and robot == "omr3" else "approach"
        assert f"by {law}" in nav.log_text(), nav.log_tail()
    if node == "planner_node" and controller == "" and robot == "omr3":
        # VFO keeps its law across paths to the same end that pass within half a lookahead of
        # the sub-goal it pursues (PathTask::replace, tested in mobil_planner), and holds the
        # robot only while a segment's optimisation outlasts an odometry period (a machine under
        # load). The stand-in plans from the odometry this process has taken: on a loaded
        # machine a path can start from a pose some tenths of a second old and miss that
        # sub-goal, and VFO then starts anew on it, as it should (seen once in a fresh-clone
        # run): one restart is allowed, more mean the law did not outlast the re-plans.
        assert nav.log_text().count("starts anew") <= 1, nav.log_tail()
        assert zeros[-1] == len(commands) - 1, f"zero commands at {zeros} of {len(commands)}"
    else:
        # No zero command while the paths came: only the last one, at the end.
        assert zeros == [len(commands) - 1], f"zero commands at {zeros} of {len(commands)}"
    xg, yg = ROUTE[-1]
    assert math.hypot(end.x - xg, end.y - yg) < 0.25, (end.x, end.y)
    # Plans as nav_msgs/Path in odom. As a controller the planner leaves `plan` to Nav2's
    # planner; on `local_plan`, what the controller heads for now (local_nav: from the robot to
    # its sub-goal; VFO: the chosen path), an empty one once the goal ended.
    vfo = node == "planner_node" and controller == "" and robot == "omr3"
    assert not any(p.poses for p in plan_msgs), "a controller published plan"
    if node == "local_nav_node" or vfo:
        drawn = [p for p in local_msgs if p.poses]
        assert drawn and all(len(p.poses) >= 2 and p.header.frame_id == "odom" for p in drawn)
        assert not local_msgs[-1].poses, "local_plan not cleared at the end"


# ---------------------------------------------------------------------------------------------
# Nav2's behavior role: drive_node's backup, drive_on_heading and spin
# ---------------------------------------------------------------------------------------------

# A wall behind the robot: 0.1 m thick, its face at x = -0.35, from y = -1 to 1.
WALL_BEHIND = "obstacles:\n  - polygon: { points: [[-0.45, -1.0], [-0.35, -1.0], [-0.35, 1.0], [-0.45, 1.0]] }\n"
# The collision check sees what the scan sees: a LIDAR all round (the default 270° one is blind
# straight behind, where a wall 0.55 m back lies outside its view).
LIDAR_ALL_ROUND = ("-p", "lidar.fov:=6.283185307179586", "-p", "lidar.beams:=720")


def duration(seconds: float):
    from builtin_interfaces.msg import Duration
    d = Duration()
    d.sec = int(seconds)
    d.nanosec = int(round((seconds - int(seconds)) * 1e9))
    return d


def yaw_of(m: Odometry) -> float:
    q = m.pose.pose.orientation
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def run_goal(client: ActionClient, goal, timeout: float = 30.0, feedback=None):
    handle = None
    for _ in range(4):
        future = client.send_goal_async(goal, feedback_callback=feedback)
        if wait_until(future.done, 3.0):
            handle = future.result()
            break
    assert handle is not None and handle.accepted, f"{client._action_name}: goal not accepted"
    return result_of(handle, timeout)


@pytest.mark.timeout(120)
def test_backup_drive_on_heading_and_spin_reach_their_targets_collide_and_time_out(
        start_scenario, start_node, sim_clock, ros_node, tmp_path):
    """OMR-III with a LIDAR all round and a wall 0.35 m behind: DriveOnHeading 0.5 m, BackUp 0.3 m
    and Spin π/2 reach their targets by ground truth; then, 0.55 m from the wall, a BackUp of 1 m
    at 0.2 m/s gives COLLISION_AHEAD at once (the 2 s horizon reaches 0.4 m, the footprint 0.25 m
    more: 0.65 m); a 0.3 s time_allowance for a 1 m drive gives TIMEOUT."""
    from nav2_msgs.action import BackUp, DriveOnHeading, Spin

    world = tmp_path / "wall_behind.yaml"
    world.write_text(WALL_BEHIND)
    params = "params/omr3.yaml"
    start_scenario(params, real_time_factor=2.0, lidar=True, node_args=CHASSIS_ARGS,
                   sim_args=("-p", f"world_file:={world}", *LIDAR_ALL_ROUND))
    start_node("drive_node", *NODE_ARGS, params_file=params)
    clients = {name: ActionClient(ros_node, kind, name)
               for name, kind in (("backup", BackUp), ("drive_on_heading", DriveOnHeading), ("spin", Spin))}
    deep = make_qos("reliable", "volatile", 5000)
    with subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        for name, client in clients.items():
            assert client.wait_for_server(timeout_sec=20.0), name

        def settled() -> Odometry:
            sim_clock.wait_until(sim_clock.now() + 1.0)
            return truth.latest

        start = settled()
        goal = DriveOnHeading.Goal()
        goal.target.x, goal.speed = 0.5, 0.2
        feedback = []
        res = run_goal(clients["drive_on_heading"], goal, feedback=lambda f: feedback.append(f.feedback))
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        assert res.result.error_code == DriveOnHeading.Result.NONE
        assert feedback and 0.0 <= feedback[-1].distance_traveled <= 0.5
        ahead = settled()
        moved = ahead.pose.pose.position.x - start.pose.pose.position.x
        assert abs(moved - 0.5) < 0.03, moved
        # 2.5 s of driving at 0.2 m/s, and the ramp-down: between 2.5 and 5 simulated seconds.
        elapsed = res.result.total_elapsed_time.sec + res.result.total_elapsed_time.nanosec * 1e-9
        assert 2.5 <= elapsed <= 5.0, elapsed

        goal = BackUp.Goal()
        goal.target.x, goal.speed = 0.3, 0.1
        res = run_goal(clients["backup"], goal)
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        back = settled()
        moved = back.pose.pose.position.x - ahead.pose.pose.position.x
        assert abs(moved + 0.3) < 0.03, moved

        goal = Spin.Goal()
        goal.target_yaw = math.pi / 2
        res = run_goal(clients["spin"], goal)
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        turned = settled()
        dyaw = math.remainder(yaw_of(turned) - yaw_of(back), math.tau)
        assert abs(dyaw - math.pi / 2) < 0.05, dyaw
        # Face east again: the wall is behind.
        goal.target_yaw = -math.pi / 2
        assert run_goal(clients["spin"], goal).status == GoalStatus.STATUS_SUCCEEDED
        settled()

        goal = BackUp.Goal()
        goal.target.x, goal.speed = 1.0, 0.2
        res = run_goal(clients["backup"], goal)
        assert res.status == GoalStatus.STATUS_ABORTED
        assert res.result.error_code == BackUp.Result.COLLISION_AHEAD, res.result.error_msg

        goal = DriveOnHeading.Goal()
        goal.target.x, goal.speed, goal.time_allowance = 1.0, 0.1, duration(0.3)
        res = run_goal(clients["drive_on_heading"], goal)
        assert res.status == GoalStatus.STATUS_ABORTED
        assert res.result.error_code == DriveOnHeading.Result.TIMEOUT, res.result.error_msg
        # Nav2's rules: a y component is INVALID_INPUT.
        goal = DriveOnHeading.Goal()
        goal.target.x, goal.target.y, goal.speed = 0.5, 0.1, 0.1
        res = run_goal(clients["drive_on_heading"], goal)
        assert res.result.error_code == DriveOnHeading.Result.INVALID_INPUT


# ---------------------------------------------------------------------------------------------
# enable_stamped_cmd_vel: the robot driven on TwistStamped only
# ---------------------------------------------------------------------------------------------

STAMPED = ("-p", "enable_stamped_cmd_vel:=true")


@pytest.mark.timeout(120)
def test_stamped_cmd_vel_drives_the_robot_and_a_twist_publisher_is_told(
        start_scenario, start_node, sim_clock, ros_node):
    """With enable_stamped_cmd_vel:=true on chassis_node, drive_node, local_nav_node and
    planner_node, cmd_vel is TwistStamped only (stamped with ROS time, in base_link), and each
    of the three moves the simulated OMR-III to its goal: a drive of 0.3 m, a path to
    (1.2, 0), a docking at (2, 0). A Twist publisher on cmd_vel is then told in chassis_node's
    log, with what to set."""
    from geometry_msgs.msg import TwistStamped
    from nav2_msgs.action import DockRobot, DriveOnHeading

    params = "params/omr3.yaml"
    sim, chassis = start_scenario(params, real_time_factor=2.0, lidar=True,
                                  node_args=(*CHASSIS_ARGS, *STAMPED))
    # Names of their own: a node of an earlier test in this domain (one killed, say) can linger
    # in the graph for a while under its name.
    names = ("stamped_drive", "stamped_local_nav", "stamped_planner")
    for exe, name in zip(("drive_node", "local_nav_node", "planner_node"), names):
        start_node(exe, *NODE_ARGS, *STAMPED, params_file=params, name=name)
    drive = ActionClient(ros_node, DriveOnHeading, "drive_on_heading")
    follow = ActionClient(ros_node, FollowPath, "follow_path")
    dock = ActionClient(ros_node, DockRobot, "dock_robot")
    deep = make_qos("reliable", "volatile", 5000)
    with subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth, \
            subscribe(ros_node, TwistStamped, "cmd_vel", qos=deep) as cmd:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        for client in (drive, follow, dock):
            assert client.wait_for_server(timeout_sec=20.0)

        goal = DriveOnHeading.Goal()
        goal.target.x, goal.speed = 0.3, 0.2
        res = run_goal(drive, goal)
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        res = run_goal(follow, follow_goal([(0.3, 0.0), (1.2, 0.0)]))
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        goal = DockRobot.Goal()
        goal.use_dock_id = False
        goal.dock_pose.header.frame_id = "odom"
        goal.dock_pose.pose.position.x = 2.0
        goal.dock_pose.pose.orientation.w = 1.0
        res = run_goal(dock, goal, timeout=40.0)
        assert res.status == GoalStatus.STATUS_SUCCEEDED, res.result.error_msg
        sim_clock.wait_until(sim_clock.now() + 1.0)
        end = truth.latest.pose.pose.position
        publishers = {(i.node_name, i.topic_type) for i in ros_node.get_publishers_info_by_topic("/cmd_vel")
                      if i.node_name in names}
        readers = {(i.node_name, i.topic_type) for i in ros_node.get_subscriptions_info_by_topic("/cmd_vel")
                   if i.node_name == "chassis"}
        commands = cmd.snapshot()

        # A Twist publisher (another process: one participant cannot have both types).
        run_ros2cli("topic", "pub", "/cmd_vel", "geometry_msgs/msg/Twist", "{}",
                    "--times", "4", "-w", "0", "--rate", "1", timeout=30.0)
        chassis.wait_for_log(r"cmd_vel: a publisher of geometry_msgs/msg/Twist is on the topic.*"
                             r"enable_stamped_cmd_vel:=false", 15.0)

    assert publishers == {(n, "geometry_msgs/msg/TwistStamped") for n in names}, publishers
    assert readers == {("chassis", "geometry_msgs/msg/TwistStamped")}, readers
    assert math.hypot(end.x - 2.0, end.y) < 0.1, (end.x, end.y)
    assert len(commands) > 50
    assert {c.header.frame_id for c in commands} == {"base_link"}
    assert all(c.header.stamp.sec > 0 or c.header.stamp.nanosec > 0 for c in commands)


# ---------------------------------------------------------------------------------------------
# The dock database: dock_robot by dock_id
# ---------------------------------------------------------------------------------------------

DOCKS = """planner:
  ros__parameters:
    docks: ["dock1", "in_map"]
    dock1:
      type: charging_dock
      frame: odom
      pose: [1.0, 0.5, 1.0]
      id: "c67f50cb"
    in_map:
      pose: [0.0, 0.0, 0.0]
"""


@pytest.mark.timeout(120)
def test_dock_id_goals_dock_at_the_databases_pose(start_scenario, start_node, sim_clock, ros_node, tmp_path):
    """Docks named in the planner's parameters, as opennav_docking takes them: a goal naming
    dock1 docks at its pose (ground truth within 0.05 m and 0.1 rad, as the planner's docking
    tests ask); an unknown name gives DOCK_NOT_IN_DB, a dock in `map` with no `map → odom` UNKNOWN (TF_ERROR)."""
    from nav2_msgs.action import DockRobot

    docks = tmp_path / "docks.yaml"
    docks.write_text(DOCKS)
    params = "params/omr3.yaml"
    start_scenario(params, real_time_factor=3.0, node_args=CHASSIS_ARGS)
    planner = start_node("planner_node", *NODE_ARGS, "--params-file", str(docks), params_file=params)
    planner.wait_for_log(r"dock `dock1` \(charging_dock\) at \(1\.000, 0\.500, 1\.000 rad\) in odom")
    planner.wait_for_log(r"dock `in_map` is in frame `map`")
    # The other form: a dock_database file (opennav_docking's), read at start by a second planner.
    database = tmp_path / "dock_database.yaml"
    database.write_text("docks:\n  home:\n    type: charging_dock\n    frame: odom\n    pose: [0.3, -0.2, 3.0]\n")
    # (In a namespace of its own, so that its actions are not this test's.)
    other = start_node("planner_node", "-r", "__ns:=/from_file", "-p", f"dock_database:={database}",
                       params_file=params, name="planner_from_file")
    other.wait_for_log(r"dock `home` \(charging_dock\) at \(0\.300, -0\.200, 3\.000 rad\) in odom")
    other.stop()
    client = ActionClient(ros_node, DockRobot, "dock_robot")
    deep = make_qos("reliable", "volatile", 5000)
    with subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth:
        sim_clock.wait_started()
        truth.wait_for(None, REPLY_TIMEOUT)
        assert client.wait_for_server(timeout_sec=20.0)

        def by_id(name: str) -> DockRobot.Goal:
            goal = DockRobot.Goal()
            goal.use_dock_id, goal.dock_id = True, name
            return goal

        # `in_map` needs `map → odom`, which nothing publishes here: UNKNOWN (TF_ERROR).
        for name, code in (("nowhere", DockRobot.Result.DOCK_NOT_IN_DB),
                           ("in_map", DockRobot.Result.UNKNOWN)):
            res = run_goal(client, by_id(name))
            assert res.status == GoalStatus.STATUS_ABORTED and res.result.error_code == code, \
                (name, res.result.error_code, res.result.error_msg)
        res = run_goal(client, by_id("dock1"), timeout=40.0)
        assert res.status == GoalStatus.STATUS_SUCCEEDED and res.result.success, res.result.error_msg
        sim_clock.wait_until(sim_clock.now() + 1.0)
        end = truth.latest
    p = end.pose.pose.position
    assert math.hypot(p.x - 1.0, p.y - 0.5) < 0.05, (p.x, p.y)
    assert abs(math.remainder(yaw_of(end) - 1.0, math.tau)) < 0.1, yaw_of(end)
