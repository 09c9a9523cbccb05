#!/usr/bin/env python3
"""A synthetic simulator for `ga_step --evaluator ros` (not physics): it serves the contract in a
namespace, `<ns>/ga_step/candidate` → `<ns>/ga_step/outcome`, answering each candidate after a
set delay (what a simulator's evaluation would take) by a rule that depends on the candidate's
knots alone, so that any simulator gives a candidate the same score.

    .venv/bin/python tests/fake_ga_sim.py --ns /sim1 [--delay 0.05] [--die-at N] [--log FILE]

The rule is `rule`'s, a function of the mean knee knots, so that scores vary from candidate to
candidate and a run's course depends on every one of them. `--die-at N` kills the process (SIGKILL, no goodbye on the wire) when its N-th distinct
candidate arrives, before answering it; `--leave-at N` leaves then instead, destroying its node
and participant, which peers see at once. `--log FILE` appends a line per candidate answered: the time (s since the epoch), the
namespace and the candidate's name.
"""
from __future__ import annotations

import argparse
import os
import signal
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rosutil  # noqa: E402

rosutil.setup_process_environment()

import rclpy  # noqa: E402
from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy  # noqa: E402
from rclpy.signals import SignalHandlerOptions  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402
from trajectory_msgs.msg import JointTrajectory  # noqa: E402


class Leave(Exception):
    """Raised in the callback to leave the spin and go cleanly."""


def rule(msg: JointTrajectory) -> tuple[bool, float, float]:
    """(fell, fall_time, forward_distance) of a candidate, from the mean knee knots r (right) and
    l (left), rad: it falls when r > 1 rad, at 3·(2.27 − r)/1.27 s (within 0.01–2.99 s); upright,
    it moves 0.03·r − 0.01·l m (under 0.03 m: never a forward step)."""
    r = sum(p.positions[2] for p in msg.points) / len(msg.points)
    l = sum(p.positions[7] for p in msg.points) / len(msg.points)
    if r > 1.0:
        return True, min(2.99, max(0.01, 3.0 * (2.27 - r) / 1.27)), 0.0
    return False, 0.0, 0.03 * r - 0.01 * l


def main(argv: list[str]) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--ns", required=True, help="namespace of the two topics, e.g. /sim1")
    parser.add_argument("--delay", type=float, default=0.05, help="seconds per evaluation")
    parser.add_argument("--die-at", type=int, default=0, help="die when the N-th candidate arrives")
    parser.add_argument("--leave-at", type=int, default=0,
                        help="leave cleanly (node and participant destroyed) when the N-th arrives")
    parser.add_argument("--log", type=Path, help="append a line per candidate answered")
    args = parser.parse_args(argv)
    ns = args.ns.rstrip("/")
    # No rclpy signal handlers: SIGTERM's default action ends the process at once, wherever it
    # waits (each log line is written and closed, so nothing is left to flush).
    rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
    node = rclpy.create_node("fake_ga_sim", namespace=ns or "/")
    qos = QoSProfile(depth=10, reliability=QoSReliabilityPolicy.RELIABLE,
                     durability=QoSDurabilityPolicy.VOLATILE)
    outcomes = node.create_publisher(JointState, f"{ns}/ga_step/outcome", qos)
    seen: set[tuple[str, int, int]] = set()

    def on_candidate(msg: JointTrajectory) -> None:
        key = (msg.header.frame_id, msg.header.stamp.sec, msg.header.stamp.nanosec)
        if key in seen:
            return  # a copy of a candidate answered already
        seen.add(key)
        if args.die_at and len(seen) >= args.die_at:
            os.kill(os.getpid(), signal.SIGKILL)
        if args.leave_at and len(seen) >= args.leave_at:
            raise Leave()
        time.sleep(args.delay)
        fell, t, dx = rule(msg)
        names, values = ["fell", "forward_distance"], [1.0 if fell else 0.0, dx]
        if fell:
            names.append("fall_time")
            values.append(t)
        outcomes.publish(JointState(header=msg.header, name=names, position=values))
        if args.log:
            with args.log.open("a") as f:
                f.write(f"{time.time():.6f} {ns} {msg.header.frame_id}\n")

    node.create_subscription(JointTrajectory, f"{ns}/ga_step/candidate", on_candidate, qos)
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, SystemExit):
        pass
    except Leave:
        # Endpoints and participant disposed on the wire: peers see them go at once.
        node.destroy_node()
        rclpy.shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
