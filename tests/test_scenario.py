"""Closed-loop scenarios under the simulated clock, faster than real time.

sim_node publishes ``/clock`` and steps its physics at ``REAL_TIME_FACTOR`` simulated seconds per
wall second; chassis_node runs on ``use_sim_time``; the test commands by simulated time and
checks the ground truth against the kinematics worked out by hand. The factor actually reached
is measured from ``/clock`` as it arrives here and must be at least 2
(harness.MIN_REAL_TIME_FACTOR).

Commands: cmd_vel is published every 0.05 simulated seconds (what a node under the simulation
would do) and, in addition, at least every 0.1 wall seconds (harness.publish_on_sim_time).
chassis_node's cmd_vel and feedback watchdogs run on the steady clock by design (docs/ros2.md,
"Time"; docs/chassis_node.md): at 5× a 0.5 s timeout is 2.5 simulated seconds, and a command stream scheduled only in
simulated time leaves wall-clock gaps whenever the simulation or this process waits for the CPU.
With a message at least every 0.1 wall seconds the watchdog, five times longer, never fires
while the test drives; the repeats carry the same command, so they change nothing in the
kinematics checked. Feedback (joint_states) comes at 50 simulated Hz, i.e. every 4 wall ms.
sim_node's simulated motor drivers time out on the steady clock too (1 wall second without
wheel_commands, which chassis_node sends every 20 ms), so a stall of chassis_node on a busy
machine does not stop the robot mid-turn at any factor.
The feedback watchdog (no joint_states for 0.5 wall s) is the one this test cannot feed: with
builds running beside it (load average 9), /clock arrived here with gaps of up to 0.23 s and
once chassis_node went 0.5 s without feedback mid-turn and stopped the wheels, as designed. The
test gives it 2 s: a stalled machine is not what it checks. (feedback_timeout_s also bounds the
stamp gap the odometry integrates across, in simulated time: 0.02 s here.)

The factor: 5× is asked and sim_node holds it on the 2-core machine of docs/performance.md
(4.97–5.03× at a load average of 6); on one 2–3 times slower, with the other pytest worker busy,
it reached 3.3–4.0×. The assertion is ≥ 2× (harness.MIN_REAL_TIME_FACTOR says why): the
kinematics checked do not depend on the factor. sim_node itself reaches 10× here, but this
process then starts to miss odom samples (500 a second).
"""

from __future__ import annotations

import math

import pytest

from harness import MIN_REAL_TIME_FACTOR, make_qos, publish_on_sim_time, subscribe

from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

# Asked of sim_node; at least MIN_FACTOR must be reached (see the module docstring).
REAL_TIME_FACTOR = 5.0
MIN_FACTOR = MIN_REAL_TIME_FACTOR
COMMAND_PERIOD = 0.05  # simulated seconds between cmd_vel
SETTLE = 1.0  # simulated seconds: motor lag τ = 0.05 s leaves e^-20 of a step after 1 s
# The feedback watchdog's steady-clock timeout, 2 s instead of 0.5 s: see the module docstring.
FEEDBACK_TIMEOUT = ("-p", "feedback_timeout_s:=2.0")

# Command (vx, vy, ω) at base_link and its body-frame twist at steady state, by hand:
# omr3: an omni chassis follows all three: (0.2, 0.1, 0.3).
# mobil2: v = 0.3, ω = 0.2 (radius 1.5 m ≥ 0.73 m: feasible). The car drops no speed; its rear
#   axle runs at 0.3 on R = 1.5 m, and base_link, d = 0.30 m ahead of the axle, moves sideways
#   at ω·d = 0.06 m/s in its own frame: body twist (0.3, 0.06, 0.2).
COMMANDS = {"omr3": (0.2, 0.1, 0.3), "mobil2": (0.3, 0.0, 0.2)}
BODY_TWIST = {"omr3": (0.2, 0.1, 0.3), "mobil2": (0.3, 0.06, 0.2)}
# Half a turn (ω·T = π) takes T = π/0.3 = 10.472 s (omr3) and π/0.2 = 15.708 s (mobil2). A
# constant body twist (vx, vy) rotating at ω moves the body, in its starting frame, by
# ((vx·sin φ − vy·(1 − cos φ))/ω, (vx·(1 − cos φ) + vy·sin φ)/ω) after φ = ω·t; at φ = π that
# is (−2·vy/ω, 2·vx/ω): omr3 (−0.2/0.3, 0.4/0.3) = (−0.666667, 1.333333), mobil2
# (−0.12/0.2, 0.6/0.2) = (−0.6, 3.0), a diameter of 2·sqrt(0.2² + 0.1²)/0.3 = 1.490712 m and
# 2·sqrt(1.5² + 0.3²) = 3.059412 m: the circles of test_chassis.RADIUS.
HALF_TURN = {"omr3": (-0.666667, 1.333333), "mobil2": (-0.6, 3.0)}


