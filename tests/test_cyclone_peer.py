"""A Cyclone DDS peer (tests/cyclone_peer.py: Eclipse Cyclone DDS from the `cyclonedds` wheel,
speaking as rmw_cyclonedds_cpp does) against sim_node + chassis_node + drive_node: odom and scan
received, cmd_vel obeyed, a parameter call answered (small, and large enough for DATA_FRAGs),
and a drive_distance goal accepted and finished. Meanwhile an rclpy (Fast DDS) client calls the
same parameter service over and over: every answer each client gets must be its own, in its own
request/reply layout (mobil's servers choose it per request, patches/README.md).
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
