"""Fuzz test of chassis_node and sim_node through real rclpy (ROS 2 Jazzy, Fast DDS).

Seeded (``MOBIL_FUZZ_SEED``, printed in every failure), thousands of malformed, non-finite,
huge, duplicated and out-of-order messages on ``cmd_vel``, ``joint_states`` and
``wheel_commands`` (as messages and as raw CDR buffers), parameter sets that must be refused,
and garbage world files. Checked throughout, not only at the end:

* every number in every ``odom``, ``wheel_commands``, ``ground_truth``, ``chassis/status`` and
  the sim's ``joint_states`` is finite, wheel speeds and steering angles stay within the robot's
  limits, and the status's count of rejected messages never decreases;
* after every bad ``cmd_vel`` the wheels are commanded to zero, and stay there until a good one;
* a refused parameter set leaves the old value (``get_parameters`` shows it);
* the node processes never exit and never panic; at the end both still answer a parameter get
  and a good command still moves the wheels (so no test can pass on a dead node).

Each test gathers every violation with the case that caused it and fails once, listing them.
The Rust side of the world-file fuzzing (thousands of texts against the loader) is
nodes/sim/tests/world_fuzz.rs; here a handful of files are given to a real sim_node.
"""

from __future__ import annotations

import math
import random
import time
from pathlib import Path
from typing import Any, Optional

import harness
from fuzzing import (INF, NAN, PER_CALL_TIMEOUT, SEED, WRONG_TYPES, Fuzz, answers_parameter_get, mutate,
                     number, rng_for, same_type)
from harness import publish_until, subscribe
from rosutil import message_to_dict

from geometry_msgs.msg import Twist
from mobil_msgs.msg import ChassisStatus
from nav_msgs.msg import Odometry
from rclpy._rclpy_pybind11 import RCLError
from rclpy.serialization import serialize_message
from sensor_msgs.msg import JointState

MOBIL2_JOINTS = ["front_left_steering", "front_right_steering", "rear_left_wheel", "rear_right_wheel"]
OMNI_JOINTS = ["wheel_1", "wheel_2", "wheel_3"]
# params/mobil2.yaml and params/omr3.yaml: wheel speed limits, and the largest angle of a physical
# steering wheel: max_steering (70°) is the virtual centre wheel's, and the inner Ackermann wheel
# steers to atan(L / (L / tan 70° − B/2)); L / tan 70° = 0.218 m < B/2 = 0.31 m puts it at 90°.
LIMITS = {"mobil2": (7.5, math.pi / 2), "omr3": (12.0, 0.0)}
NO_LIDAR = ("-p", "lidar.enabled:=false")
def twist(vx: float = 0.0, vy: float = 0.0, wz: float = 0.0) -> Twist:
    t = Twist()
    t.linear.x, t.linear.y, t.angular.z = float(vx), float(vy), float(wz)
    return t


def joint_state(sec: int, nanosec: int, names, positions, velocities) -> JointState:
    js = JointState()
    js.header.stamp.sec, js.header.stamp.nanosec = int(sec), int(nanosec)
    js.name = list(names)
    js.position = [float(p) for p in positions]
    js.velocity = [float(v) for v in velocities]
    return js


def at(t: float, names, positions, velocities) -> JointState:
    sec = math.floor(t)
    return joint_state(sec, min(999_999_999, round((t - sec) * 1e9)), names, positions, velocities)


def empty_world(tmp_path: Path) -> str:
    path = tmp_path / "empty_world.yaml"
    path.write_text("obstacles: []\n")
    return str(path)


def stamp_s(msg: Any) -> float:
    return msg.header.stamp.sec + msg.header.stamp.nanosec * 1e-9


# How soon after a bad command the wheels must be commanded to zero (s): the node stops them on
# receipt (or the next 20 ms tick); the rest is rclpy → node → rclpy DDS latency and scheduling on
# a loaded 2-core machine, which over 128 chances a run must not flake.
REACTION = 0.4


def status_after(status: Any, t: float) -> ChassisStatus:
    """The first chassis status published after the time ``t`` (the host's clock)."""
    # The wait is long for a loaded machine (the check on the reaction is on the stamps).
    return status.wait_for(lambda st: stamp_s(st) > t, timeout=5.0, start=max(0, len(status) - 5))


def settled(node: Any, cmd: Any, status: Any, vx: float) -> Optional[ChassisStatus]:
    """Send the feasible command ``vx`` (well inside every limit, so commanded unchanged) until a
    status shows it: by then the chassis has processed every earlier cmd_vel (DDS keeps order).
    Returns that status, or None after 3 s."""
    def shown() -> bool:
        latest = status.latest
        return latest is not None and latest.commanded.linear.x == vx and latest.commanded.angular.z == 0.0
    try:
        publish_until(node, cmd, twist(vx), shown, rate_hz=20, timeout=3)
    except TimeoutError:
        return None
    return status.latest


def zero(msg: JointState) -> bool:
    return all(v == 0.0 for v in msg.velocity)


def nonzero(msg: JointState) -> bool:
    return any(abs(v) > 1e-6 for v in msg.velocity)


# ------------------------------------------------------------------------------------------------
# cmd_vel
# ------------------------------------------------------------------------------------------------

def fuzz_twist(rng: random.Random) -> tuple[Twist, bool]:
    """A twist with specials in any of its six numbers; bad if one the chassis uses (linear x,
    y, angular z) is not finite."""
    values = [number(rng, -0.6, 0.6, special=0.3) for _ in range(6)]
    t = Twist()
    t.linear.x, t.linear.y, t.linear.z, t.angular.x, t.angular.y, t.angular.z = values
    return t, not all(math.isfinite(v) for v in (values[0], values[1], values[5]))


