"""gait_node from real rclpy (ROS 2 Jazzy, Fast DDS), through exactly the interfaces other
programs rely on: `gait/compute_plan` (mobil_msgs/srv/PlanGait), `goal_pose` in, `gait/plan`
(latched) and `gait/body` out, `terrain/assessment` (latched) in.

Expected values are worked out by hand, not taken from the node:
* The start state of the paper's experiment A,(1): body at (0, 0), φ = π/4, legs nominal — each
  foot at 1.5 [j] from its hip along the body's ±x_r, i.e. at (±2.5, ±1.5) in the body frame
  (SPEC §7), rotated by φ into the world.
* A plan is a path of rules: each step's moving_leg is −1 (body move, rules 1..3) or the leg
  (0..3) of its rule ((rule − 4) mod 4 for rules 4..27); the last body lies within the goal
  tolerance (0.5 [j], params/quadruped.yaml) of the goal.
* UNEVEN ground (uneven_stability_margin 0.15, uneven_translation_step 0.5 [j], the gait
  section's): the test computes, from the plan's own feet, the distance of the body centre
  inside the triangle of the three feet standing while each leg moves; on UNEVEN ground none is
  below 0.15, and each rule-2 step (translate by ΔY) moves the body by exactly 0.5 instead of
  1.0. That is how the reaction is observed in the plan.
"""

from __future__ import annotations

import math
import time

from geometry_msgs.msg import PoseStamped
from rclpy.serialization import serialize_message
from visualization_msgs.msg import Marker, MarkerArray

from harness import make_qos, param_set, qos_latched, subscribe, wait_until

from mobil_msgs.msg import GaitPlan, TerrainAssessment
from mobil_msgs.srv import PlanGait

PARAMS = "params/quadruped.yaml"
GOAL_TOLERANCE = 0.5
UNEVEN_MARGIN = 0.15
UNEVEN_STEP = 0.5
REPLY_TIMEOUT = 10.0


def call(client, request, attempts: int = 4):
    """A service call, re-sent after 3 s without a reply (ROS2-NOTES: the first call after
    discovery may stall). A stalled request that arrives after its re-sent copy is pre-empted by
    it (or pre-empts it): the answer is the first reply that is not "pre-empted"."""
    futures = []

    def answered():
        return next((f.result() for f in futures
                     if f.done() and f.result().plan.reason != "pre-empted"), None)

    for _ in range(attempts):
        futures.append(client.call_async(request))
        if wait_until(lambda: answered() is not None, 3.0):
            return answered()
    raise AssertionError("no reply from gait/compute_plan")


def request(start=(0.0, 0.0, math.pi / 4), goal=(-10.0, 10.0), rule_set="A", evaluation=1,
            max_expansions=0) -> PlanGait.Request:
    r = PlanGait.Request()
    r.start.x, r.start.y, r.start.theta = start
    r.goal.x, r.goal.y = goal
    r.rule_set, r.evaluation, r.max_expansions = rule_set, evaluation, max_expansions
    return r


def nominal_feet(x: float, y: float, phi: float) -> list[tuple[float, float]]:
    """Legs 0 front left, 1 rear left, 2 front right, 3 rear right at (±2.5, ±1.5) in the body
    frame (x_r across, y_r forward), rotated by φ."""
    body = [(-2.5, 1.5), (-2.5, -1.5), (2.5, 1.5), (2.5, -1.5)]
    c, s = math.cos(phi), math.sin(phi)
    return [(x + c * bx - s * by, y + s * bx + c * by) for bx, by in body]


def margin_inside(p, q, r, c) -> float:
    """Signed distance of c inside triangle pqr (least distance to an edge; negative outside)."""
    area = (q[0] - p[0]) * (r[1] - p[1]) - (q[1] - p[1]) * (r[0] - p[0])
    sign = 1.0 if area > 0 else -1.0
    out = math.inf
    for u, v in ((p, q), (q, r), (r, p)):
        ex, ey = v[0] - u[0], v[1] - u[1]
        out = min(out, sign * (ex * (c[1] - u[1]) - ey * (c[0] - u[0])) / math.hypot(ex, ey))
    return out


