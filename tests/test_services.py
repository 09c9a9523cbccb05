"""Service replies of any size, from a Rust node's service to rclpy (ROS 2 Jazzy, Fast DDS).

A reply larger than one UDP datagram (about 1.4 KB) travels as DATA_FRAG submessages, each with
the request's identity in its inline QoS (PID_RELATED_SAMPLE_IDENTITY), by which rmw_fastrtps
matches the reply to the call. RustDDS 0.15.1 wrote that inline QoS one byte off (see
patches/README.md), so Fast DDS dropped every fragment of every such reply, and the reliable
reply writer then held all later replies behind the lost one.

The carrier is the standard parameter service ``get_parameters`` of ``chassis_node``, asked for
the same few parameters over and over: the reply grows with the number of names (56 bytes a
value as CDR, about five times the request), every value is known from params/mobil2.yaml, and the order of
the values shows that the fragments were put together in order.
"""

from __future__ import annotations

import math
import time

import pytest
import yaml

import harness
import rosutil
from harness import ROOT, param_get

from rcl_interfaces.srv import GetParameters
from rclpy.serialization import serialize_message

PARAMS_FILE = "params/mobil2.yaml"
# Parameters of `chassis` in params/mobil2.yaml, of every type the reply carries: strings of
# several lengths (so the values do not all share one alignment), doubles and a bool.
NAMES = ["model", "wheelbase", "odom_frame", "v_max", "base_frame", "publish_tf", "track"]


def expected_values() -> dict[str, object]:
    """The values of NAMES as params/mobil2.yaml sets them for the node `chassis`."""
    doc = yaml.safe_load((ROOT / PARAMS_FILE).read_text())
    values = {**doc["/**"]["ros__parameters"], **doc["chassis"]["ros__parameters"]}
    return {name: values[name] for name in NAMES}


def names_for_reply_of(size: int, expected: dict[str, object]) -> list[str]:
    """NAMES repeated (whole cycles) so that the reply is at least ``size`` bytes, as rclpy
    serialises a GetParameters response holding the expected values."""
    one_cycle = GetParameters.Response(
        values=[rosutil.parameter_value_from_python(expected[n]) for n in NAMES])
    # 4 bytes of encapsulation header and 4 of sequence length, then the values.
    per_cycle = len(serialize_message(one_cycle)) - 8
    cycles = max(1, math.ceil((size - 8) / per_cycle))
    return NAMES * cycles


def get_parameters_once(node, names: list[str], timeout: float):
    """One `get_parameters` call, no retry: returns (response, seconds)."""
    start = time.monotonic()
    response = rosutil.call_service(
        node, GetParameters, "/chassis/get_parameters", GetParameters.Request(names=names),
        timeout=timeout, attempt_timeout=timeout)
    return response, time.monotonic() - start


@pytest.mark.timeout(150)
def test_replies_of_1_kb_64_kb_and_1_mb_arrive_and_later_calls_still_answer(start_node, ros_node):
    start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file=PARAMS_FILE)
    assert harness.wait_for_node(ros_node, "/chassis", timeout=10)
    expected = expected_values()
    # A small call first: it matches the client (its first request may wait for a heartbeat).
    assert param_get(ros_node, "/chassis", "v_max") == 0.5

    timings = []
    for size in (1_000, 64_000, 1_000_000):
        names = names_for_reply_of(size, expected)
        # The reply as rclpy serialises it: at least `size`, within one cycle of names of it.
        want = GetParameters.Response(
            values=[rosutil.parameter_value_from_python(expected[n]) for n in names])
        wire = len(serialize_message(want))
        assert size <= wire < size + 400, (size, wire)
        response, seconds = get_parameters_once(ros_node, names, timeout=30.0)
        got = [rosutil.parameter_value_to_python(v) for v in response.values]
        assert len(got) == len(names), f"{wire}-byte reply: {len(got)} values of {len(names)}"
        assert got == [expected[n] for n in names], f"{wire}-byte reply: values out of place"
        timings.append((wire, seconds))
        # A small call right after a large reply still answers, and quickly.
        small, seconds = get_parameters_once(ros_node, ["v_max"], timeout=10.0)
        assert [rosutil.parameter_value_to_python(v) for v in small.values] == [0.5]
        assert seconds < 5.0, f"small call after a {wire}-byte reply took {seconds:.2f} s"
    print("reply bytes, seconds:", ", ".join(f"{w} {s:.3f}" for w, s in timings))


@pytest.mark.timeout(90)
def test_reply_just_above_one_datagram_arrives(start_node, ros_node):
    """Around the size where RustDDS starts to send the reply as DATA_FRAG (between 26 and 27
    values here), and a little above: each reply followed by a small call."""
    start_node("chassis_node", "-p", "feedback_timeout_s:=0.0", params_file=PARAMS_FILE)
    assert harness.wait_for_node(ros_node, "/chassis", timeout=10)
    assert param_get(ros_node, "/chassis", "v_max") == 0.5
    # 8 bytes of encapsulation and length, 56 bytes a double value (type, bool, int64, double,
    # empty string, five empty sequences, CDR-aligned): 1464, 1520, 2248 and 3368 bytes.
    for count in (26, 27, 40, 60):
        names = ["v_max"] * count
        response, _ = get_parameters_once(ros_node, names, timeout=10.0)
        assert [rosutil.parameter_value_to_python(v) for v in response.values] == [0.5] * count
        assert len(serialize_message(response)) == 8 + 56 * count
        assert param_get(ros_node, "/chassis", "wheelbase", timeout=10.0) == 0.6