def bad_twist(rng: random.Random) -> Twist:
    while True:
        t, bad = fuzz_twist(rng)
        if bad:
            return t


def good_twist(rng: random.Random) -> Twist:
    """Forward or backward at 0.1…0.4 m/s on a gentle curve: every wheel of MOBIL-II turns."""
    return twist(rng.choice([-1, 1]) * rng.uniform(0.1, 0.4), 0.0, rng.uniform(-0.3, 0.3))


def test_fuzz_cmd_vel_every_bad_command_stops_the_wheels(start_node, ros_node, tmp_path):
    """MOBIL-II (chassis_node fed by sim_node): good/bad pairs checked one by one, then bursts
    of hundreds of random twists (specials in all six numbers, duplicates)."""
    rng = rng_for("cmd_vel")
    fuzz = Fuzz("cmd_vel")
    world = empty_world(tmp_path)
    sim = start_node("sim_node", *NO_LIDAR, "-p", f"world_file:={world}", params_file="params/mobil2.yaml")
    # The cmd_vel watchdog far off, so that only the bad command can have stopped the wheels.
    chassis = start_node("chassis_node", "-p", "cmd_vel_timeout_s:=5.0", params_file="params/mobil2.yaml")
    answers_parameter_get(fuzz, ros_node, "/chassis", "v_max", 0.5)
    answers_parameter_get(fuzz, ros_node, "/sim", "wheel_radius", 0.1)
    fuzz.watch(ros_node, JointState, "wheel_commands", fuzz.wheel_limits(LIMITS["mobil2"]))
    fuzz.watch(ros_node, Odometry, "odom")
    fuzz.watch(ros_node, Odometry, "ground_truth")
    fuzz.watch(ros_node, ChassisStatus, "chassis/status", fuzz.status_checks())
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, JointState, "wheel_commands", qos=harness.make_qos(depth=1000)) as wheels, \
            subscribe(ros_node, ChassisStatus, "chassis/status", qos=harness.qos_latched()) as status:
        fuzz.case = "first good command"
        publish_until(ros_node, cmd, twist(0.2), lambda: wheels.latest is not None and nonzero(wheels.latest),
                      rate_hz=20, timeout=15)
        # One by one: a good command (the wheels turn), then a bad one, sent 1–3 times.
        pairs = 120
        for i in range(pairs):
            fuzz.case = f"pair {i}"
            start = len(wheels)
            cmd.publish(good_twist(rng))
            try:
                wheels.wait_for(nonzero, timeout=2.0, start=start)
            except TimeoutError:
                fuzz.fail("a good command did not turn the wheels within 2 s")
                if fuzz.repeated(3):
                    break
                continue
            bad = bad_twist(rng)
            fuzz.case = f"pair {i}: bad {message_to_dict(bad)}"
            start = len(wheels)
            sent_at = time.time()
            for _ in range(rng.randint(1, 3)):
                cmd.publish(bad)
                fuzz.count("bad cmd_vel")
            fuzz.count("good cmd_vel")
            try:
                # Long for a loaded machine: the reaction is checked on the stamps below.
                stopped = wheels.wait_for(zero, timeout=3.0, start=start)
            except TimeoutError:
                fuzz.fail("the wheels were not stopped within 3 s")
                if fuzz.repeated(3):
                    break
                continue
            # wheel_commands are stamped when published (same host clock): those published before
            # the bad command arrived, and still in flight, may show the old command; every one
            # published from REACTION after it on must be zero.
            time.sleep(0.03)
            fuzz.check(stamp_s(stopped) - sent_at < REACTION,
                       f"the first zero was published {stamp_s(stopped) - sent_at:.3f} s after the bad command")
            late = [(round(stamp_s(m) - sent_at, 3), list(m.velocity)) for m in wheels.snapshot()[start:]
                    if stamp_s(m) > sent_at + REACTION and not zero(m)]
            fuzz.check(not late, f"non-zero wheel_commands (s after the bad command, speeds): {late[:2]}")
        # Bursts: hundreds of random twists as fast as rclpy publishes them, some duplicated.
        # Each is framed by a distinct good command that the status must show as commanded, so
        # the chassis has worked through everything before it; then one bad command must stop
        # the wheels and count exactly one rejection.
        bursts, burst_size = 8, 300
        for b in range(bursts):
            fuzz.case = f"burst {b}"
            before = settled(ros_node, cmd, status, 0.11 + 0.01 * b)
            bad_count = 0
            for _ in range(burst_size):
                t, bad = fuzz_twist(rng)
                for _ in range(rng.choice([1, 1, 1, 2, 5])):
                    cmd.publish(t)
                    bad_count += bad
                    fuzz.count("burst cmd_vel")
            after = settled(ros_node, cmd, status, 0.31 + 0.01 * b)
            if before is None or after is None:
                fuzz.fail("the chassis never showed the good command after the burst")
                if fuzz.repeated(2):
                    break
                continue
            # Keep-last queues may drop part of a burst, never count more than was sent.
            fuzz.check(before.rejected_messages < after.rejected_messages <= before.rejected_messages + bad_count,
                       f"rejected_messages {before.rejected_messages} → {after.rejected_messages} "
                       f"for {bad_count} bad")
            fuzz.case = f"burst {b}: bad command after it"
            start, sent_at = len(wheels), time.time()
            cmd.publish(bad_twist(rng))
            try:
                stopped = wheels.wait_for(zero, timeout=3.0, start=start)
                time.sleep(0.03)
                fuzz.check(stamp_s(stopped) - sent_at < REACTION, "the wheels were stopped late")
                late = [m for m in wheels.snapshot()[start:] if stamp_s(m) > sent_at + REACTION and not zero(m)]
                fuzz.check(not late, f"non-zero wheel_commands after the bad command: {len(late)}")
                st = status_after(status, sent_at + REACTION)
                fuzz.check(st.rejected_messages == after.rejected_messages + 1,
                           f"rejected_messages {after.rejected_messages} → {st.rejected_messages} for one bad")
            except TimeoutError as exc:
                fuzz.fail(f"no zero wheel command or status after the bad command: {exc}")
        # Still alive: a good command still turns the wheels.
        fuzz.case = "final good command"
        try:
            publish_until(ros_node, cmd, twist(0.3), lambda: wheels.latest is not None
                          and nonzero(wheels.latest), rate_hz=20, timeout=5)
        except TimeoutError as exc:
            fuzz.fail(f"a good cmd_vel no longer turns the wheels: {exc}")
        cmd.publish(twist())
    answers_parameter_get(fuzz, ros_node, "/chassis", "v_max", 0.5)
    answers_parameter_get(fuzz, ros_node, "/sim", "wheel_radius", 0.1)
    # Commands came every few milliseconds throughout: the 5 s cmd_vel watchdog never had cause
    # to report silence (a bad command is not a missing one).
    fuzz.case = "end"
    silence = [line for line in chassis.log_text().splitlines() if "no cmd_vel for" in line]
    fuzz.check(not silence, f"the chassis reported {len(silence)} times that no cmd_vel came for 5 s: {silence[:1]}")
    fuzz.finish(chassis, sim)