def leg_move_margins(plan) -> list[float]:
    """For each leg move: the body centre's distance inside the other three feet."""
    margins = []
    for s in plan.steps[1:]:
        if s.moving_leg >= 0:
            feet = [(f.x, f.y) for k, f in enumerate(s.feet) if k != s.moving_leg]
            margins.append(margin_inside(*feet, (s.body.x, s.body.y)))
    return margins


def translate_lengths(plan) -> list[float]:
    """Body displacement of every rule-2 step (translate by ΔY)."""
    return [math.hypot(b.body.x - a.body.x, b.body.y - a.body.y)
            for a, b in zip(plan.steps, plan.steps[1:]) if b.rule == 2]


def check_path_start(plan, start) -> None:
    """steps[0] is the start, legs nominal."""
    first = plan.steps[0]
    assert (first.rule, first.moving_leg) == (0, -1)
    assert (first.body.x, first.body.y, first.body.theta) == start
    for f, (x, y) in zip(first.feet, nominal_feet(*start)):
        assert math.hypot(f.x - x, f.y - y) < 1e-9, (f, x, y)


def check_plan(plan, start, goal, rule_count: int) -> None:
    assert plan.success, plan.reason
    assert plan.reason == ""
    assert plan.states_expanded > 0 and plan.states_generated >= plan.states_expanded
    check_path_start(plan, start)
    for s in plan.steps[1:]:
        assert 1 <= s.rule <= rule_count, s.rule
        assert s.moving_leg == (-1 if s.rule <= 3 else (s.rule - 4) % 4), (s.rule, s.moving_leg)
        assert -1 <= s.moving_leg <= 3
    last = plan.steps[-1].body
    assert math.hypot(last.x - goal[0], last.y - goal[1]) <= GOAL_TOLERANCE + 1e-9


def start_gait(start_node, ros_node, *args):
    proc = start_node("gait_node", *args, params_file=PARAMS)
    client = ros_node.create_client(PlanGait, "gait/compute_plan")
    assert client.wait_for_service(timeout_sec=20.0)
    return proc, client


