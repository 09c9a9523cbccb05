#!/usr/bin/env python3
"""A goal sent the way RViz sends one (``goal_pose``, geometry_msgs/PoseStamped in ``odom``), and
the robot's odometry watched until it gets there: one JSON line, exit 0 when reached.

    netns_goal_client.py X Y [--tolerance 0.15] [--timeout 40]

Used by tests/test_multi_host.py from a network namespace of its own, so that the goal, the
odometry and (between the nodes) the scan, the wheel feedback and commands all cross hosts.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rosutil  # noqa: E402

rosutil.setup_process_environment()

import rclpy  # noqa: E402
from geometry_msgs.msg import PoseStamped  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("x", type=float)
    ap.add_argument("y", type=float)
    ap.add_argument("--tolerance", type=float, default=0.15)
    ap.add_argument("--timeout", type=float, default=40.0)
    args = ap.parse_args()
    rclpy.init()
    node = rclpy.create_node("netns_goal_client")
    latest: list[Odometry] = []

    def on_odom(msg: Odometry) -> None:
        latest[:] = [msg]

    node.create_subscription(Odometry, "/odom", on_odom, 10)
    goal_pub = node.create_publisher(PoseStamped, "/goal_pose", 10)
    start = time.monotonic()
    deadline = start + args.timeout
    sent_at = None
    result = {"reached": False}
    while time.monotonic() < deadline:
        rclpy.spin_once(node, timeout_sec=0.05)
        if sent_at is None and latest and goal_pub.get_subscription_count() > 0:
            time.sleep(0.5)  # the navigator's reader matched ours too
            goal = PoseStamped()
            goal.header.frame_id = "odom"
            goal.pose.position.x, goal.pose.position.y = args.x, args.y
            goal.pose.orientation.w = 1.0
            goal_pub.publish(goal)
            sent_at = time.monotonic()
            result["first_odom_s"] = round(sent_at - start, 2)
        if sent_at is not None and latest:
            p = latest[-1].pose.pose.position
            d = math.hypot(p.x - args.x, p.y - args.y)
            result.update(distance=round(d, 3), x=round(p.x, 3), y=round(p.y, 3))
            if d <= args.tolerance:
                result.update(reached=True, seconds=round(time.monotonic() - sent_at, 2))
                break
    result["odom_seen"] = bool(latest)
    print(json.dumps(result), flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0 if result["reached"] else 1


if __name__ == "__main__":
    sys.exit(main())