# ------------------------------------------------------------------------------------------------
# joint_states
# ------------------------------------------------------------------------------------------------

def random_name(rng: random.Random) -> str:
    return rng.choice(["", "wheel", "wheel_4", "WHEEL_1", "wheel_1 ", "ü", "x" * rng.choice([1, 300, 1000]),
                       "steering", "rear_left_wheel"])


def fuzz_joint_state(rng: random.Random, t: float, last: tuple[int, int], names: list[str]) -> JointState:
    """Any of: specials in the values, mismatched or empty arrays, unknown, duplicated or missing
    joints; with a stamp that may be zero, in the past, far ahead, backwards, repeated or invalid."""
    n = len(names)
    kind = rng.randrange(8)
    if kind == 0:    # mismatched lengths
        js_names = rng.sample(names, rng.randint(0, n))
        pos = [number(rng) for _ in range(rng.randint(0, n + 2))]
        vel = [number(rng) for _ in range(rng.randint(0, n + 2))]
    elif kind == 1:  # empty
        js_names, pos, vel = [], [], []
    elif kind == 2:  # unknown names only
        js_names = [random_name(rng) for _ in range(n)]
        pos, vel = [], [number(rng) for _ in range(n)]
    elif kind == 3:  # a duplicated joint
        js_names = names + [rng.choice(names)]
        rng.shuffle(js_names)
        pos, vel = [], [number(rng) for _ in range(n + 1)]
    elif kind == 4:  # a missing joint
        js_names = rng.sample(names, n - 1)
        pos, vel = [], [number(rng) for _ in range(n - 1)]
    elif kind == 5:  # positions only, with specials
        js_names, pos, vel = list(names), [number(rng, -100, 100) for _ in range(n)], []
    else:            # the right joints (plus an unknown one sometimes) with specials
        js_names = list(names) + (["caster"] if rng.random() < 0.3 else [])
        pos, vel = [], [number(rng, -5, 5) for _ in js_names]
    sec, nanosec = math.floor(t), round((t - math.floor(t)) * 1e9) % 1_000_000_000
    stamp = rng.randrange(10)
    if stamp == 0:
        sec, nanosec = 0, 0
    elif stamp == 1:
        sec -= rng.choice([1, 100, 10_000])
    elif stamp == 2:
        sec = rng.choice([sec + 1_000_000, 2**31 - 1])
    elif stamp == 3:
        sec, nanosec = last
    elif stamp == 4:
        nanosec = rng.choice([1_000_000_000, 2**32 - 1])
    elif stamp == 5:
        sec = rng.choice([-1, -(2**31)])
    return joint_state(sec, nanosec, js_names, pos, vel)


