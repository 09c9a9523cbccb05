"""planner/check_route from rclpy, run by hand (not a test):

    MOBIL_BIN_DIR=$PWD/target/release .venv/bin/python tests/bench_check_route.py [--calls 300]

The same request as the Rust bench (`cargo bench -p mobil_planner_node --bench check_route`): the
20 waypoints round the built-in world's demo loop, from a given start (use_start), to
planner_node with params/mobil2.yaml. After the first answer (discovery) and 20 calls to warm
up, the calls are timed one after the other (the client's node spun by a persistent executor on
a thread of its own), alternating with a request the node refuses at once (a NaN start: the
floor of a call). Reported: p50 / p90 / p99 of each (ms).
"""

from __future__ import annotations

import argparse
import math
import os
import random
import statistics
import sys
import tempfile
import threading
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
os.environ.setdefault("ROS_DOMAIN_ID", str(random.SystemRandom().randrange(200, 230)))

import rosutil  # noqa: E402

rosutil.setup_process_environment()

import harness  # noqa: E402


def demo_loop(n: int) -> list[tuple[float, float]]:
    """The demo loop of the built-in world as n waypoints (nodes/planner/benches/common/demo_loop.rs)."""
    sides = [((0.0, 0.0), (2.0, 0.0), (2.0, 1.0)), ((3.0, 1.0), (3.0, 2.0), (2.0, 2.0)),
             ((2.0, 3.0), (0.0, 3.0), (0.0, 2.0)), ((-1.0, 2.0), (-1.0, 1.0), (0.0, 1.0))]
    total = 6.0 + 2.0 * math.pi
    out = []
    for k in range(1, n + 1):
        s = total * k / n
        for i, (a, b, c) in enumerate(sides):
            length = math.hypot(b[0] - a[0], b[1] - a[1])
            if s <= length:
                f = s / length
                out.append((a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1])))
                break
            s -= length
            if s <= math.pi / 2 or i == 3:
                phi = -math.pi / 2 + math.pi / 2 * i + min(s, math.pi / 2)
                out.append((c[0] + math.cos(phi), c[1] + math.sin(phi)))
                break
            s -= math.pi / 2
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--calls", type=int, default=300)
    args = ap.parse_args()

    import rclpy
    from geometry_msgs.msg import PoseStamped
    from mobil_msgs.srv import CheckRoute

    rclpy.init()
    node = rclpy.create_node("bench_check_route")
    logs = Path(tempfile.mkdtemp(prefix="bench_check_route_"))
    planner = harness.launch_node("planner_node", "--log-level", "warn",
                                  params_file="params/mobil2.yaml", log_dir=logs)
    client = node.create_client(CheckRoute, "planner/check_route")
    # A persistent executor on its own thread (spin_until_future_complete per call adds
    # milliseconds of executor set-up to every call).
    spinner = rosutil.Spinner(node).start()
    try:
        request = CheckRoute.Request()
        request.route.header.frame_id = "odom"
        for x, y in demo_loop(20):
            p = PoseStamped()
            p.header.frame_id = "odom"
            p.pose.position.x, p.pose.position.y = x, y
            p.pose.orientation.w = 1.0
            request.route.poses.append(p)
        request.use_start = True
        request.start.orientation.w = 1.0
        refused = CheckRoute.Request()
        refused.route = request.route
        refused.use_start = True
        refused.start.position.x = math.nan
        refused.start.orientation.w = 1.0
        assert client.wait_for_service(timeout_sec=20.0), "planner/check_route not found"

        def call(req, timeout: float = 5.0):
            done = threading.Event()
            future = client.call_async(req)
            future.add_done_callback(lambda _: done.set())
            done.wait(timeout)
            return future.result() if future.done() else None

        deadline = time.monotonic() + 30.0
        while call(request, 1.0) is None:
            if time.monotonic() > deadline:
                raise SystemExit(f"no answer in 30 s; logs in {logs}")
        times = {"route": [], "refused": []}
        for k in range(20 + args.calls):
            for name, req in (("route", request), ("refused", refused)):
                t0 = time.perf_counter()
                reply = call(req)
                elapsed = (time.perf_counter() - t0) * 1e3
                if reply is None:
                    raise SystemExit(f"call {k}: no answer in 5 s")
                if k >= 20:
                    times[name].append(elapsed)
        answer = call(request)
    finally:
        spinner.stop()
        planner.stop()
        rclpy.try_shutdown()

    print(f"planner/check_route from rclpy, {args.calls} calls; reply {len(answer.simulated_path.poses)} "
          f"poses, {len(answer.problems)} problems")
    for name, label in (("route", "20-waypoint route"), ("refused", "refused at once (the floor)")):
        q = statistics.quantiles(times[name], n=100)
        print(f"  {label:<30} p50 {statistics.median(times[name]):.3f}  p90 {q[89]:.3f}  p99 {q[98]:.3f} ms")
    return 0


if __name__ == "__main__":
    sys.exit(main())
