#!/usr/bin/env python3
"""Soak: a robot's whole graph (sim_node at 5× real time with its LIDAR, chassis_node,
local_nav_node, planner_node; OMR-III in the built-in world) driven by goals, VFO routes, dockings
and undockings in a loop, one at a time, for a span of simulated time. Reports each node's
resident memory and CPU at the start (after a warm-up) and at the end, the goals sent and how
they ended, and any stall: a ``/clock`` that stops for over a second of wall time, or a goal whose
result does not come within its allowance.

    .venv/bin/python tests/soak.py --sim-minutes 30          # the long soak (6 min at 5×)
    .venv/bin/python tests/soak.py --sim-minutes 30 --json soak.json

tests/test_soak.py runs a short one (3 simulated minutes after 1 of warm-up) in the suite. The long soak's figures
are in docs/performance.md.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import sys
import tempfile
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402
import rosutil  # noqa: E402
from harness import stamped_pose as pose  # noqa: E402

PARAMS = "params/omr3.yaml"
FACTOR = 5.0
# Resident memory settles over the first simulated minutes (allocator arenas, DDS buffers,
# histories filling): measured from then on.
WARM_UP_SIM_S = 300.0
SAMPLE_SIM_S = 300.0
# The loop, by hand from the demo's acts (nodes/tools/src: nav_demo, vfo.rs DEMO_ROUTE,
# plan.rs DEMO_DOCK): behind the pillar and back by local_nav, the four VFO waypoints through
# the clutter, the dock in front of the south wall, out of it, home.
NAV_GOALS = [(3.0, 4.0), (0.0, 0.0)]
VFO_ROUTE = [(2.0, 2.6), (3.2, 0.3), (1.0, -0.3), (0.0, 2.2)]
DOCK = (3.5, -1.2, -math.pi / 2)
# How long a goal may take in simulated time before it counts as a stall (a goal that ends by
# itself, however it ends, is no stall).
ALLOWANCE_SIM_S = {"navigate_to_pose": 90.0, "follow_waypoints": 180.0, "dock_robot": 150.0,
                   "undock_robot": 45.0}


@dataclass
class Usage:
    rss_kib: int
    cpu_s: float


@dataclass
class Report:
    sim_s: float = 0.0
    wall_s: float = 0.0
    goals_sent: int = 0
    ended: dict[str, int] = field(default_factory=dict)
    stalls: list[str] = field(default_factory=list)
    start: dict[str, Usage] = field(default_factory=dict)
    end: dict[str, Usage] = field(default_factory=dict)
    dead: list[str] = field(default_factory=list)
    # Each node's RSS (KiB) every SAMPLE_SIM_S of simulated time from the start.
    rss_samples: dict[str, list[int]] = field(default_factory=dict)

    def growth(self) -> dict[str, float]:
        """Each node's RSS growth from the start to the end, %."""
        return {n: 100.0 * (self.end[n].rss_kib - u.rss_kib) / u.rss_kib
                for n, u in self.start.items() if n in self.end}

    def cpu_share(self) -> dict[str, float]:
        """Each node's CPU from the start to the end, % of one core over the wall time."""
        span = max(self.wall_s, 1e-9)
        return {n: 100.0 * (self.end[n].cpu_s - u.cpu_s) / span
                for n, u in self.start.items() if n in self.end}

    def text(self) -> str:
        lines = [f"soak: {self.sim_s / 60:.1f} simulated min in {self.wall_s / 60:.1f} wall min "
                 f"({self.sim_s / max(self.wall_s, 1e-9):.2f}×); {self.goals_sent} goals sent, ended: "
                 + ", ".join(f"{k} {v}" for k, v in sorted(self.ended.items()))]
        for n, u in self.start.items():
            e = self.end.get(n)
            if e:
                lines.append(f"  {n}: RSS {u.rss_kib / 1024:.1f} → {e.rss_kib / 1024:.1f} MiB "
                             f"({self.growth()[n]:+.1f} %), CPU {self.cpu_share()[n]:.1f} % of a core")
        for n, samples in self.rss_samples.items():
            lines.append(f"  {n} RSS every {SAMPLE_SIM_S:.0f} simulated s (MiB): "
                         + " ".join(f"{k / 1024:.1f}" for k in samples))
        lines.append(f"  stalls: {self.stalls or 'none'}; nodes dead: {self.dead or 'none'}")
        return "\n".join(lines)


