"""End-to-end latency of local_nav_node against a do-nothing floor, run by hand (not a test):

    MOBIL_BIN_DIR=$PWD/target/release .venv/bin/python tests/bench_latency.py [--scans 1200]

rclpy publishes 1081-beam, 270° LaserScans at 40 Hz, the send time in the header stamp, to two
Rust nodes in the same run, each in its own namespace:

* ``scan_echo`` (nodes/local_nav_node): answers every scan with one cmd_vel at once (the floor: the
  same DDS path, the same message types and QoS, no work);
* ``local_nav_node`` (params/omr3.yaml): fed an odometry that advances at 0.5 m/s along x (so its
  progress checker is satisfied) and a goal 1 km ahead, in a 4 m wide corridor (the walls are in
  every scan, so the sectors are not empty; the goal sector is clear, so the node stays in R-mode).

The latency of a scan is from its send time to the arrival here of the first cmd_vel after it
(the first within 25 ms, the scan period; none is a miss). That is the right measure for a node
that answers each scan, and for one that publishes on a timer it is the wait for its next
command; the echo's replies also carry the scan's stamp, which checks the pairing. The two nodes
are measured in alternating rounds so that a change of the machine's load hits both alike.
Reported: answered scans, p50, p99 and mean (ms) per node, the ratio of the p50s, and the CPU each
node used while being fed (utime + stime from /proc/PID/stat, percent of one core).
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

BEAMS = 1081
FOV = math.radians(270.0)
RATE_HZ = 40.0
CORRIDOR_HALF_WIDTH = 2.0
SPEED = 0.5


def corridor_ranges() -> list[float]:
    """Ranges of a 270° scan in a corridor |y| = 2 m, open ahead and behind (inf = no return)."""
    out = []
    inc = FOV / (BEAMS - 1)
    for i in range(BEAMS):
        a = -FOV / 2 + i * inc
        s = math.sin(a)
        r = CORRIDOR_HALF_WIDTH / abs(s) if abs(s) > 1e-9 else math.inf
        out.append(r if r <= 10.0 else math.inf)
    return out


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    # utime and stime are fields 14 and 15 of stat (1-based), 12 and 13 after the ")".
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def percentile(values: list[float], p: float) -> float:
    s = sorted(values)
    k = (len(s) - 1) * p / 100.0
    lo, hi = math.floor(k), math.ceil(k)
    return s[lo] + (s[hi] - s[lo]) * (k - lo)


class Target:
    """One node under test: its topics in namespace ``ns``, its replies' arrival times."""

    def __init__(self, node, ns: str, proc: harness.NodeProcess) -> None:
        from geometry_msgs.msg import Twist
        from nav_msgs.msg import Odometry
        from sensor_msgs.msg import LaserScan
        from geometry_msgs.msg import PoseStamped
        self.ns, self.proc = ns, proc
        self.lock = threading.Lock()
        self.replies: list[tuple[int, int]] = []  # (arrival ns, echoed stamp ns or -1)
        self.scan_pub = node.create_publisher(LaserScan, f"{ns}/scan", harness.qos_sensor())
        self.odom_pub = node.create_publisher(Odometry, f"{ns}/odom", harness.qos_default())
        self.goal_pub = node.create_publisher(PoseStamped, f"{ns}/goal_pose", harness.qos_default())
        node.create_subscription(Twist, f"{ns}/cmd_vel", self._on_cmd, harness.qos_default())
        self.latencies: list[float] = []
        self.sent = 0
        self.cpu = 0.0
        self.wall = 0.0
        self.paired_ok = 0

    def _on_cmd(self, msg) -> None:
        now = time.time_ns()
        echoed = int(msg.angular.x) * 1_000_000_000 + int(msg.angular.y) if msg.angular.x > 0 else -1
        with self.lock:
            self.replies.append((now, echoed))


def make_scan(stamp_ns: int):
    from sensor_msgs.msg import LaserScan
    m = LaserScan()
    m.header.frame_id = "laser"
    m.header.stamp.sec, m.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    m.angle_min, m.angle_max = -FOV / 2, FOV / 2
    m.angle_increment = FOV / (BEAMS - 1)
    m.scan_time = 1.0 / RATE_HZ
    m.range_min, m.range_max = 0.06, 10.0
    m.ranges = RANGES
    return m


def make_odom(stamp_ns: int, x: float):
    from nav_msgs.msg import Odometry
    m = Odometry()
    m.header.frame_id, m.child_frame_id = "odom", "base_link"
    m.header.stamp.sec, m.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    m.pose.pose.position.x = x
    m.pose.pose.orientation.w = 1.0
    m.twist.twist.linear.x = SPEED
    return m


def make_goal(stamp_ns: int):
    from geometry_msgs.msg import PoseStamped
    m = PoseStamped()
    m.header.frame_id = "odom"
    m.header.stamp.sec, m.header.stamp.nanosec = divmod(stamp_ns, 1_000_000_000)
    m.pose.position.x = 1000.0
    m.pose.orientation.w = 1.0
    return m