def test_compute_plan_the_papers_experiment_refusals_preemption_and_uneven_ground(start_node, ros_node):
    # max_generated_states raised so that a long search (below) is bounded by time, not memory.
    gait, client = start_gait(start_node, ros_node, "-p", "time_limit_s:=5.0",
                              "-p", "max_generated_states:=100000000")
    start, goal = (0.0, 0.0, math.pi / 4), (-10.0, 10.0)

    # The paper's experiment A,(1).
    even = call(client, request(start, goal)).plan
    check_plan(even, start, goal, 11)
    assert (even.rule_set, even.evaluation) == ("A", 1)

    # A far goal: B,(3) to (−900, 900), 1270 [j] away, reaches it in thousands of states, all
    # of them in the reply (the default max_plan_states is 0, no limit): from the start to the
    # goal, each step a rule of set B. Hundreds of KB: the tests' Fast DDS profile gives the
    # receive buffer such a reply needs (docs/ros2.md).
    far_start, far_goal = (0.0, 0.0, 1.5 * math.pi), (-900.0, 900.0)
    long = call(client, request(far_start, far_goal, "B", 3)).plan
    check_plan(long, far_start, far_goal, 27)
    assert len(long.steps) > 400 and len(serialize_message(long)) > 100_000, len(long.steps)

    # Refusals, answered at once with the reason.
    for bad, words in ((request(rule_set="C"), "rule_set"), (request(evaluation=4), "evaluation"),
                       (request(goal=(math.nan, 10.0)), "goal.x"),
                       (request(start=(0.0, 1e5, 0.0)), "start.y"),
                       (request(goal=(-1000.5, 10.0)), "goal.x")):
        reply = call(client, bad).plan
        assert not reply.success and words in reply.reason and not reply.steps, reply.reason

    # Pre-emption: a search that cannot end soon (under Tab. 1's rearward reading A,(3) finds
    # no plan within 200 000 expansions, docs/experiments/gait-paper-table.md; here 1 000 000
    # are allowed, beyond the 5 s time limit) is pre-empted by the next request; its caller
    # gets "pre-empted", the newer one its plan.
    assert param_set(ros_node, "gait", "reading", "rearward").successful
    far = request(start, goal, "A", 3, 1_000_000)
    searching = gait.log_text().count("searching")
    slow = client.call_async(far)
    assert wait_until(lambda: gait.log_text().count("searching") > searching, REPLY_TIMEOUT)
    quick = client.call_async(request(start, goal))
    assert wait_until(lambda: slow.done() and quick.done(), REPLY_TIMEOUT), "no replies"
    assert slow.result().plan.reason == "pre-empted" and not slow.result().plan.success
    assert not slow.result().plan.steps
    check_plan(quick.result().plan, start, goal, 11)

    # Parameters: an unknown name and invalid values are refused with the reason.
    for name, value in (("no_such_parameter", 1.0), ("walk_evaluation", 4), ("walk_rule_set", "C"),
                        ("uneven_stability_margin", 1.5)):
        result = param_set(ros_node, "gait", name, value)
        assert not result.successful and result.reason, (name, result.reason)

    # The time limit ends a search with its best partial plan.
    assert param_set(ros_node, "gait", "time_limit_s", 0.2).successful
    began = time.monotonic()
    limited = call(client, far).plan
    assert time.monotonic() - began < 3.0
    assert not limited.success and limited.reason.startswith("TIME_LIMIT"), limited.reason
    assert limited.states_expanded > 0
    check_path_start(limited, start)
    assert param_set(ros_node, "gait", "reading", "forward").successful

    # UNEVEN ground: the next plans keep the larger margin and take the shorter step.
    even_margins = leg_move_margins(even)
    assert even_margins and min(even_margins) < UNEVEN_MARGIN, even_margins
    assert translate_lengths(even) and all(abs(d - 1.0) < 1e-9 for d in translate_lengths(even))
    pub = ros_node.create_publisher(TerrainAssessment, "terrain/assessment", qos_latched())
    pub.publish(TerrainAssessment(terrain_class=TerrainAssessment.UNEVEN))
    gait.wait_for_log(r"terrain: UNEVEN ground", timeout=REPLY_TIMEOUT)
    uneven = call(client, request(start, goal)).plan
    check_plan(uneven, start, goal, 11)
    margins = leg_move_margins(uneven)
    assert margins and min(margins) >= UNEVEN_MARGIN - 1e-9, margins
    steps = translate_lengths(uneven)
    assert steps and all(abs(d - UNEVEN_STEP) < 1e-9 for d in steps), steps


def test_goal_pose_walk_publishes_latched_plans_and_ends_at_the_goal(start_node, ros_node):
    start_node("gait_node", "-p", "walk_move_period_s:=0.01", params_file=PARAMS)
    goal = (2.0, 4.0)
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", make_qos("reliable", "volatile", 10))
    assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
    msg = PoseStamped()
    msg.header.frame_id = "odom"
    msg.pose.position.x, msg.pose.position.y = goal
    with subscribe(ros_node, PoseStamped, "gait/body", qos=make_qos("reliable", "volatile", 1000)) as body:
        # Sent until the walk starts (a volatile reader may miss the first while it matches).
        plans = None
        for _ in range(20):
            pub.publish(msg)
            try:
                body.wait_for(lambda b: b.pose.position.x != 0.0 or b.pose.position.y != 0.0, timeout=0.5)
                break
            except TimeoutError:
                continue
        # The plan is latched: a reader that joins now still gets the latest.
        with subscribe(ros_node, GaitPlan, "gait/plan", qos=qos_latched()) as plans:
            first = plans.wait_for(None, REPLY_TIMEOUT)
            # The plan is in [j]: its header names no frame.
            assert first.header.frame_id == "" and first.rule_set == "A" and len(first.steps) >= 2

        def arrived(b):
            return math.hypot(b.pose.position.x - goal[0], b.pose.position.y - goal[1]) <= GOAL_TOLERANCE + 1e-9

        end = body.wait_for(arrived, 20.0)
        assert end.header.frame_id == "odom"