def test_fuzz_joint_states_never_poison_the_odometry(start_node, ros_node):
    """OMR-III chassis_node with rclpy playing the robot: thousands of broken feedback samples
    mixed with good ones, then 1 s of good motion must give exactly the commanded twist."""
    rng = rng_for("joint_states")
    fuzz = Fuzz("joint_states")
    chassis = start_node("chassis_node", params_file="params/omr3.yaml")
    answers_parameter_get(fuzz, ros_node, "/chassis", "model", "omni")
    fuzz.watch(ros_node, Odometry, "odom")
    fuzz.watch(ros_node, JointState, "wheel_commands", fuzz.wheel_limits(LIMITS["omr3"]))
    fuzz.watch(ros_node, ChassisStatus, "chassis/status", fuzz.status_checks())
    fb = ros_node.create_publisher(JointState, "joint_states", 10)
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    with subscribe(ros_node, Odometry, "odom", qos=harness.make_qos(depth=1000)) as odom, \
            subscribe(ros_node, JointState, "wheel_commands", qos=harness.make_qos(depth=1000)) as wheels, \
            subscribe(ros_node, ChassisStatus, "chassis/status", qos=harness.qos_latched()) as status:
        fuzz.case = "first feedback"
        stamps = iter(1000.0 + 0.01 * k for k in range(1000))
        publish_until(ros_node, fb, lambda: at(next(stamps), OMNI_JOINTS, [], [0.0] * 3),
                      lambda: odom.latest is not None, rate_hz=10, timeout=10)
        t, last = 1010.0, (1010, 0)
        sent = 0
        for b in range(12):
            fuzz.case = f"block {b}"
            for _ in range(rng.choice([50, 100, 300])):
                t += 0.01
                if rng.random() < 0.3:
                    js = at(t, OMNI_JOINTS, [], [rng.uniform(-3, 3) for _ in OMNI_JOINTS])
                else:
                    js = fuzz_joint_state(rng, t, last, OMNI_JOINTS)
                last = (js.header.stamp.sec, js.header.stamp.nanosec)
                for _ in range(rng.choice([1, 1, 1, 2])):
                    fb.publish(js)
                    sent += 1
            # A breath between blocks, so the chassis's keep-last queue drains.
            time.sleep(0.02)
        fuzz.count("joint_states sent", sent)
        # Only broken feedback for longer than feedback_timeout_s (0.5 s): the odometry is
        # stale, so good commands must not turn the wheels, neither on the control tick nor in
        # the immediate answer to each cmd_vel.
        fuzz.case = "good cmd_vel on broken feedback"
        try:
            status.wait_for(lambda st: st.feedback_stale, timeout=3, start=len(status))
            start = len(wheels)
            for i in range(60):
                t += 0.01
                cmd.publish(good_twist(rng))
                fb.publish(at(t, OMNI_JOINTS, [], [NAN, 1.0, 1.0]))
                time.sleep(0.01)
            time.sleep(0.05)
            turning = [list(m.velocity) for m in wheels.snapshot()[start:] if nonzero(m)]
            fuzz.check(not turning, f"{len(turning)} of {len(wheels) - start} wheel_commands turn the wheels "
                       f"on stale feedback, e.g. {turning[:1]}")
            fuzz.count("cmd_vel on stale feedback", 60)
        except TimeoutError as exc:
            fuzz.fail(f"status never reported the feedback stale: {exc}")
        cmd.publish(twist())
        # Good motion from rest: Ω = [6, −3, −3] rad/s with r = 0.05 is body-x 0.3 m/s
        # (v = r·(2/3)·(Ω1 − Ω2/2 − Ω3/2) = 0.05·(2/3)·9).
        fuzz.case = "good motion after the fuzz"
        t0 = 50_000.0
        rest = iter(t0 - 1.0 + 0.01 * k for k in range(100))
        try:
            publish_until(ros_node, fb, lambda: at(next(rest), OMNI_JOINTS, [], [0.0] * 3),
                          lambda: odom.latest is not None and odom.latest.header.stamp.sec >= t0 - 1,
                          rate_hz=20, timeout=5)
            for i in range(1, 11):
                fb.publish(at(t0 + 0.1 * i, OMNI_JOINTS, [], [6.0, -3.0, -3.0]))
            last_odom = odom.wait_for(lambda m: m.header.stamp.sec == t0 + 1 and m.header.stamp.nanosec == 0,
                                      timeout=5)
            tw = last_odom.twist.twist
            fuzz.check(abs(tw.linear.x - 0.3) < 1e-6 and abs(tw.linear.y) < 1e-6 and abs(tw.angular.z) < 1e-6,
                       f"odometry twist {message_to_dict(tw)} after the fuzz, expected (0.3, 0, 0)")
        except TimeoutError as exc:
            fuzz.fail(f"good feedback no longer gives odometry: {exc}")
    answers_parameter_get(fuzz, ros_node, "/chassis", "model", "omni")
    fuzz.finish(chassis)


# ------------------------------------------------------------------------------------------------
# wheel_commands
# ------------------------------------------------------------------------------------------------

def test_fuzz_wheel_commands_keep_the_simulation_finite(start_node, ros_node, tmp_path):
    """sim_node (MOBIL-II, empty world) under broken wheel commands: its ground truth and wheel
    feedback stay finite, and a good command afterwards drives it at the commanded speed."""
    rng = rng_for("wheel_commands")
    fuzz = Fuzz("wheel_commands")
    sim = start_node("sim_node", *NO_LIDAR, "-p", f"world_file:={empty_world(tmp_path)}",
                     params_file="params/mobil2.yaml")
    answers_parameter_get(fuzz, ros_node, "/sim", "model", "car_like")
    fuzz.watch(ros_node, Odometry, "ground_truth")
    fuzz.watch(ros_node, JointState, "joint_states")
    pub = ros_node.create_publisher(JointState, "wheel_commands", 10)
    with subscribe(ros_node, Odometry, "ground_truth", qos=harness.make_qos(depth=1000)) as truth, \
            subscribe(ros_node, JointState, "joint_states", qos=harness.make_qos(depth=1000)) as feedback:
        truth.wait_for(None, timeout=10)
        # The sim hears this publisher: it steers the front wheels to 0.1 rad when asked.
        fuzz.case = "first command"
        publish_until(ros_node, pub, at(50.0, MOBIL2_JOINTS, [0.1, 0.1, 0.0, 0.0], [0.0] * 4),
                      lambda: feedback.latest is not None and abs(feedback.latest.position[0] - 0.1) < 1e-3,
                      rate_hz=20, timeout=10)
        sent, t = 0, 100.0
        for b in range(10):
            fuzz.case = f"block {b}"
            for _ in range(rng.choice([50, 100, 300])):
                t += 0.01
                if rng.random() < 0.5:
                    # The right joints: steering angles and wheel speeds with specials.
                    js = at(t, MOBIL2_JOINTS, [number(rng, -1.5, 1.5) for _ in range(4)],
                            [number(rng, -3, 3) for _ in range(4)])
                else:
                    js = fuzz_joint_state(rng, t, (int(t), 0), MOBIL2_JOINTS)
                for _ in range(rng.choice([1, 1, 2])):
                    pub.publish(js)
                    sent += 1
            time.sleep(0.02)
        fuzz.count("wheel_commands sent", sent)
        # Straight ahead: rear wheels at 3 rad/s with r = 0.10 m is 0.3 m/s.
        fuzz.case = "good command after the fuzz"
        good = at(200.0, MOBIL2_JOINTS, [0.0, 0.0, 0.0, 0.0], [0.0, 0.0, 3.0, 3.0])
        try:
            publish_until(ros_node, pub, good, lambda: truth.latest is not None
                          and abs(truth.latest.twist.twist.linear.x - 0.3) < 1e-3
                          and abs(truth.latest.twist.twist.angular.z) < 1e-3, rate_hz=20, timeout=5)
        except TimeoutError as exc:
            fuzz.fail(f"a good wheel command no longer drives the simulated robot: {exc}")
        pub.publish(at(201.0, MOBIL2_JOINTS, [0.0] * 4, [0.0] * 4))
    answers_parameter_get(fuzz, ros_node, "/sim", "model", "car_like")
    fuzz.finish(sim)