def usage(pid: int) -> Usage:
    with open(f"/proc/{pid}/status") as f:
        rss = next(int(line.split()[1]) for line in f if line.startswith("VmRSS:"))
    with open(f"/proc/{pid}/stat") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    ticks = os.sysconf("SC_CLK_TCK")
    return Usage(rss, (int(fields[11]) + int(fields[12])) / ticks)


class Loop:
    """The goals of the loop, each sent when the one before ended."""

    def __init__(self, node: Any) -> None:
        from nav2_msgs.action import DockRobot, FollowWaypoints, NavigateToPose, UndockRobot
        from action_client import ActionClient
        self.clients = {
            "navigate_to_pose": ActionClient(node, NavigateToPose, "navigate_to_pose"),
            "follow_waypoints": ActionClient(node, FollowWaypoints, "follow_waypoints"),
            "dock_robot": ActionClient(node, DockRobot, "dock_robot"),
            "undock_robot": ActionClient(node, UndockRobot, "undock_robot"),
        }
        self.goals = [
            ("navigate_to_pose", NavigateToPose.Goal(pose=pose(*NAV_GOALS[0]))),
            ("navigate_to_pose", NavigateToPose.Goal(pose=pose(*NAV_GOALS[1]))),
            ("follow_waypoints", FollowWaypoints.Goal(poses=[pose(x, y) for x, y in VFO_ROUTE])),
            ("dock_robot", DockRobot.Goal(use_dock_id=False, dock_pose=pose(DOCK[0], DOCK[1], yaw=DOCK[2]))),
            ("undock_robot", UndockRobot.Goal(max_undocking_time=30.0)),
            ("navigate_to_pose", NavigateToPose.Goal(pose=pose(*NAV_GOALS[1]))),
        ]
        self.next = 0

    def wait_for_servers(self) -> None:
        for name, client in self.clients.items():
            if not client.wait_for_server(timeout_sec=30.0):
                raise RuntimeError(f"{name} server not found")

    def send(self) -> tuple[str, Any]:
        """The next goal of the loop, sent until accepted (a response lost in discovery is sent
        again); its name and its result future."""
        name, goal = self.goals[self.next % len(self.goals)]
        self.next += 1
        for _ in range(4):
            future = self.clients[name].send_goal_async(goal)
            if rosutil.wait_until(future.done, 3.0):
                handle = future.result()
                if not handle.accepted:
                    raise RuntimeError(f"{name} refused a goal of the loop")
                return name, handle.get_result_async()
        raise RuntimeError(f"{name}: no goal response")