RANGES = corridor_ranges()


def feed(t: Target, count: int, x0: float, measure: bool) -> float:
    """Send ``count`` scans (with odometry) at 40 Hz; return the odometry's x at the end."""
    period_ns = int(1e9 / RATE_HZ)
    sends: list[int] = []
    x = x0
    with t.lock:
        t.replies.clear()
    cpu0, wall0 = cpu_seconds(t.proc.pid), time.monotonic()
    next_ns = time.time_ns()
    for _ in range(count):
        while (now := time.time_ns()) < next_ns:
            time.sleep(min(0.002, (next_ns - now) / 1e9))
        x += SPEED / RATE_HZ
        t.odom_pub.publish(make_odom(now, x))
        stamp = time.time_ns()
        t.scan_pub.publish(make_scan(stamp))
        sends.append(stamp)
        next_ns += period_ns
    time.sleep(0.1)
    if measure:
        t.cpu += cpu_seconds(t.proc.pid) - cpu0
        t.wall += time.monotonic() - wall0
        with t.lock:
            replies = list(t.replies)
        arrivals = [a for a, _ in replies]
        echoed = {e for _, e in replies}
        j = 0
        for k, s in enumerate(sends):
            nxt = sends[k + 1] if k + 1 < len(sends) else s + period_ns
            while j < len(arrivals) and arrivals[j] <= s:
                j += 1
            if j < len(arrivals) and arrivals[j] < nxt:
                t.latencies.append((arrivals[j] - s) / 1e6)
            if s in echoed:
                t.paired_ok += 1
        t.sent += count
    return x


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--scans", type=int, default=1200, help="scans measured per node (default 1200)")
    ap.add_argument("--rounds", type=int, default=4, help="alternating rounds (default 4)")
    ap.add_argument("--params", default="params/omr3.yaml", help="local_nav_node's params file")
    args = ap.parse_args()

    import rclpy
    rclpy.init()
    node = rclpy.create_node("bench_latency")
    logs = Path(tempfile.mkdtemp(prefix="bench_latency_"))
    echo = harness.launch_node("scan_echo", "-r", "__ns:=/echo", "--log-level", "warn", log_dir=logs)
    nav = harness.launch_node("local_nav_node", "-r", "__ns:=/nav", "--log-level", "warn",
                              params_file=args.params, log_dir=logs)
    targets = [Target(node, "/echo", echo), Target(node, "/nav", nav)]
    spinner = rosutil.Spinner(node).start()
    try:
        x = 0.0

        def warm_up(t: Target, x: float) -> float:
            """Feed until replies come (discovery; for local_nav a goal, sent again each round:
            its scan and odom watchdogs end the goal while the other node is measured)."""
            deadline = time.monotonic() + 20.0
            while True:
                t.goal_pub.publish(make_goal(time.time_ns()))
                x = feed(t, 20, x, measure=False)
                with t.lock:
                    if len(t.replies) >= 15:
                        return x
                if time.monotonic() > deadline:
                    raise SystemExit(f"{t.ns}: no cmd_vel after 20 s; logs in {logs}")

        per_round = math.ceil(args.scans / args.rounds)
        for _ in range(args.rounds):
            for t in targets:
                x = warm_up(t, x)
                x = feed(t, per_round, x, measure=True)
    finally:
        spinner.stop()
        for p in (echo, nav):
            try:
                p.stop()
            except harness.NodeProcessError as exc:
                print(exc, file=sys.stderr)
        rclpy.try_shutdown()

    names = {"/echo": "scan_echo (floor)", "/nav": "local_nav_node"}
    print(f"{BEAMS}-beam scans at {RATE_HZ:g} Hz, {args.rounds} alternating rounds, "
          f"send → first cmd_vel after it (ms):")
    print(f"  {'node':<20} {'answered':>11} {'p50':>7} {'p99':>7} {'mean':>7} {'CPU %':>6}")
    p50 = {}
    for t in targets:
        lat = t.latencies
        cpu = 100.0 * t.cpu / t.wall if t.wall else float("nan")
        if not lat:
            print(f"  {names[t.ns]:<20} {0:>5}/{t.sent:<5} no replies")
            continue
        p50[t.ns] = percentile(lat, 50)
        print(f"  {names[t.ns]:<20} {len(lat):>5}/{t.sent:<5} {p50[t.ns]:7.3f} "
              f"{percentile(lat, 99):7.3f} {statistics.fmean(lat):7.3f} {cpu:6.1f}")
    e = targets[0]
    print(f"  scan_echo replies paired to their scan by the echoed stamp: {e.paired_ok}/{e.sent}")
    if "/echo" in p50 and "/nav" in p50:
        print(f"  p50 ratio local_nav_node / scan_echo: {p50['/nav'] / p50['/echo']:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