# ------------------------------------------------------------------------------------------------
# Raw CDR buffers
# ------------------------------------------------------------------------------------------------

def test_fuzz_raw_cdr_buffers_are_refused_safely(start_node, ros_node, tmp_path):
    """Truncated, over-long and random CDR buffers on cmd_vel and joint_states (chassis_node,
    OMR-III) and on wheel_commands (sim_node, in its own namespace so that this test's
    subscription to the chassis's wheel_commands never sees the junk)."""
    rng = rng_for("raw")
    fuzz = Fuzz("raw CDR")
    sim = start_node("sim_node", *NO_LIDAR, "-r", "__ns:=/fuzzsim", "-p", f"world_file:={empty_world(tmp_path)}",
                     params_file="params/omr3.yaml")
    chassis = start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", "-p", "cmd_vel_timeout_s:=5.0",
                         params_file="params/omr3.yaml")
    answers_parameter_get(fuzz, ros_node, "/chassis", "model", "omni")
    answers_parameter_get(fuzz, ros_node, "/fuzzsim/sim", "model", "omni")
    fuzz.watch(ros_node, JointState, "/wheel_commands", fuzz.wheel_limits(LIMITS["omr3"]))
    fuzz.watch(ros_node, Odometry, "/odom")
    fuzz.watch(ros_node, ChassisStatus, "/chassis/status", fuzz.status_checks())
    fuzz.watch(ros_node, Odometry, "/fuzzsim/ground_truth")
    fuzz.watch(ros_node, JointState, "/fuzzsim/joint_states")
    cmd = ros_node.create_publisher(Twist, "/cmd_vel", 10)
    fb = ros_node.create_publisher(JointState, "/joint_states", 10)
    sim_cmd = ros_node.create_publisher(JointState, "/fuzzsim/wheel_commands", 10)
    good_cmd = serialize_message(twist(0.2, 0.1, 0.3))
    good_js = serialize_message(at(77.5, OMNI_JOINTS, [1.0, 2.0, 3.0], [0.5, 0.5, 0.5]))
    with subscribe(ros_node, JointState, "/wheel_commands", qos=harness.make_qos(depth=1000)) as wheels, \
            subscribe(ros_node, Odometry, "/fuzzsim/ground_truth", qos=harness.make_qos(depth=100)) as truth:
        fuzz.case = "first good command"
        publish_until(ros_node, cmd, twist(0.2), lambda: wheels.latest is not None and nonzero(wheels.latest),
                      rate_hz=20, timeout=15)
        # Both other publishers are heard: the chassis answers feedback with odometry, the sim
        # turns its wheels on a command (OMR-III turning in place at Ω = 1 rad/s each).
        stamps = iter(70.0 + 0.01 * k for k in range(1000))
        with subscribe(ros_node, Odometry, "/odom", qos=harness.make_qos(depth=100)) as odom, \
                subscribe(ros_node, JointState, "/fuzzsim/joint_states", qos=harness.make_qos(depth=100)) as sim_fb:
            publish_until(ros_node, fb, lambda: at(next(stamps), OMNI_JOINTS, [], [0.0] * 3),
                          lambda: odom.latest is not None, rate_hz=20, timeout=10)
            publish_until(ros_node, sim_cmd, at(1.0, OMNI_JOINTS, [], [1.0] * 3),
                          lambda: sim_fb.latest is not None and sim_fb.latest.velocity[0] > 0.5, rate_hz=20, timeout=10)
        truth.wait_for(None, timeout=10)
        # One by one: a good command, then a cmd_vel cut short (a Twist is 4 + 48 bytes): it
        # cannot be decoded, so the chassis must stop the wheels as for any bad command.
        for i in range(40):
            fuzz.case = f"truncated cmd_vel {i}"
            start = len(wheels)
            cmd.publish(good_twist(rng))
            try:
                wheels.wait_for(nonzero, timeout=2.0, start=start)
            except TimeoutError:
                fuzz.fail("a good command did not turn the wheels within 2 s")
                if fuzz.repeated(3):
                    break
                continue
            start = len(wheels)
            cmd.publish(good_cmd[:rng.randrange(8, len(good_cmd))])
            fuzz.count("truncated cmd_vel")
            try:
                wheels.wait_for(zero, timeout=1.0, start=start)
            except TimeoutError:
                fuzz.fail("an undecodable cmd_vel did not stop the wheels within 1 s")
                if fuzz.repeated(3):
                    break
        fuzz.case = "random buffers"
        kinds: dict[str, int] = {}
        for b in range(10):
            for _ in range(100):
                for pub, valid, topic in ((cmd, good_cmd, "cmd_vel"), (fb, good_js, "joint_states"),
                                          (sim_cmd, good_js, "wheel_commands")):
                    buf, kind = mutate(rng, valid)
                    fuzz.case = f"block {b}: {kind} {topic} {buf[:64].hex()}"
                    try:
                        pub.publish(buf)
                    except RCLError:
                        # Fast DDS itself refuses some buffers (e.g. shorter than the 4-byte
                        # encapsulation header): nothing was sent.
                        fuzz.count(f"raw {topic} {kind} refused by rclpy")
                        continue
                    kinds[kind] = kinds.get(kind, 0) + 1
                    fuzz.count(f"raw {topic}")
            time.sleep(0.02)
        print(f"raw buffers by kind: {kinds}")
        fuzz.case = "good commands after the fuzz"
        try:
            # OMR-III, body (0.2, 0, 0) with r = 0.05: Ω = (0.2/0.05)·[1, −½, −½] = [4, −2, −2].
            publish_until(ros_node, cmd, twist(0.2), lambda: wheels.latest is not None
                          and [round(v, 9) for v in wheels.latest.velocity] == [4.0, -2.0, -2.0],
                          rate_hz=20, timeout=5)
        except TimeoutError as exc:
            fuzz.fail(f"a good cmd_vel no longer turns the wheels: {exc}")
        cmd.publish(twist())
        try:
            # The same wheel speeds to the sim: body-x 0.2 m/s.
            publish_until(ros_node, sim_cmd, at(5.0, OMNI_JOINTS, [], [4.0, -2.0, -2.0]),
                          lambda: truth.latest is not None and abs(truth.latest.twist.twist.linear.x - 0.2) < 1e-3,
                          rate_hz=20, timeout=5)
        except TimeoutError as exc:
            fuzz.fail(f"a good wheel command no longer drives the simulated robot: {exc}")
    answers_parameter_get(fuzz, ros_node, "/chassis", "model", "omni")
    answers_parameter_get(fuzz, ros_node, "/fuzzsim/sim", "model", "omni")
    fuzz.finish(chassis, sim)


