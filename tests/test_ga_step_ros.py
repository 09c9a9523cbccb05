"""ga_step --evaluator ros against a fake simulator in rclpy.

The fake subscribes to ga_step/candidate (trajectory_msgs/JointTrajectory) and answers on
ga_step/outcome (sensor_msgs/JointState, the candidate's header echoed) by a rule the test can
work out: the robot falls at 1.5 s when a knee knot (RKneePitch or LKneePitch) exceeds 1.8 rad,
and moves forward 0.01 m per radian of the mean RKneePitch knot (under 0.023 m: never the 0.04 m
"forward step" that would stop the run). Before each answer after the first it sends a stale one,
the previous candidate's header with an upright 5 m, which would score 1 + 2·(5 + 1) = 13.
ga_step runs under a namespace given as a ROS argument, for 2 generations of 6.
"""

from __future__ import annotations

import csv
import json
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

from rclpy.qos import QoSDurabilityPolicy, QoSProfile, QoSReliabilityPolicy
from sensor_msgs.msg import JointState
from trajectory_msgs.msg import JointTrajectory

import harness
import rosutil

NS = "/gatest"
T_SIM = 3.0  # step time 2 s + settle time 1 s
W, B = 2.0, 1.0  # forward weight (1/m) and backward allowance (m), params/nao_step.yaml


def fake_rule(msg: JointTrajectory) -> tuple[bool, float, float]:
    """(fell, fall_time, forward_distance) of a candidate."""
    knees = [p.positions[2] for p in msg.points] + [p.positions[7] for p in msg.points]
    fell = max(knees) > 1.8
    forward = 0.01 * sum(p.positions[2] for p in msg.points) / len(msg.points)
    return fell, (1.5 if fell else 0.0), forward


def fitness(fell: bool, fall_time: float, forward: float) -> float:
    """The fitness formula of params/nao_step.yaml, worked out here."""
    return fall_time / T_SIM if fell else 1.0 + W * max(0.0, forward + B)


def test_ga_step_evaluates_through_a_simulator_and_ignores_stale_answers(ros_node: Any, tmp_path: Path) -> None:
    qos = QoSProfile(depth=10, reliability=QoSReliabilityPolicy.RELIABLE,
                     durability=QoSDurabilityPolicy.VOLATILE)
    outcomes = ros_node.create_publisher(JointState, f"{NS}/ga_step/outcome", qos)
    scored: list[float] = []
    frames: list[str] = []
    previous: list[Any] = []
    lock = threading.Lock()

    def on_candidate(msg: JointTrajectory) -> None:
        fell, t, dx = fake_rule(msg)
        with lock:
            if msg.header.frame_id in frames:
                return  # a candidate sent again after a simulator restart: answered already
            frames.append(msg.header.frame_id)
            scored.append(fitness(fell, t, dx))
            if previous:
                stale = JointState(header=previous[-1], name=["fell", "forward_distance"],
                                   position=[0.0, 5.0])
                outcomes.publish(stale)
            previous.append(msg.header)
        names, values = ["fell", "forward_distance"], [1.0 if fell else 0.0, dx]
        if fell:
            names.append("fall_time")
            values.append(t)
        outcomes.publish(JointState(header=msg.header, name=names, position=values))

    ros_node.create_subscription(JointTrajectory, f"{NS}/ga_step/candidate", on_candidate, qos)

    out = tmp_path / "run"
    cmd = [str(harness.resolve_executable("ga_step")), "--population", "6", "--generations", "2",
           "--seed", "5", "--crossover", "blx", "--out", str(out), "--evaluator", "ros",
           "--eval-timeout", "10", "--ros-args", "-r", f"__ns:={NS}"]
    started = time.monotonic()
    proc = subprocess.run(cmd, env=rosutil.ros_environ(), capture_output=True, text=True, timeout=60)
    assert proc.returncode == 0, proc.stderr
    assert time.monotonic() - started < 30

    history = json.loads((out / "checkpoint.json").read_text())["history"]
    assert [h["generation"] for h in history] == [0, 1, 2]
    counts = [h["evaluations"] for h in history]
    with lock:
        assert len(scored) == sum(counts), (counts, frames)
        assert frames == [f"candidate {i}" for i in range(1, len(frames) + 1)]
        all_scores = list(scored)
    rows = list(csv.DictReader((out / "fitness.csv").open()))
    assert len(rows) == 3
    # Best-N replacement keeps the best 6 of everything evaluated so far.
    done = 0
    for row, n in zip(rows, counts):
        done += n
        best = sorted(all_scores[:done], reverse=True)[:6]
        assert abs(float(row["max"]) - best[0]) < 1e-9, (row, best)
        assert abs(float(row["mean"]) - sum(best) / 6) < 1e-9, (row, best)
        assert abs(float(row["min"]) - best[-1]) < 1e-9, (row, best)
    # The stale answers (13) arrived and were never taken: every fitness is what the rule gives,
    # at most 3 + 2·0.0227 < 3.05.
    assert "discarded an outcome for `candidate" in proc.stderr, proc.stderr
    # Every candidate was answered: no void score.
    assert "; 0 unanswered candidates scored 0;" in proc.stdout, proc.stdout
    assert max(float(r["max"]) for r in rows) < 3.05
