#!/usr/bin/env python3
"""Summarises a comparison of crossovers run with `ga_step` (docs/experiments/ga-step-webots.md):
per run the generation of its first non-falling forward step (or none by 300), the first
upright best, best / mean / min fitness every 50 generations, the last best's outcome in the
built-in evaluator and its replay in MuJoCo (tests/mujoco_replay.py; the P-controller every
MuJoCo step, and every 20 ms as Webots runs it); then per operator the median generation of the
first step with its range, and a two-sided exact Mann–Whitney U test between the first two
operators (a run without a step by 300 counts as beyond 300, all such runs tied). A run that
neither stepped nor reached generation 300 is unfinished: shown, and left out of the statistics.

    .venv/bin/python tests/ga_comparison.py RUN_DIR...

A RUN_DIR is `ga_step`'s output directory, named `<crossover>-<seed>` (checkpoint.json,
fitness.csv, best.motion).
"""
from __future__ import annotations

import csv
import itertools
import json
import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import mujoco_replay  # noqa: E402

EVERY = 50
LAST = 300  # the experiment's last generation: a run without a step by then is censored there


def midranks(values: list[float]) -> list[float]:
    order = sorted(range(len(values)), key=lambda i: values[i])
    ranks = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            ranks[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return ranks


def u_statistic(a: list[float], b: list[float]) -> float:
    """U of sample a: the pairs (x in a, y in b) with x > y, ties counting a half."""
    ranks = midranks(a + b)
    return sum(ranks[: len(a)]) - len(a) * (len(a) + 1) / 2


def mann_whitney(a: list[float], b: list[float]) -> tuple[float, float]:
    """U of a and the exact two-sided p-value: the share of all splits of the pooled values into
    groups of len(a) and len(b) whose U is at least as far from its mean as the observed one's
    (ties kept, by enumeration)."""
    pooled = a + b
    mean = len(a) * len(b) / 2
    observed = abs(u_statistic(a, b) - mean)
    splits = 0
    extreme = 0
    for pick in itertools.combinations(range(len(pooled)), len(a)):
        chosen = set(pick)
        x = [pooled[i] for i in pick]
        y = [pooled[i] for i in range(len(pooled)) if i not in chosen]
        splits += 1
        if abs(u_statistic(x, y) - mean) >= observed - 1e-9:
            extreme += 1
    return u_statistic(a, b), extreme / splits


def summarise(run: Path) -> dict:
    checkpoint = json.loads((run / "checkpoint.json").read_text())
    rows = list(csv.DictReader((run / "fitness.csv").open()))
    last = checkpoint["generation"]
    upright = next((int(r["generation"]) for r in rows if float(r["max"]) >= 1.0), None)
    best = max(checkpoint["population"], key=lambda p: p["evaluation"]["fitness"])["evaluation"]
    times, knots = mujoco_replay.read_motion(run / "best.motion")
    mj = mujoco_replay.simulate(times, knots)
    mj20 = mujoco_replay.simulate(times, knots, control_period=0.02)
    return {
        "run": run.name,
        "crossover": run.name.rsplit("-", 1)[0],
        "first_step": checkpoint["first_step_generation"],
        "last": last,
        "first_upright": upright,
        "curve": [(int(r["generation"]), float(r["max"]), float(r["mean"]), float(r["min"])) for r in rows
                  if int(r["generation"]) % EVERY == 0 or int(r["generation"]) == last],
        "best": best,
        "mujoco": (mj, mj20),
    }


def mujoco_line(o: mujoco_replay.Outcome) -> str:
    return f"falls ({o.cause}) at {o.t_end:.2f} s, {o.dx:+.3f} m" if o.fell else f"upright, {o.dx:+.3f} m"


def outcome(e: dict) -> str:
    if e["fell"]:
        return f"falls at {e['t_fall']:.2f} s, {e['forward_distance']:+.3f} m"
    return f"upright, {e['forward_distance']:+.3f} m"


def main(argv: list[str]) -> int:
    if not argv:
        print(__doc__)
        return 2
    runs = [summarise(Path(a)) for a in argv]
    print("| run | first non-falling forward step | first upright best | best / mean / min every "
          f"{EVERY} generations | the last best | in MuJoCo | in MuJoCo, control every 20 ms |")
    print("|---|---|---|---|---|---|---|")
    for r in runs:
        if r["first_step"] is not None:
            step = str(r["first_step"])
        elif r["last"] >= LAST:
            step = f"none by {LAST}"
        else:
            step = f"none yet (unfinished at {r['last']})"
        curve = "; ".join(f"{g}: {b:.2f} / {m:.2f} / {lo:.2f}" for g, b, m, lo in r["curve"])
        print(f"| {r['run']} | {step} | {r['first_upright'] if r['first_upright'] is not None else 'none'} | "
              f"{curve} | {outcome(r['best'])} | {mujoco_line(r['mujoco'][0])} | {mujoco_line(r['mujoco'][1])} |")
    groups: dict[str, list[float]] = {}
    for r in runs:
        if r["first_step"] is not None:
            value = float(r["first_step"])
        elif r["last"] >= LAST:
            value = float(LAST + 1)  # censored: beyond 300, tied with every other such run
        else:
            print(f"{r['run']}: unfinished, left out of the statistics", file=sys.stderr)
            continue
        groups.setdefault(r["crossover"], []).append(value)
    print()
    for name, values in groups.items():
        shown = ["beyond 300" if v > LAST else int(v) for v in values]
        ordered = sorted(values)
        middle = ordered[(len(ordered) - 1) // 2 : len(ordered) // 2 + 1]
        if middle[-1] <= LAST:
            median = f"{statistics.median(values):g}"
        elif middle[0] <= LAST:
            median = f"between {middle[0]:g} and beyond {LAST}"  # one middle run censored
        else:
            median = f"beyond {LAST}"
        print(f"{name}: first step at {shown}; median {median} "
              f"({len(values)} runs, {sum(v <= LAST for v in values)} with a step)")
    names = list(groups)
    if len(names) >= 2:
        u, p = mann_whitney(groups[names[0]], groups[names[1]])
        print(f"Mann–Whitney U ({names[0]} against {names[1]}): U = {u:g}, exact two-sided p = {p:.3f}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