# ------------------------------------------------------------------------------------------------
# Parameters
# ------------------------------------------------------------------------------------------------

# Values outside each parameter's range (the nodes' --help states the ranges).
OUT_OF_RANGE = {
    "/chassis": {"v_max": [-1.0, 0.0], "omega_max": [0.0, -3.0], "max_wheel_speed": [0.0],
                 "wheel_radius": [0.0, -0.1], "wheelbase": [-0.6], "track": [-1.0],
                 "max_steering": [2.0, -0.1], "min_turning_radius": [-0.5], "cmd_vel_timeout_s": [-2.0],
                 "feedback_timeout_s": [-0.5], "control_rate_hz": [0.0, 0.5, 1e6],
                 "odom.twist_variance": [[1.0, 2.0], [1.0, 2.0, 3.0, 4.0], [-1.0, 0.0, 0.0]],
                 "odom.along_track_var_per_m": [-1e-3]},
    "/sim": {"robot_radius": [0.0, -1.0], "joint_states_rate_hz": [0.0, 1e4], "wheel_slip": [0.6, -0.9],
             "real_time_factor": [0.0, 1e3], "lidar.beams": [1, 0, -5, 10**9], "lidar.fov": [0.0, 7.0],
             "lidar.range_max": [0.0, -10.0], "lidar.rate_hz": [0.0, 1e4], "lidar.mount": [[0.0, 0.0]],
             "motor_time_constant": [-0.05], "command_timeout_s": [-1.0], "wheel_speed_noise": [-0.1]},
}
# Read-only parameters, each with another value that would be valid at start-up.
READ_ONLY = {
    "/chassis": {"model": "omni", "reference_offset": 0.1},
    "/sim": {"model": "omni", "reference_offset": 0.1, "world_file": "params/worlds/default.yaml", "seed": 7,
             "initial_pose": [1.0, 0.0, 0.0], "physics_rate_hz": 100.0, "publish_clock": True},
}
def test_fuzz_parameter_sets_refused_leave_the_old_value(start_node, ros_node, tmp_path):
    """set_parameters and set_parameters_atomically on chassis_node and sim_node (MOBIL-II) with
    wrong types, NaN/inf, out-of-range values, unknown, read-only and 1 KB–100 KB names and values,
    while the robot drives; every refused set leaves the old value."""
    from rcl_interfaces.msg import Parameter, ParameterType, ParameterValue
    from rcl_interfaces.srv import SetParametersAtomically
    from rosutil import call_service, get_parameters, parameter_value_from_python, parameter_value_to_python
    from rosutil import set_parameters
    rng = rng_for("parameters")
    fuzz = Fuzz("parameters")
    sim = start_node("sim_node", *NO_LIDAR, "-p", f"world_file:={empty_world(tmp_path)}",
                     params_file="params/mobil2.yaml")
    chassis = start_node("chassis_node", params_file="params/mobil2.yaml")
    fuzz.watch(ros_node, JointState, "wheel_commands")
    fuzz.watch(ros_node, Odometry, "odom")
    fuzz.watch(ros_node, Odometry, "ground_truth")
    fuzz.watch(ros_node, ChassisStatus, "chassis/status", fuzz.status_checks())
    # The robot drives during the fuzz, so that accepted values are used at once.
    cmd = ros_node.create_publisher(Twist, "cmd_vel", 10)
    driving = ros_node.create_timer(0.1, lambda: cmd.publish(twist(0.2, 0.0, 0.1)))

    def get_all(node: str, names: list[str], timeout: float = PER_CALL_TIMEOUT) -> dict[str, Any]:
        # A few names a request keeps each reply small (large replies are a matter of their own).
        out = {}
        for k in range(0, len(names), 6):
            chunk = names[k:k + 6]
            values = get_parameters(ros_node, node, chunk, timeout=timeout)
            out.update({n: parameter_value_to_python(v) for n, v in zip(chunk, values)})
        return out

    def pv(value: Any) -> ParameterValue:
        if isinstance(value, ParameterValue):
            return value
        return parameter_value_from_python(value)

    def describe(value: Any) -> str:
        text = repr(value)
        return text if len(text) < 60 else f"{text[:40]}… ({len(text)} chars)"

    refused = accepted = 0
    try:
        for node in ("/chassis", "/sim"):
            assert harness.wait_for_node(ros_node, node, timeout=10)
            names = harness.param_list(ros_node, node, timeout=10)
            old = get_all(node, names, timeout=10.0)
            cases: list[tuple[str, Any, Optional[bool]]] = []  # (name, value, must be refused?)
            for name, value in old.items():
                for wrong in rng.sample(WRONG_TYPES, 3):
                    if not same_type(wrong, value):
                        cases.append((name, wrong, True))
                if isinstance(value, float):
                    cases += [(name, v, True) for v in (NAN, INF, -INF)]
                    # Huge or tiny but finite: the node may accept them (then they must work).
                    cases.append((name, rng.choice([1e308, -1e308, 5e-324, -0.0]), None))
                cases.append((name, ParameterValue(type=ParameterType.PARAMETER_NOT_SET), True))
            for name, values in OUT_OF_RANGE[node].items():
                cases += [(name, v, True) for v in values]
            for name, value in READ_ONLY[node].items():
                cases.append((name, value, True))
            for _ in range(30):
                cases.append((random_name(rng) + rng.choice(["", "/x", ".y", "..", "*"]), number(rng), True))
            rng.shuffle(cases)
            started = time.monotonic()
            for name, value, must_refuse in cases:
                fuzz.case = f"{node} {name}={describe(value)}"
                try:
                    res = set_parameters(ros_node, node, {name: pv(value)}, timeout=PER_CALL_TIMEOUT)[0]
                    now = get_all(node, [name])[name]
                except TimeoutError as exc:
                    fuzz.fail(f"no answer: {exc}")
                    continue
                was = old.get(name)
                if must_refuse and res.successful:
                    fuzz.fail("accepted")
                if res.successful:
                    accepted += 1
                    print(f"accepted: {fuzz.case}")
                    fuzz.check(now == value or (isinstance(value, float) and now == value),
                               f"accepted, but get_parameters shows {describe(now)}")
                    back = set_parameters(ros_node, node, {name: pv(was)}, timeout=PER_CALL_TIMEOUT)[0]
                    fuzz.check(back.successful, f"restoring {describe(was)} refused: {back.reason}")
                else:
                    refused += 1
                    fuzz.check(bool(res.reason), "refused without a reason")
                    fuzz.check(now == was, f"refused, but the value changed from {describe(was)} to {describe(now)}")
            # Atomic batches with an invalid value: nothing changes.
            atomic = f"{node}/set_parameters_atomically"
            for i in range(20):
                valid_name = rng.choice([n for n in ("v_max", "omega_max", "wheel_radius") if n in old])
                batch = [(valid_name, old[valid_name] * rng.uniform(0.5, 0.9))]
                bad_name, bad_value, _ = rng.choice([c for c in cases if c[2]])
                batch.insert(rng.randrange(2) if i % 2 else 1, (bad_name, bad_value))
                fuzz.case = f"{atomic} {[(n, describe(v)) for n, v in batch]}"
                request = SetParametersAtomically.Request(parameters=[Parameter(name=n, value=pv(v)) for n, v in batch])
                try:
                    res = call_service(ros_node, SetParametersAtomically, atomic, request, timeout=PER_CALL_TIMEOUT)
                    now = get_all(node, [n for n, _ in batch])
                except TimeoutError as exc:
                    fuzz.fail(f"no answer: {exc}")
                    continue
                fuzz.check(not res.result.successful, "accepted")
                for n, _ in batch:
                    fuzz.check(now[n] == old.get(n), f"{n} changed from {describe(old.get(n))} to {describe(now[n])}")
                fuzz.count("atomic sets")
            # Very long names and string values (1 KB, 10 KB, 100 KB): unknown names, a string for
            # a double, and read-only or constrained strings.
            long_cases = [(size, "".join(rng.choice("abcxyz_/.") for _ in range(size)))
                          for size in (1_000, 10_000, 100_000)]
            long_cases = [(size, name, value) for size, text in long_cases
                          for name, value in ((text, 1.0), ("v_max", text), ("model", text))]
            for k, (size, name, value) in enumerate(long_cases):
                fuzz.case = f"{node} {describe(name)}={describe(value)} ({size} B)"
                try:
                    res = set_parameters(ros_node, node, {name: value}, timeout=PER_CALL_TIMEOUT)[0]
                    now = get_all(node, [name])[name]
                except TimeoutError as exc:
                    # The rest would time out the same way: one failure says it, and keeps the
                    # run short.
                    fuzz.fail(f"no answer: {str(exc)[:200]} ({len(long_cases) - k - 1} longer sets not tried)")
                    break
                fuzz.check(not res.successful, "accepted")
                fuzz.check(now == old.get(name), f"the value changed to {describe(now)}")
                fuzz.count("long sets")
            fuzz.count(f"{node} sets", len(cases))
            print(f"{node}: {len(cases)} sets and the atomic and long ones in {time.monotonic() - started:.1f} s")
            # Still alive and unchanged.
            fuzz.case = f"{node} after the fuzz"
            try:
                fuzz.check(get_all(node, names) == old, "some value changed")
            except TimeoutError as exc:
                fuzz.fail(f"no longer answers get_parameters: {exc}")
    finally:
        ros_node.destroy_timer(driving)
    fuzz.count("refused", refused)
    fuzz.count("accepted (and restored)", accepted)
    fuzz.case = "good command after the fuzz"
    with subscribe(ros_node, JointState, "wheel_commands", qos=harness.make_qos(depth=100)) as wheels:
        try:
            publish_until(ros_node, cmd, twist(0.3), lambda: wheels.latest is not None and nonzero(wheels.latest),
                          rate_hz=20, timeout=5)
        except TimeoutError as exc:
            fuzz.fail(f"a good cmd_vel no longer turns the wheels: {exc}")
        cmd.publish(twist())
    fuzz.finish(chassis, sim)


