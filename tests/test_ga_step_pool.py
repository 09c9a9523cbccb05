"""ga_step --evaluator ros --pool with simulators across network namespaces.

Four synthetic simulators (tests/fake_ga_sim.py, a rule of the knots, 50 ms an evaluation):
/pool/sim1 in ga_step's network namespace; /pool/sim2, /pool/sim3 and /pool/sim4 in a second one
joined to the first by a veth pair, as two hosts on a link would be. /pool/sim3 kills itself
(SIGKILL, no goodbye on the wire: it stays matched until its lease ends) when its 6th candidate
arrives, so that candidate misses its first attempt and goes elsewhere; /pool/sim4 leaves cleanly
when its 3rd arrives, so that candidate is lost with it and sent again at once. Each happens
while other candidates of the same generation are in flight. The run finishes with no void
score and writes the same fitness.csv and best.motion as a run of the same seed against one
simulator in ga_step's own namespace (the contract before the pool, without --pool).
"""

from __future__ import annotations

import os
import shutil
import subprocess
import time
from pathlib import Path
from typing import Iterator

import pytest

import harness
import rosutil

ROOT = Path(__file__).resolve().parent
FAKE = ROOT / "fake_ga_sim.py"
PYTHON = ROOT.parent / ".venv" / "bin" / "python"
# Six generations of ten: about 60 evaluations, so that each of the four simulators gets well over
# the six candidates sim3 needs to reach its end even when the pool favours the nearer ones (with
# three, a loaded run once ended before sim3 had its 6th).
RUN = ["--population", "10", "--generations", "6", "--seed", "7", "--crossover", "blx",
       "--evaluator", "ros", "--eval-timeout", "8"]


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True, timeout=10)


@pytest.fixture
def two_hosts() -> Iterator[tuple[str, str]]:
    """Two network namespaces joined by a veth pair, multicast routed over it; removed after."""
    if os.geteuid() != 0 or shutil.which("ip") is None:
        pytest.skip("network namespaces need root and iproute2's ip")
    tag = f"{os.getpid() % 100000}"
    a, b = f"mobil_ga_{tag}_a", f"mobil_ga_{tag}_b"
    va, vb = f"mga{tag}a", f"mga{tag}b"
    net = f"10.213.{os.getpid() % 250}"
    try:
        subprocess.run(["ip", "link", "del", va], capture_output=True, timeout=10)
        _ip("netns", "add", a)
        _ip("netns", "add", b)
        _ip("link", "add", va, "type", "veth", "peer", "name", vb)
        for ns, dev, host in ((a, va, 1), (b, vb, 2)):
            _ip("link", "set", dev, "netns", ns)
            _ip("-n", ns, "addr", "add", f"{net}.{host}/24", "dev", dev)
            _ip("-n", ns, "link", "set", "lo", "up")
            _ip("-n", ns, "link", "set", dev, "up", "multicast", "on")
            _ip("-n", ns, "route", "add", "224.0.0.0/4", "dev", dev)
        yield a, b
    finally:
        # The pair goes with its namespace; one left in this one (a failed move) goes here.
        subprocess.run(["ip", "link", "del", va], capture_output=True, timeout=10)
        for ns in (a, b):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=10)


def _simulator(ns: str, netns: str | None, log: Path, *extra: str) -> subprocess.Popen[bytes]:
    cmd = [str(PYTHON), str(FAKE), "--ns", ns, "--delay", "0.05", "--log", str(log), *extra]
    if netns:
        cmd = ["ip", "netns", "exec", netns, *cmd]
    return subprocess.Popen(cmd, env=rosutil.ros_environ(), stdout=subprocess.DEVNULL,
                            stderr=subprocess.PIPE)


def _stop(procs: list[subprocess.Popen[bytes]]) -> None:
    for p in procs:
        if p.poll() is None:
            p.terminate()
    for p in procs:
        try:
            p.wait(timeout=5)
        except subprocess.TimeoutExpired:
            p.kill()
            p.wait()


def _answered(log: Path) -> int:
    return len(log.read_text().splitlines()) if log.exists() else 0


def test_a_pool_across_two_hosts_survives_a_killed_simulator_and_matches_one_simulator(
        two_hosts: tuple[str, str], tmp_path: Path) -> None:
    host_a, host_b = two_hosts
    ga_step = str(harness.resolve_executable("ga_step"))

    # The reference: one simulator in ga_step's own namespace, both on this host.
    solo_log = tmp_path / "solo.log"
    solo = [_simulator("/solo", None, solo_log)]
    try:
        ref = subprocess.run([ga_step, *RUN, "--out", str(tmp_path / "solo"), "--ros-args", "-r",
                              "__ns:=/solo"], env=rosutil.ros_environ(), capture_output=True,
                             text=True, timeout=60)
    finally:
        _stop(solo)
    assert ref.returncode == 0, ref.stderr
    assert "; 0 unanswered candidates scored 0;" in ref.stdout, ref.stdout
    evaluations = _answered(solo_log)
    assert evaluations >= 60, evaluations

    # The pool: ga_step and sim1 on host A, sim2, sim3 and sim4 on host B.
    logs = [tmp_path / f"sim{i}.log" for i in (1, 2, 3, 4)]
    sims = [_simulator("/pool/sim1", host_a, logs[0]),
            _simulator("/pool/sim2", host_b, logs[1]),
            _simulator("/pool/sim3", host_b, logs[2], "--die-at", "6"),
            _simulator("/pool/sim4", host_b, logs[3], "--leave-at", "3")]
    try:
        time.sleep(2.0)  # all four discovered before the first generation, so each has work
        pool = subprocess.run(["ip", "netns", "exec", host_a, ga_step, *RUN, "--pool", "--out",
                               str(tmp_path / "pool"), "--ros-args", "-r", "__ns:=/pool"],
                              env=rosutil.ros_environ(), capture_output=True, text=True,
                              timeout=60)
        ended = [s.poll() for s in sims]
    finally:
        _stop(sims)
    assert pool.returncode == 0, pool.stderr
    assert ended[2] == -9, "sim3 should have killed itself at its 6th candidate"
    assert ended[3] == 0, "sim4 should have left at its 3rd candidate"
    assert "; 0 unanswered candidates scored 0;" in pool.stdout, pool.stdout
    # sim3 answered 5 and took a 6th to its grave: missed after the timeout, sent elsewhere.
    # sim4 answered 2 and left with its 3rd: lost at once, sent elsewhere, no attempt counted.
    answered = [_answered(log) for log in logs]
    assert answered[2] == 5 and answered[3] == 2, answered
    assert answered[0] >= 5 and answered[1] >= 5, answered
    assert sum(answered) == evaluations, (answered, evaluations)
    assert "no outcome from /pool/sim3 within 8.0 s (attempt 1 of 2)" in pool.stderr, pool.stderr
    assert "simulator /pool/sim4 left before answering; sent again" in pool.stderr, pool.stderr
    assert "no outcome from /pool/sim4" not in pool.stderr, pool.stderr
    # The same run as against one simulator: every score is the rule's, whoever computed it.
    for name in ("fitness.csv", "best.motion"):
        assert (tmp_path / "pool" / name).read_text() == (tmp_path / "solo" / name).read_text(), name
