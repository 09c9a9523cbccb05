"""A foreign LIDAR for tests/test_local_nav.py: a simulated planar LIDAR in its own process,
with its own raycaster, independent of sim_node's.

``foreign_lidar.py WORLD_FILE [--ros-args ...]`` reads a world in the format of
params/worlds/*.yaml (``obstacles``: ``polygon: {points}`` and ``circle: {center, radius}``),
follows sim_node's ``ground_truth`` and, for every ``every``-th sample (parameter, default 2:
25 Hz at sim_node's 50 Hz), publishes ``scan`` (sensor_msgs/LaserScan, best effort, frame
``laser``: 541 beams over 270°, range 0.06–10 m, +inf where nothing is in range, REP-117) as
seen from that pose, stamped with the sample's own stamp. Driven by the samples, not by a
timer, the scan is exact for its stamp whatever the clock does. Exits 0 on SIGINT.

A process of its own: in the busy test process a scan thread was seen to stall for 0.4 wall
seconds (2 simulated seconds at 5×) while chassis_node kept driving the last command.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import numpy as np
import yaml


class WorldRaycaster:
    """Ranges of a planar LIDAR in a world file: every polygon edge a segment (ray-segment
    intersection), every circle a quadratic; the nearest hit per beam, +inf beyond range_max."""

    def __init__(self, world_file: Path, range_max: float = 10.0) -> None:
        world = yaml.safe_load(Path(world_file).read_text()) or {}
        segments, circles = [], []
        for ob in world.get("obstacles") or []:
            if "polygon" in ob:
                pts = ob["polygon"]["points"]
                for a, b in zip(pts, pts[1:] + pts[:1]):
                    segments.append((*a, *b))
            elif "circle" in ob:
                c = ob["circle"]
                circles.append((*c["center"], c["radius"]))
        self.segments = np.array(segments, dtype=float).reshape(-1, 4)
        self.circles = np.array(circles, dtype=float).reshape(-1, 3)
        self.range_max = range_max

    def ranges(self, x: float, y: float, angles: np.ndarray) -> np.ndarray:
        """Range along each world-frame angle from (x, y)."""
        dx, dy = np.cos(angles)[:, None], np.sin(angles)[:, None]
        best = np.full(len(angles), np.inf)
        if len(self.segments):
            ax, ay, bx, by = (self.segments[:, i][None, :] for i in range(4))
            ex, ey = bx - ax, by - ay
            denom = dx * ey - dy * ex
            with np.errstate(divide="ignore", invalid="ignore"):
                t = ((ax - x) * ey - (ay - y) * ex) / denom  # along the ray
                u = ((ax - x) * dy - (ay - y) * dx) / denom  # along the segment
            hit = (np.abs(denom) > 1e-12) & (t > 0) & (u >= 0) & (u <= 1)
            best = np.minimum(best, np.where(hit, t, np.inf).min(axis=1))
        if len(self.circles):
            cx, cy, r = (self.circles[:, i][None, :] for i in range(3))
            fx, fy = x - cx, y - cy
            b = fx * dx + fy * dy
            disc = b * b - (fx * fx + fy * fy - r * r)
            root = np.sqrt(np.where(disc >= 0, disc, 0.0))
            t = np.where((disc >= 0) & (-b - root > 0), -b - root, np.inf)
            best = np.minimum(best, t.min(axis=1))
        return np.where(best <= self.range_max, best, np.inf)


FOV = 1.5 * math.pi
BEAMS = 541


def main() -> int:
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import rosutil
    rosutil.setup_process_environment()
    import rclpy
    from rclpy.executors import ExternalShutdownException
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan

    import signal
    from rclpy.signals import SignalHandlerOptions
    stop = {"now": False}
    # Our own SIGINT handler: rclpy's, shutting the context down under a running take, made the
    # process exit with an error now and then.
    rclpy.init(args=sys.argv, signal_handler_options=SignalHandlerOptions.NO)
    signal.signal(signal.SIGINT, lambda *_: stop.update(now=True))
    args = rclpy.utilities.remove_ros_args(sys.argv)
    caster = WorldRaycaster(Path(args[1]))
    node = rclpy.create_node("foreign_lidar")
    every = node.declare_parameter("every", 2).value
    pub = node.create_publisher(LaserScan, "scan", rosutil.qos_sensor())
    angles = -FOV / 2 + np.arange(BEAMS) * (FOV / (BEAMS - 1))
    count = {"truth": 0, "scans": 0}

    def on_truth(m: Odometry) -> None:
        count["truth"] += 1
        if count["truth"] % every:
            return
        p, q = m.pose.pose.position, m.pose.pose.orientation
        yaw = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        scan = LaserScan()
        scan.header.stamp = m.header.stamp
        scan.header.frame_id = "laser"
        scan.angle_min, scan.angle_max = -FOV / 2, FOV / 2
        scan.angle_increment = FOV / (BEAMS - 1)
        scan.range_min, scan.range_max = 0.06, caster.range_max
        scan.ranges = caster.ranges(p.x, p.y, angles + yaw).astype(np.float32).tolist()
        pub.publish(scan)
        count["scans"] += 1
        if count["scans"] == 1:
            print("foreign_lidar: first scan published", flush=True)

    # Best effort: a lost sample costs one scan, and no reliability protocol can hold the stream up.
    node.create_subscription(Odometry, "ground_truth", on_truth, rosutil.qos_sensor())
    print("foreign_lidar up", flush=True)
    try:
        while not stop["now"]:
            rclpy.spin_once(node, timeout_sec=0.05)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    print(f"foreign_lidar: {count['scans']} scans published; shutting down", flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