def twist(vx: float, vy: float, wz: float) -> Twist:
    t = Twist()
    t.linear.x, t.linear.y, t.angular.z = float(vx), float(vy), float(wz)
    return t


def seconds(msg) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


def pose(msg: Odometry) -> tuple[float, float, float]:
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    return p.x, p.y, math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


def arc_displacement(body_twist: tuple[float, float, float], t: float) -> tuple[float, float]:
    """Displacement after ``t`` s of a constant body twist, in the body's starting frame."""
    vx, vy, w = body_twist
    phi = w * t
    return ((vx * math.sin(phi) - vy * (1 - math.cos(phi))) / w,
            (vx * (1 - math.cos(phi)) + vy * math.sin(phi)) / w)


def displacement_in_start_frame(start: Odometry, end: Odometry) -> tuple[float, float, float]:
    (x0, y0, th0), (x1, y1, th1) = pose(start), pose(end)
    dx, dy = x1 - x0, y1 - y0
    c, s = math.cos(th0), math.sin(th0)
    return c * dx + s * dy, -s * dx + c * dy, math.remainder(th1 - th0, math.tau)


@pytest.mark.parametrize("robot", ["omr3", "mobil2"])
def test_half_turn_faster_than_real_time(robot, start_scenario, sim_clock, ros_node, tmp_path):
    """Half a circle driven by cmd_vel on simulated time: the ground truth ends where the
    kinematics say (HALF_TURN, by hand) after the simulated time it takes, odometry agrees, every
    odom stamp is simulated time, and the simulation ran at least harness.MIN_REAL_TIME_FACTOR
    times real time."""
    # An empty world: the built-in one has a pillar on these circles.
    world = tmp_path / "empty.yaml"
    world.write_text("obstacles: []\n")
    start_scenario(f"params/{robot}.yaml", real_time_factor=REAL_TIME_FACTOR,
                   sim_args=("-p", f"world_file:={world}"), node_args=FEEDBACK_TIMEOUT)
    vx, vy, wz = COMMANDS[robot]
    body = BODY_TWIST[robot]
    half_turn = math.pi / wz
    # The hand figures and the general formula the window is checked with agree.
    assert arc_displacement(body, half_turn) == pytest.approx(HALF_TURN[robot], abs=1e-6)

    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    # A deep reader history (1 wall second at 5×), so that only the writers' own depth of 10 (40
    # wall ms) can lose a sample, when this process stalls longer than that.
    deep = make_qos("reliable", "volatile", 250)
    with subscribe(ros_node, Odometry, "odom", qos=deep) as odom, \
            subscribe(ros_node, Odometry, "ground_truth", qos=deep) as truth:
        sim_clock.wait_started(timeout=10)
        # chassis_node publishes odom once it has feedback; the first commands may be lost while
        # discovery completes, so the settling phase starts when the robot demonstrably turns.
        odom.wait_for(None, timeout=10)
        publish_on_sim_time(cmd, twist(vx, vy, wz), sim_clock, until=math.inf,
                            period=COMMAND_PERIOD, timeout=15,
                            done=lambda: truth.latest is not None
                            and truth.latest.twist.twist.angular.z > 0.5 * wz)
        t_go = sim_clock.now()
        publish_on_sim_time(cmd, twist(vx, vy, wz), sim_clock, until=t_go + SETTLE,
                            period=COMMAND_PERIOD, timeout=15)
        mark = sim_clock.mark()
        t_start = mark[0]
        publish_on_sim_time(cmd, twist(vx, vy, wz), sim_clock, until=t_start + half_turn + 0.2,
                            period=COMMAND_PERIOD, timeout=20)
        factor = sim_clock.factor(since=mark)
        cmd.publish(twist(0.0, 0.0, 0.0))
        truth.wait_for(lambda m: seconds(m) >= t_start + half_turn + 0.1, timeout=5)
        odom.wait_for(lambda m: seconds(m) >= t_start + half_turn + 0.1, timeout=5)
        truths, odoms = truth.snapshot(), odom.snapshot()
        now = sim_clock.now()

    print(f"{robot}: simulated {now - t_start:.2f} s at {factor:.2f}× real time; longest "
          f"/clock gap {sim_clock.max_gap * 1000:.0f} wall ms")
    assert factor >= MIN_FACTOR, f"{factor:.2f}× real time, asked {REAL_TIME_FACTOR}×"

    # Odometry stamps are simulated time: the feedback's stamps, republished unchanged, which
    # sim_node takes from its clock, which starts at 0: the first after the first physics step
    # (1/200 s), then every 1/50 s (joint_states_rate_hz). So each is 0.005 s or a multiple of
    # 0.02 s, none is ahead of the clock (by more than the /clock message still on its way,
    # 0.1 s), and none is an epoch time (1.7e9 s).
    assert len(odoms) > 100
    assert all(seconds(m) <= now + 0.1 for m in odoms)
    off_grid = [t for t in map(seconds, odoms) if abs(t / 0.02 - round(t / 0.02)) > 1e-4 and abs(t - 0.005) > 1e-6]
    assert not off_grid, f"odom stamps off the 50 Hz grid of simulated time: {off_grid[:5]}"
    assert seconds(odoms[-1]) < 600.0

    # The window: from the first settled instant to the one nearest half a turn later, at
    # instants with both a truth and an odom sample (the odometry republishes the feedback's
    # stamps; this process may miss a sample now and then when the machine is loaded).
    odom_at = {round(seconds(m), 6): m for m in odoms}
    both = [m for m in truths if round(seconds(m), 6) in odom_at]
    start = next(m for m in both if seconds(m) >= t_start)
    end = min(both, key=lambda m: abs(seconds(m) - (seconds(start) + half_turn)))
    dt = seconds(end) - seconds(start)
    # The robot kept the command all along: a wheel stopped by a watchdog or by the simulated
    # drivers' timeout would show here first (and then as a shorter arc).
    window = [m for m in truths if seconds(start) <= seconds(m) <= seconds(end)]
    turn_rates = [m.twist.twist.angular.z for m in window]
    assert min(turn_rates) == pytest.approx(wz, abs=1e-4) and max(turn_rates) == pytest.approx(wz, abs=1e-4)
    # Near half a turn, so that HALF_TURN is what is checked (a sample missed here, when this
    # process is short of CPU, moves the end by 0.02 s; the formula takes the actual dt).
    assert dt == pytest.approx(half_turn, abs=0.3)
    ex, ey = arc_displacement(body, dt)
    gx, gy, gth = displacement_in_start_frame(start, end)
    assert (gx, gy) == pytest.approx((ex, ey), abs=2e-3)
    assert gth == pytest.approx(wz * dt - math.tau * round(wz * dt / math.tau), abs=1e-3)

    # The odometry over the same instants (noise-free encoders) agrees with the same figures.
    o_start, o_end = odom_at[round(seconds(start), 6)], odom_at[round(seconds(end), 6)]
    ox, oy, oth = displacement_in_start_frame(o_start, o_end)
    assert (ox, oy) == pytest.approx((ex, ey), abs=3e-3)
    assert oth == pytest.approx(gth, abs=1e-3)