def test_walk_markers_and_a_goal_in_another_frame_stops_the_walk(start_node, ros_node):
    period = 0.1
    gait = start_node("gait_node", "-p", f"walk_move_period_s:={period}", params_file=PARAMS)
    pub = ros_node.create_publisher(PoseStamped, "goal_pose", make_qos("reliable", "volatile", 10))
    assert wait_until(lambda: pub.get_subscription_count() > 0, timeout=10)
    msg = PoseStamped()
    msg.header.frame_id = "odom"
    msg.pose.position.x, msg.pose.position.y = 0.0, 40.0
    volatile = make_qos("reliable", "volatile", 1000)
    with subscribe(ros_node, PoseStamped, "gait/body", qos=volatile) as body, \
            subscribe(ros_node, MarkerArray, "gait/markers", qos=volatile) as markers:
        for _ in range(20):
            pub.publish(msg)
            try:
                body.wait_for(lambda b: b.pose.position.y != 0.0, timeout=0.5)
                break
            except TimeoutError:
                continue
        # While walking: a DELETEALL first, then the body outline (0), the feet (1), the path (3)
        # and the goal (4) at (0, 40) m; the support triangle (2) after a leg move.
        walking = markers.wait_for(lambda m: any(k.id == 3 for k in m.markers), REPLY_TIMEOUT)
        assert walking.markers[0].action == Marker.DELETEALL
        ids = [k.id for k in walking.markers[1:]]
        assert ids in ([0, 1, 3, 4], [0, 1, 2, 3, 4]), ids
        goal_marker = walking.markers[-1]
        assert (goal_marker.pose.position.x, goal_marker.pose.position.y) == (0.0, 40.0)
        # A goal in frame `map` (the node has no transforms) stops the walk where it is.
        wrong = PoseStamped()
        wrong.header.frame_id = "map"
        wrong.pose.position.x = 5.0
        pub.publish(wrong)
        gait.wait_for_log(r"goal_pose in frame `map`", timeout=REPLY_TIMEOUT)
        stopped = markers.wait_for(lambda m: [k.id for k in m.markers[1:]] == [0, 1], REPLY_TIMEOUT)
        assert stopped.markers[0].action == Marker.DELETEALL
        here = body.latest
        seen = len(body)
        time.sleep(2 * period + 0.05)  # two move periods: a walk still going would move
        after = body.snapshot()[seen:]
        assert all((b.pose.position.x, b.pose.position.y) == (here.pose.position.x, here.pose.position.y)
                   for b in after), after
        # The next walk's plan starts where the body stands (1 m per [j]).
        with subscribe(ros_node, GaitPlan, "gait/plan", qos=qos_latched()) as plans:
            msg.pose.position.x, msg.pose.position.y = here.pose.position.x + 3.0, here.pose.position.y
            pub.publish(msg)
            gait.wait_for_log(r"walking there.*\n(.*\n)*.*walking there", timeout=REPLY_TIMEOUT)
            plan = plans.wait_for(lambda p: p.steps and abs(p.steps[0].body.y - here.pose.position.y) < 1e-9,
                                  REPLY_TIMEOUT)
            first = plan.steps[0].body
            assert math.hypot(first.x - here.pose.position.x, first.y - here.pose.position.y) < 1e-9