# ------------------------------------------------------------------------------------------------
# World files
# ------------------------------------------------------------------------------------------------

def test_fuzz_world_files_start_or_exit_with_one_clear_line(start_node, ros_node, tmp_path):
    """sim_node on degenerate and garbage world files: it runs the world when the file is
    valid (a bow tie, 100k obstacles) or exits at once with a non-zero code and one error line
    naming the file; never a panic or a hang."""
    rng = rng_for("worlds")
    far = "".join(f"  - circle: {{ center: [{100 + (i % 1000) * 0.5}, {(i // 1000) * 0.5}], radius: 0.1 }}\n"
                  for i in range(100_000))
    files: dict[str, tuple[Optional[bytes], Optional[int]]] = {
        # name: (content or None for a missing file, obstacle count if it must start)
        "binary": (bytes(rng.randrange(256) for _ in range(2000)), None),
        "empty": (b"", None),
        "wrong_shape": (b"obstacles:\n  circle: { center: [0, 0], radius: 1 }\n", None),
        "list_at_top": (b"- circle: { center: [3, 3], radius: 1 }\n", None),
        "nan": (b"obstacles:\n  - circle: { center: [.nan, 3], radius: 1 }\n", None),
        "inf": (b"obstacles:\n  - polygon: { points: [[3, 3], [.inf, 3], [4, 4]] }\n", None),
        "huge": (b"obstacles:\n  - polygon: { points: [[-1e308, 3], [1e308, 3], [0, 1e308]] }\n", None),
        "zero_radius": (b"obstacles:\n  - circle: { center: [3, 3], radius: 0 }\n", None),
        "negative_radius": (b"obstacles:\n  - circle: { center: [3, 3], radius: -2 }\n", None),
        "two_points": (b"obstacles:\n  - polygon: { points: [[3, 3], [4, 4]] }\n", None),
        "missing": (None, None),
        "bow_tie": (b"obstacles:\n  - polygon: { points: [[5, 5], [7, 7], [7, 5], [5, 7]] }\n", 1),
        "100k": (("obstacles:\n" + far).encode(), 100_000),
    }
    procs = {}
    for name, (content, _) in files.items():
        path = tmp_path / f"{name}.yaml"
        if content is not None:
            path.write_bytes(content)
        procs[name] = (path, start_node("sim_node", *NO_LIDAR, "-p", f"world_file:={path}",
                                        params_file="params/mobil2.yaml", name=f"sim_{name}"))
    problems = []
    for name, (content, count) in files.items():
        path, proc = procs[name]
        try:
            if count is not None:
                proc.wait_for_log(rf"world of {count} obstacles", timeout=30)
                continue
            code = proc.wait(timeout=15)
        except (TimeoutError, harness.NodeProcessError) as exc:
            problems.append(f"{name}: {exc}")
            continue
        log = proc.log_text()
        lines = [line for line in log.splitlines() if line.strip()]
        if code == 0:
            problems.append(f"{name}: exited with 0")
        if "panicked" in log:
            problems.append(f"{name}: panicked\n{log[-2000:]}")
        # The reason is the node's last word: one ERROR line naming the file (the DDS stack may
        # log errors of its own while the participant leaves, before it).
        if not lines or "ERROR" not in lines[-1] or str(path) not in lines[-1]:
            problems.append(f"{name}: the last line does not name {path}: {lines[-1:]}")
        else:
            print(f"{name}: {lines[-1].split('ERROR', 1)[1].strip()}")
    for name, (content, count) in files.items():
        path, proc = procs[name]
        if count is not None and proc.running:
            try:
                proc.stop()
            except harness.NodeProcessError as exc:
                problems.append(f"{name}: {exc}")
            if "panicked" in proc.log_text():
                problems.append(f"{name}: panicked")
    assert not problems, f"seed {SEED}:\n" + "\n".join(problems)