def run(sim_s: float, log_dir: Path, factor: float = FACTOR, warm_up_s: float = WARM_UP_SIM_S,
        progress: bool = False, niceness: int = 0) -> Report:
    """Runs the soak for ``sim_s`` simulated seconds after ``warm_up_s`` of warm-up; every
    process at ``niceness`` at least (the suite's short soak yields the CPU to the real-time
    tests beside it)."""
    import rclpy
    from action_msgs.msg import GoalStatus
    rosutil.setup_process_environment()
    os.environ.setdefault("ROS_DOMAIN_ID", str(int(time.time()) % 90 + 10))
    own_rclpy = not rclpy.ok()
    if own_rclpy:
        rclpy.init()
    node = rclpy.create_node("soak_driver")
    spinner = rosutil.Spinner(node, context=node.context).start()
    names = ("sim_node", "chassis_node", "local_nav_node", "planner_node")
    def launch(exe: str, *args: str, params_file: Any = None, niceness: int = 0, **kw: Any) -> Any:
        return harness.launch_node(exe, *args, log_dir=log_dir, params_file=params_file,
                                   niceness=max(niceness, nice), **kw)

    nice = niceness
    procs = harness.launch_scenario(PARAMS, real_time_factor=factor, nodes=names[1:], lidar=True,
                                    launch=launch)
    report = Report()
    statuses = {GoalStatus.STATUS_SUCCEEDED: "succeeded", GoalStatus.STATUS_ABORTED: "aborted",
                GoalStatus.STATUS_CANCELED: "canceled"}
    try:
        with harness.SimClock(node) as clock:
            clock.wait_started(timeout=30.0)
            loop = Loop(node)
            loop.wait_for_servers()
            started_wall = None
            next_sample = math.inf
            begin_sim = clock.now() + warm_up_s
            end_sim = begin_sim + sim_s
            name, result = loop.send()
            sent_at = clock.now()
            report.goals_sent = 1
            last_clock = (clock.now(), time.monotonic())
            while True:
                time.sleep(0.05)
                now_sim, now_wall = clock.now(), time.monotonic()
                if now_sim > last_clock[0]:
                    last_clock = (now_sim, now_wall)
                elif now_wall - last_clock[1] > 1.0:
                    report.stalls.append(f"/clock stood still {now_wall - last_clock[1]:.1f} s at "
                                         f"{now_sim:.1f} s simulated")
                    last_clock = (now_sim, now_wall)
                if started_wall is None and now_sim >= begin_sim:
                    started_wall = now_wall
                    report.start = {p.name: usage(p.pid) for p in procs}
                    next_sample = begin_sim
                if started_wall is not None and now_sim >= next_sample:
                    next_sample += SAMPLE_SIM_S
                    for p in procs:
                        if p.running:
                            report.rss_samples.setdefault(p.name, []).append(usage(p.pid).rss_kib)
                if result.done():
                    r = result.result()
                    outcome = f"{name} {statuses.get(r.status, r.status)}"
                    code = getattr(r.result, "error_msg", "").split(":")[0]
                    if r.status != GoalStatus.STATUS_SUCCEEDED and code:
                        outcome += f" ({code})"
                    report.ended[outcome] = report.ended.get(outcome, 0) + 1
                    if progress:
                        print(f"{now_sim:8.1f} s: {outcome}", flush=True)
                    if now_sim >= end_sim:
                        break
                    name, result = loop.send()
                    sent_at = now_sim
                    report.goals_sent += 1
                elif now_sim - sent_at > ALLOWANCE_SIM_S[name]:
                    report.stalls.append(f"{name}: no result {ALLOWANCE_SIM_S[name]:.0f} s after it was sent "
                                         f"(at {sent_at:.1f} s simulated)")
                    break
                if not all(p.running for p in procs):
                    break
            report.end = {p.name: usage(p.pid) for p in procs if p.running}
            report.dead = [p.name for p in procs if not p.running]
            report.sim_s = max(0.0, clock.now() - begin_sim)
            report.wall_s = time.monotonic() - (started_wall or time.monotonic())
    finally:
        spinner.stop()
        node.destroy_node()
        for p in reversed(procs):
            try:
                p.stop()
            except harness.NodeProcessError as exc:
                report.dead.append(f"{p.name}: {exc}")
        if own_rclpy:
            rclpy.try_shutdown()
    return report


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--sim-minutes", type=float, default=30.0)
    parser.add_argument("--factor", type=float, default=FACTOR)
    parser.add_argument("--json", type=Path, help="also write the report here")
    args = parser.parse_args()
    log_dir = Path(tempfile.mkdtemp(prefix="mobil-soak-"))
    report = run(args.sim_minutes * 60.0, log_dir, args.factor, progress=True)
    print(report.text())
    print(f"logs: {log_dir}")
    if args.json:
        data = asdict(report) | {"growth_percent": report.growth(), "cpu_percent": report.cpu_share()}
        args.json.write_text(json.dumps(data, indent=2))
    ok = not report.stalls and not report.dead and all(g < 5.0 for g in report.growth().values())
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
