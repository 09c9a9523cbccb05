"""A Cyclone DDS peer (tests/cyclone_peer.py: Eclipse Cyclone DDS from the `cyclonedds` wheel,
speaking as rmw_cyclonedds_cpp does) against sim_node + chassis_node + drive_node: odom and scan
received, cmd_vel obeyed, a parameter call answered (small, and large enough for DATA_FRAGs),
and a drive_distance goal accepted and finished. Meanwhile an rclpy (Fast DDS) client calls the
same parameter service over and over: every answer each client gets must be its own, in its own
request/reply layout (mobil's servers choose it per request, patches/README.md).

The other way round, the peer serves `gait/compute_plan` as a Cyclone DDS server and mobil's
client (gait_demo) calls it: the client sends in the Cyclone layout when every server it
reaches is Cyclone DDS, and reads the Cyclone reply.
"""

from __future__ import annotations

import json
import subprocess
import sys
import threading
import time

import pytest

import harness
import rosutil
from harness import ROOT

cyclonedds = pytest.importorskip("cyclonedds")

PARAMS = "params/omr3.yaml"


@pytest.mark.closed_loop  # a real-time drive: never beside the demo or the soak (RUNNING_ALONE)
def test_cyclone_peer_reads_commands_calls_a_service_and_an_action(start_node, ros_node, ros_domain_id):
    start_node("sim_node", params_file=PARAMS)  # with the LIDAR: rt/scan, 1081 beams
    start_node("chassis_node", params_file=PARAMS)
    start_node("drive_node")

    # The rclpy client, calling chassis' get_parameters throughout the peer's run.
    from rcl_interfaces.srv import GetParameters
    answers: list[float] = []
    errors: list[str] = []
    stop = threading.Event()

    def fast_dds_client() -> None:
        while not stop.is_set():
            try:
                # Strings and a double: a reply that a Cyclone client would misread as its own
                # (a header, then values) would not decode to these.
                r = rosutil.call_service(ros_node, GetParameters, "/chassis/get_parameters",
                                         GetParameters.Request(names=["odom_frame", "v_max", "model"]),
                                         timeout=10.0)
                answers.append((r.values[0].string_value, r.values[1].double_value, r.values[2].string_value))
            except Exception as e:  # noqa: BLE001 - reported below
                errors.append(repr(e))
            time.sleep(0.05)

    thread = threading.Thread(target=fast_dds_client, daemon=True)
    thread.start()
    try:
        peer = subprocess.run(
            [sys.executable, str(ROOT / "tests" / "cyclone_peer.py"), "--domain", str(ros_domain_id)],
            capture_output=True, text=True, timeout=120, env=rosutil.ros_environ())
    finally:
        stop.set()
        thread.join(timeout=15)
    steps = {}
    for line in peer.stdout.splitlines():
        if line.startswith("{"):
            record = json.loads(line)
            steps[record["step"]] = record
    assert peer.returncode == 0, f"peer failed:\n{peer.stdout}\n{peer.stderr[-3000:]}"
    assert set(steps) == {"odom", "scan", "cmd_vel", "get_parameters", "get_parameters_large",
                          "send_goal", "get_result"}, steps
    assert steps["scan"]["beams"] == 1081
    v_max = harness.param_get(ros_node, "chassis", "v_max")
    expected = (harness.param_get(ros_node, "chassis", "odom_frame"), v_max,
                harness.param_get(ros_node, "chassis", "model"))
    # The small call: v_max (a double, type 3) and model (a string, type 4) as params give them.
    assert steps["get_parameters"]["values"][0] == [3, v_max, ""]
    assert steps["get_parameters"]["values"][1][0] == 4
    assert steps["get_result"]["reason"] == "reached"
    assert abs(steps["get_result"]["travelled"] - 0.2) < 0.03
    # The Fast DDS client got answers all along, each its own (v_max), none lost.
    assert not errors, errors[:3]
    assert len(answers) >= 10 and all(a == expected for a in answers), answers[:10]


def test_mobil_client_calls_a_cyclone_server(tmp_path, ros_domain_id):
    env = rosutil.ros_environ(domain_id=ros_domain_id)
    peer = subprocess.Popen(
        [sys.executable, str(ROOT / "tests" / "cyclone_peer.py"), "--serve-gait", "25"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env)
    try:
        assert peer.stdout is not None
        ready = peer.stdout.readline()
        assert '"ready"' in ready, ready + (peer.stderr.read() if peer.poll() is not None else "")
        svg = tmp_path / "gait.svg"
        demo = subprocess.run(
            [str(harness.resolve_executable("gait_demo")), "--ros-args", "-p", f"output_svg:={svg}",
             "-p", "timeout_s:=20.0"],
            capture_output=True, text=True, timeout=60, env=env)
    finally:
        peer.terminate()
        out, err = peer.communicate(timeout=15)
    requests = [json.loads(line) for line in out.splitlines() if line.startswith("{")]
    assert demo.returncode == 0, f"{demo.stdout}\n{demo.stderr[-3000:]}\npeer: {out}\n{err[-2000:]}"
    # Every request decoded in the Cyclone layout: a header (seq from 1), then gait_demo's own
    # request (experiment B,(3) to (-10, 10)); a Fast DDS-layout request would not decode so.
    assert requests and all(r["ok"] for r in requests), requests
    first = requests[0]
    assert first["seq"] >= 1 and first["rule_set"] == "B" and first["evaluation"] == 3, first
    assert first["goal"] == [-10.0, 10.0], first
    # ... and gait_demo read the Cyclone reply: the peer's plan, its 2 states, 7 and 11.
    assert "2 states" in demo.stdout and "7 expanded, 11 generated" in demo.stdout, demo.stdout
    assert svg.is_file()
