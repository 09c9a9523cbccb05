#!/usr/bin/env python3
"""Start-up stress: many nodes started at once, again and again. Each round starts ``--nodes``
processes together (sim_node, chassis_node, local_nav_node, planner_node, terrain_node and
gait_node in turn, each under a name of its own), waits for every one to log that it is up, then
stops them all with SIGINT; a node that does not come up within ``--up-timeout`` or does not exit
within 5 s is a failure, reported with where its threads were (gdb, when installed).

    .venv/bin/python tests/stress_startup.py --rounds 50 --nodes 13

It is how a start-up stall of RustDDS's discovery was caught and shown gone (patches/README.md,
"a node hangs at start-up when many nodes start together"); docs/performance.md has the last
figures.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import harness  # noqa: E402
import rosutil  # noqa: E402

EXECUTABLES = [
    ("sim_node", ("-p", "lidar.enabled:=false"), "params/omr3.yaml"),
    ("chassis_node", (), "params/omr3.yaml"),
    ("local_nav_node", (), "params/omr3.yaml"),
    ("planner_node", ("-p", "world_file:=none"), "params/omr3.yaml"),
    ("terrain_node", (), "params/hexapod.yaml"),
    ("gait_node", (), "params/quadruped.yaml"),
]


def round_(k: int, count: int, log_dir: Path, up_timeout: float) -> tuple[list[float], list[str]]:
    """One round: the seconds each node took to come up, and the failures."""
    procs = []
    for i in range(count):
        exe, args, params = EXECUTABLES[i % len(EXECUTABLES)]
        procs.append(harness.launch_node(exe, *args, "-r", f"__ns:=/stress{i}", log_dir=log_dir,
                                         params_file=params, name=f"r{k}_{exe}_{i}"))
    started = time.monotonic()
    times, failures = [], []
    for p in procs:
        try:
            p.wait_for_log(r" up on ROS_DOMAIN_ID", timeout=max(0.0, up_timeout - (time.monotonic() - started)))
            times.append(time.monotonic() - started)
        except (TimeoutError, harness.NodeProcessError) as exc:
            stacks = harness.thread_stacks(p.pid) if p.running else ""
            failures.append(f"round {k}: {p.name} not up: {str(exc).splitlines()[0]}\n{stacks[:4000]}")
    for p in procs:
        try:
            p.stop()
        except harness.NodeProcessError as exc:
            failures.append(f"round {k}: {str(exc)[:4000]}")
    return times, failures


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--rounds", type=int, default=50)
    parser.add_argument("--nodes", type=int, default=13)
    parser.add_argument("--up-timeout", type=float, default=15.0)
    args = parser.parse_args()
    rosutil.setup_process_environment()
    os.environ.setdefault("ROS_DOMAIN_ID", str(int(time.time()) % 90 + 10))
    log_dir = Path(tempfile.mkdtemp(prefix="mobil-stress-"))
    all_times, all_failures = [], []
    began = time.monotonic()
    for k in range(args.rounds):
        times, failures = round_(k, args.nodes, log_dir, args.up_timeout)
        all_times += times
        all_failures += failures
        print(f"round {k}: {len(times)}/{args.nodes} up, slowest {max(times, default=0):.2f} s"
              + (f", {len(failures)} failure(s)" if failures else ""), flush=True)
    print(f"stress: {args.rounds} rounds of {args.nodes} nodes started together in "
          f"{time.monotonic() - began:.0f} s; {len(all_times)} came up "
          f"(median {statistics.median(all_times) if all_times else 0:.2f} s, "
          f"slowest {max(all_times, default=0):.2f} s); {len(all_failures)} failure(s); logs {log_dir}")
    for f in all_failures:
        print(f)
    return 1 if all_failures else 0


if __name__ == "__main__":
    sys.exit(main())
