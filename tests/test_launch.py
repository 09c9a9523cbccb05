"""The launch scripts a user runs: one per robot (all nodes up, all gone on Ctrl-C) and the demo."""

from __future__ import annotations

import os
import re
import signal
import subprocess
import time
from pathlib import Path
from typing import Optional

import pytest

import harness
from harness import ROOT

from rcl_interfaces.srv import DescribeParameters


def _pids_of(name: str, session: Optional[int] = None) -> set[int]:
    """PIDs of processes called ``name`` (in the session ``session`` only, if given: other
    programs on the machine may run the same executables)."""
    cmd = ["pgrep", "-x", name] + (["-s", str(session)] if session is not None else [])
    out = subprocess.run(cmd, capture_output=True, text=True)
    return {int(p) for p in out.stdout.split()}


def _script_env() -> dict[str, str]:
    env = harness.rosutil.ros_environ()
    env["MOBIL_SKIP_BUILD"] = "1"  # tests/run_all built the executables already
    env["MOBIL_BIN_DIR"] = str(harness.BIN_DIR)
    return env


@pytest.mark.parametrize("robot,model,how", [("omr3", "omni", "ctrl-c"), ("tricycle", "tricycle", "sigterm")])
def test_robot_script_starts_its_nodes_and_stopping_it_stops_them_all(robot, model, how, tmp_path):
    log = open(tmp_path / "launch.log", "wb")
    script = subprocess.Popen([str(ROOT / "launch_scripts" / robot), "-r", "__ns:=/launch_test"],
                              env=_script_env(), stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        # As a user checks it: `ros2 topic echo` / `ros2 param get` from a new process
        # (participant). The test session's long-lived participant is not used here: after many
        # nodes came and went, it sometimes never matches newly launched nodes (seen with Fast DDS
        # 2.14.5 from PyPI, with this suite's binaries of before and after; a fresh participant
        # always matches).
        echo = harness.run_ros2cli("topic", "echo", "/launch_test/odom", "--once", "--timeout", "20", timeout=40)
        assert echo.returncode == 0, echo.stdout + echo.stderr
        assert "frame_id: odom" in echo.stdout, echo.stdout
        for node_name in ("chassis", "sim"):
            # (--timeout: ros2cli's 5 s default is short for a machine running builds beside.)
            result = harness.run_ros2cli("param", "get", f"/launch_test/{node_name}", "model",
                                         "--timeout", "20", timeout=40)
            assert result.returncode == 0, result.stdout + result.stderr
            assert result.stdout.strip().splitlines()[-1] == f"String value is: {model}", result.stdout
        # The script runs in a session of its own (start_new_session), and so do its nodes.
        started = _pids_of("sim_node", script.pid) | _pids_of("chassis_node", script.pid)
        assert len(started) == 2, started
        if how == "ctrl-c":
            # Ctrl-C in a terminal signals the whole foreground process group.
            os.killpg(script.pid, signal.SIGINT)
        else:
            # A process manager stops the script alone; it must take its nodes with it.
            script.send_signal(signal.SIGTERM)
        assert script.wait(timeout=10) in (0, 130, 143)
        # Cleanly: each node logged its own shutdown (no SIGKILL was needed).
        assert harness.wait_until(lambda: (tmp_path / "launch.log").read_text().count("shut down") == 2, timeout=5)
        assert harness.wait_until(lambda: not (started & (_pids_of("sim_node") | _pids_of("chassis_node"))),
                                  timeout=5), "nodes left running"
    finally:
        if script.poll() is None:
            os.killpg(script.pid, signal.SIGKILL)
        log.close()


@pytest.mark.closed_loop  # the demo runs sim_node at 3x and 8x with the nodes in its loop
@pytest.mark.timeout(170)
def test_demo_drives_the_route_and_plots_it():
    out = subprocess.run([str(ROOT / "launch_scripts" / "demo")], env=_script_env(), capture_output=True,
                         text=True, timeout=160)
    assert out.returncode == 0, out.stdout + out.stderr
    m = re.search(r"demo: drove ([\d.]+) m; final odometry error ([\d.]+) m", out.stdout)
    assert m, out.stdout
    driven, error = float(m.group(1)), float(m.group(2))
    # The loop: 2·2 m + 2·1 m straights and four quarter circles of radius 1 m = 6 + 2π = 12.28 m at
    # the rear axle; the reference point 0.30 m ahead runs slightly longer through the corners.
    assert 12.2 < driven < 12.8
    # Encoders in the demo read 0.5 % fast with 2 % noise: drift of a few centimetres.
    assert error < 0.02 * driven
    svg = (ROOT / "demo_out" / "mobil2_run.svg").read_text()
    assert "ground truth" in svg and "odometry" in svg and svg.count("<polyline") >= 2
    # Third act: the planner's route and docking on the car-like MOBIL-II.
    assert "pre-check: route of 5 waypoints feasible" in out.stdout, out.stdout
    m = re.search(r"demo: planner followed 5 waypoints \((\d+) missed\) in ([\d.]+) simulated s, docking ended "
                  r"after [\d.]+ s at e ([\d.]+) m, heading error ([\d.]+) rad \(RESIDUAL: a steered chassis", out.stdout)
    assert m, out.stdout
    missed, route_s, e, heading = int(m.group(1)), float(m.group(2)), float(m.group(3)), float(m.group(4))
    assert missed == 0, out.stdout + out.stderr
    # The straight legs from (3, 3.9) through the waypoints sum to 10.50 m; each may end
    # Z_crit = 0.16 m short and the start lies within 0.14 m of (3, 3.9): at least 9.56 m at no
    # more than the planner's 0.3 m/s cruise speed, 31.9 s; the turns and the slow-down add.
    assert 31.0 < route_s < 60.0
    # A car ends near the dock with a residual (e ≈ 0.07 m, 0.14 rad in mobil_planner's own
    # simulation of this docking), never docked.
    assert e < 0.2 and heading < 0.6
    svg = (ROOT / "demo_out" / "mobil2_planner.svg").read_text()
    assert "V = ½(λe² + α² + hΘ²)" in svg and 'stroke-dasharray="8 5"' in svg, svg[:2000]


def test_describe_parameters_answers_a_stock_client(start_node, ros_node):
    start_node("chassis_node", params_file="params/mobil2.yaml")
    client = ros_node.create_client(DescribeParameters, "/chassis/describe_parameters")
    assert client.wait_for_service(timeout_sec=10)
    req = DescribeParameters.Request(names=["v_max", "model"])
    for _ in range(5):  # the first call after discovery can be lost (ROS2-NOTES)
        future = client.call_async(req)
        deadline = time.monotonic() + 2
        while not future.done() and time.monotonic() < deadline:
            time.sleep(0.01)
        if future.done():
            break
    result = future.result()
    assert [d.name for d in result.descriptors] == ["v_max", "model"]
    # rcl_interfaces/ParameterType: PARAMETER_DOUBLE = 3, PARAMETER_STRING = 4.
    assert [d.type for d in result.descriptors] == [3, 4]
