#!/usr/bin/env python3
"""Throughput of `ga_step --evaluator ros` with 1, 2 and 4 simulators (tests/fake_ga_sim.py,
each taking DELAY s an evaluation, all on this host): candidates answered per second from the
first answer to the last, and the ratio to one simulator.

    .venv/bin/python tests/bench_ga_pool.py [--delay 0.1] [--population 20] [--generations 2]

A benchmark, not a test: it prints figures. ROS_DOMAIN_ID is taken from the environment (a
domain of its own is best); ga_step from MOBIL_BIN_DIR (default target/release).
"""
from __future__ import annotations

import argparse
import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rosutil  # noqa: E402

ROOT = Path(__file__).resolve().parent
BIN = Path(os.environ.get("MOBIL_BIN_DIR", ROOT.parent / "target" / "release")) / "ga_step"


def run(k: int, delay: float, population: int, generations: int, tmp: Path) -> tuple[int, float]:
    logs = [tmp / f"k{k}_sim{i}.log" for i in range(k)]
    sims = [subprocess.Popen([sys.executable, str(ROOT / "fake_ga_sim.py"), "--ns", f"/bench/sim{i}",
                              "--delay", str(delay), "--log", str(log)],
                             env=rosutil.ros_environ(), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
            for i, log in enumerate(logs)]
    try:
        time.sleep(2.0)
        out = subprocess.run([str(BIN), "--population", str(population), "--generations", str(generations),
                              "--seed", "1", "--crossover", "blx", "--evaluator", "ros", "--pool", "--eval-timeout", "10",
                              "--out", str(tmp / f"k{k}"), "--ros-args", "-r", "__ns:=/bench"],
                             env=rosutil.ros_environ(), capture_output=True, text=True, timeout=600)
        if out.returncode != 0:
            raise SystemExit(f"ga_step failed with {k} simulators:\n{out.stderr}")
    finally:
        for s in sims:
            s.terminate()
        for s in sims:
            try:
                s.wait(timeout=10)
            except subprocess.TimeoutExpired:
                s.kill()
                s.wait()
    times = sorted(float(line.split()[0]) for log in logs if log.exists() for line in log.read_text().splitlines())
    if len(times) < 2 or times[-1] <= times[0]:
        raise SystemExit(f"{k} simulators answered {len(times)} candidates: nothing to measure")
    return len(times), (len(times) - 1) / (times[-1] - times[0])


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--delay", type=float, default=0.1)
    parser.add_argument("--population", type=int, default=20)
    parser.add_argument("--generations", type=int, default=2)
    args = parser.parse_args()
    print(f"simulators | candidates | candidates/s | ratio to 1 | ideal (1/delay each) ({args.delay} s an evaluation)")
    base = None
    with tempfile.TemporaryDirectory() as d:
        for k in (1, 2, 4):
            n, rate = run(k, args.delay, args.population, args.generations, Path(d))
            base = base or rate
            print(f"{k} | {n} | {rate:.2f} | {rate / base:.2f} | {k / args.delay:.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
