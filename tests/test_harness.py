"""Self-test of the harness and of tests/ros2cli.py against real rclpy, without the Rust nodes.

In-process rclpy nodes play the other side; ros2cli.py runs as a subprocess in the same
ROS_DOMAIN_ID; tests/fake_node.py stands in for a node executable.
"""

from __future__ import annotations

import math
import os
import stat
import sys
import time
from pathlib import Path
from typing import Any, Callable

import pytest
import rclpy
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry, Path as PathMsg
from std_msgs.msg import String

import harness
import rosutil

TESTS = Path(__file__).resolve().parent


def yaml_docs(text: str) -> list[Any]:
    """The YAML documents `topic echo` printed (one per message)."""
    return [d for d in yaml.safe_load_all(text) if d is not None]


def start_talker(node: Any, topic: str, make: Callable[[int], Any], msg_type: type,
                 qos: Any = None, period: float = 0.1) -> Any:
    """Publish ``make(i)`` on ``topic`` every ``period`` s from ``node`` (spun in background)."""
    pub = node.create_publisher(msg_type, topic, qos or rosutil.qos_default())
    count = iter(range(1, 10**9))
    node.create_timer(period, lambda: pub.publish(make(next(count))))
    return pub


def twist(x: float, z: float) -> Twist:
    msg = Twist()
    msg.linear.x = x
    msg.angular.z = z
    return msg


def executable_script(path: Path, body: str) -> Path:
    path.write_text("#!/bin/sh\n" + body + "\n")
    path.chmod(path.stat().st_mode | stat.S_IXUSR)
    return path


# --------------------------------------------------------------------------------------------
# (a) topic echo
# --------------------------------------------------------------------------------------------

def test_echo_once_discovers_type(ros_node, ros2cli):
    start_talker(ros_node, "/selftest/chatter", lambda i: String(data=f"hello {i}"), String)
    result = ros2cli("topic", "echo", "/selftest/chatter", "--once", "--timeout", "20")
    assert result.returncode == 0, result.stderr
    docs = yaml_docs(result.stdout)
    assert len(docs) == 1
    assert docs[0]["data"].startswith("hello ")
    assert result.stdout.rstrip().endswith("---")


def test_echo_twist_with_type_and_count(ros_node, ros2cli):
    start_talker(ros_node, "selftest/cmd_vel", lambda i: twist(0.5, -1.25), Twist)
    result = ros2cli("topic", "echo", "selftest/cmd_vel", "geometry_msgs/msg/Twist",
                     "--count", "2", "--timeout", "20")
    assert result.returncode == 0, result.stderr
    docs = yaml_docs(result.stdout)
    assert len(docs) == 2
    for doc in docs:
        assert doc == {"linear": {"x": 0.5, "y": 0.0, "z": 0.0},
                       "angular": {"x": 0.0, "y": 0.0, "z": -1.25}}


def test_echo_matches_best_effort_publisher(ros_node, ros2cli):
    start_talker(ros_node, "/selftest/scan_like", lambda i: String(data=f"be {i}"), String,
                 qos=rosutil.qos_sensor())
    result = ros2cli("topic", "echo", "/selftest/scan_like", "--once", "--timeout", "20", "-v")
    assert result.returncode == 0, result.stderr
    assert "best_effort/volatile" in result.stderr
    assert yaml_docs(result.stdout)[0]["data"].startswith("be ")


def test_echo_receives_latched_message(ros_node, ros2cli):
    pub = ros_node.create_publisher(String, "/selftest/status", rosutil.qos_latched())
    pub.publish(String(data="latched once"))
    result = ros2cli("topic", "echo", "/selftest/status", "--once", "--timeout", "20", "-v")
    assert result.returncode == 0, result.stderr
    assert "reliable/transient_local" in result.stderr
    assert yaml_docs(result.stdout) == [{"data": "latched once"}]


def test_echo_field_and_truncation(ros_node, ros2cli):
    def odom(i: int) -> Odometry:
        msg = Odometry()
        msg.pose.pose.position.x = 1.5
        msg.pose.covariance = [float(k) for k in range(36)]
        return msg

    start_talker(ros_node, "/selftest/odom", odom, Odometry)
    result = ros2cli("topic", "echo", "/selftest/odom", "--once", "--timeout", "20",
                     "--field", "pose", "--truncate-length", "4")
    assert result.returncode == 0, result.stderr
    doc = yaml_docs(result.stdout)[0]
    assert doc["pose"]["position"]["x"] == 1.5
    assert doc["covariance"] == [0.0, 1.0, 2.0, 3.0, "..."]


def test_echo_times_out_with_exit_code_1(ros2cli):
    start = time.monotonic()
    result = ros2cli("topic", "echo", "/selftest/nobody", "std_msgs/msg/String", "--once",
                     "--timeout", "1")
    assert result.returncode == 1
    assert "timeout" in result.stderr
    assert time.monotonic() - start < 10


def test_echo_unknown_topic_without_type_fails(ros2cli):
    result = ros2cli("topic", "echo", "/selftest/unknown", "--timeout", "1")
    assert result.returncode == 1
    assert "could not determine the type" in result.stderr


def test_topic_hz(ros_node, ros2cli):
    start_talker(ros_node, "/selftest/hz", lambda i: String(data="x"), String, period=0.05)
    result = ros2cli("topic", "hz", "/selftest/hz", "--duration", "2.5", "--timeout", "10")
    assert result.returncode == 0, result.stderr
    rates = [float(line.split(":")[1]) for line in result.stdout.splitlines()
             if line.startswith("average rate:")]
    assert rates, result.stdout
    assert rates[-1] == pytest.approx(20.0, rel=0.15)


# --------------------------------------------------------------------------------------------
# (b) topic pub
# --------------------------------------------------------------------------------------------

def test_pub_times_3_is_received(ros_node, ros2cli):
    with harness.subscribe(ros_node, String, "/selftest/pub", rosutil.qos_default()) as rec:
        result = ros2cli("topic", "pub", "/selftest/pub", "std_msgs/msg/String", "{data: hi}",
                         "--times", "3", "--rate", "20")
        assert result.returncode == 0, result.stderr
        messages = rec.wait_count(3, timeout=10)
        time.sleep(0.3)  # nothing more may come: the publisher has exited
        assert [m.data for m in rec.snapshot()] == ["hi", "hi", "hi"]
        assert len(messages) == 3
    assert "publishing #3" in result.stdout


def test_pub_twist_yaml_numbers_are_coerced(ros_node, ros2cli):
    with harness.subscribe(ros_node, Twist, "selftest/pub_twist", rosutil.qos_default()) as rec:
        result = ros2cli("topic", "pub", "selftest/pub_twist", "geometry_msgs/Twist",
                         "{linear: {x: 1}, angular: {z: -0.5}}", "--once")
        assert result.returncode == 0, result.stderr
        msg = rec.wait_for(timeout=10)
    assert (msg.linear.x, msg.linear.y, msg.angular.z) == (1.0, 0.0, -0.5)


def test_pub_best_effort_option(ros_node, ros2cli):
    with harness.subscribe(ros_node, String, "/selftest/pub_be", rosutil.qos_sensor()) as rec:
        # A reliable subscription would not match... a best-effort one matches both; check the
        # option is accepted and the data flows.
        result = ros2cli("topic", "pub", "/selftest/pub_be", "std_msgs/msg/String", "{data: be}",
                         "--times", "2", "--rate", "20", "--qos-reliability", "best_effort")
        assert result.returncode == 0, result.stderr
        assert rec.wait_for(timeout=10).data == "be"


def test_pub_rejects_unknown_field(ros2cli):
    result = ros2cli("topic", "pub", "/selftest/x", "std_msgs/msg/String", "{nope: 1}", "--once")
    assert result.returncode == 1
    assert "nope" in result.stderr


def test_pub_rejects_unknown_type(ros2cli):
    result = ros2cli("topic", "pub", "/selftest/x", "std_msgs/msg/NoSuchType", "{}", "--once")
    assert result.returncode == 1
    assert "cannot import" in result.stderr


def test_pub_fails_without_subscriber(ros2cli):
    result = ros2cli("topic", "pub", "/selftest/none", "std_msgs/msg/String", "{data: x}",
                     "--once", "--max-wait-time", "1")
    assert result.returncode == 1
    assert "matching subscription" in result.stderr


# --------------------------------------------------------------------------------------------
# (c) node list / topic list
# --------------------------------------------------------------------------------------------

def test_node_and_topic_list(ros_node, spinner, ros2cli):
    listed = spinner.add_node(rclpy.create_node("mobil_selftest_listed", namespace="/robot1"),
                              own=True)
    listed.create_publisher(Twist, "cmd_vel", 10)
    result = ros2cli("node", "list")
    assert result.returncode == 0, result.stderr
    names = result.stdout.split()
    assert "/robot1/mobil_selftest_listed" in names
    assert f"/{ros_node.get_name()}" in names
    assert not any("_ros2cli_" in n for n in names)

    result = ros2cli("topic", "list", "-t")
    assert result.returncode == 0, result.stderr
    assert "/robot1/cmd_vel [geometry_msgs/msg/Twist]" in result.stdout.splitlines()


# --------------------------------------------------------------------------------------------
# (d) parameters
# --------------------------------------------------------------------------------------------

@pytest.fixture
def param_node(spinner):
    node = rclpy.create_node("mobil_selftest_params")
    node.declare_parameter("max_speed", 1.0)
    node.declare_parameter("mode", "track")
    node.declare_parameter("gains", [1, 2, 3])
    return spinner.add_node(node, own=True)


def test_param_set_get_via_cli(param_node, ros2cli):
    result = ros2cli("param", "set", "/mobil_selftest_params", "max_speed", "2.5")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "Set parameter successful"
    assert param_node.get_parameter("max_speed").value == 2.5

    result = ros2cli("param", "get", "mobil_selftest_params", "max_speed")
    assert result.returncode == 0, result.stderr
    assert result.stdout.strip() == "Double value is: 2.5"

    result = ros2cli("param", "set", "/mobil_selftest_params", "max_speed", "fast")
    assert result.returncode == 1
    assert result.stderr.startswith("Setting parameter failed: ")
    assert param_node.get_parameter("max_speed").value == 2.5

    result = ros2cli("param", "set", "/mobil_selftest_params", "gains", "[4, 5]")
    assert result.returncode == 0, result.stderr
    assert list(param_node.get_parameter("gains").value) == [4, 5]
    result = ros2cli("param", "get", "/mobil_selftest_params", "gains", "--hide-type")
    assert result.stdout.strip() == "[4, 5]"

    result = ros2cli("param", "list", "/mobil_selftest_params")
    assert result.returncode == 0, result.stderr
    assert {"gains", "max_speed", "mode"} <= set(result.stdout.split())


def test_param_errors_via_cli(param_node, ros2cli):
    result = ros2cli("param", "get", "/mobil_selftest_params", "no_such_param")
    assert result.returncode == 1
    assert "not set" in result.stderr
    result = ros2cli("param", "set", "/mobil_selftest_params", "no_such_param", "1")
    assert result.returncode == 1
    assert result.stderr.startswith("Setting parameter failed")
    result = ros2cli("param", "get", "/no_such_node", "x", "--timeout", "1")
    assert result.returncode == 1
    assert "not found" in result.stderr


def test_param_helpers_in_process(ros_node, param_node):
    assert harness.param_get(ros_node, "/mobil_selftest_params", "mode") == "track"
    result = harness.param_set(ros_node, "/mobil_selftest_params", "mode", "dock")
    assert result.successful, result.reason
    assert harness.param_get(ros_node, "mobil_selftest_params", "mode") == "dock"
    refused = harness.param_set(ros_node, "/mobil_selftest_params", "max_speed", "fast")
    assert not refused.successful and refused.reason
    assert harness.param_get(ros_node, "/mobil_selftest_params", "max_speed") == 1.0
    assert harness.param_get(ros_node, "/mobil_selftest_params", "undeclared") is None
    assert "gains" in harness.param_list(ros_node, "/mobil_selftest_params")
    with pytest.raises(harness.ServiceUnavailable):
        harness.param_get(ros_node, "/no_such_node", "x", timeout=0.5)


def test_parameter_value_parsing():
    from rcl_interfaces.msg import ParameterType as T
    cases = {"3": (T.PARAMETER_INTEGER, 3), "3.5": (T.PARAMETER_DOUBLE, 3.5),
             "true": (T.PARAMETER_BOOL, True), "hello": (T.PARAMETER_STRING, "hello"),
             "[1, 2]": (T.PARAMETER_INTEGER_ARRAY, [1, 2]),
             "[0.5, 1.5]": (T.PARAMETER_DOUBLE_ARRAY, [0.5, 1.5]),
             "[a, b]": (T.PARAMETER_STRING_ARRAY, ["a", "b"]),
             "[1, a]": (T.PARAMETER_STRING, "[1, a]"), "'7'": (T.PARAMETER_STRING, "7")}
    for text, (ptype, value) in cases.items():
        pv = rosutil.parameter_value_from_string(text)
        assert (pv.type, rosutil.parameter_value_to_python(pv)) == (ptype, value), text


# --------------------------------------------------------------------------------------------
# Harness: node processes and topic helpers
# --------------------------------------------------------------------------------------------

@pytest.fixture
def fake_exe(tmp_path) -> Path:
    return executable_script(tmp_path / "fake_node",
                             f'exec "{sys.executable}" "{TESTS / "fake_node.py"}" "$@"')


def test_start_node_with_ros_args(start_node, ros_node, fake_exe, tmp_path, ros_domain_id):
    params = tmp_path / "params.yaml"
    params.write_text("fake1:\n  ros__parameters:\n    prefix: fromfile\n")
    proc = start_node(str(fake_exe), "-p", "rate:=20.0", "-r", "chatter:=fake_out",
                      params_file=params, name="fake1")
    msg = harness.wait_for_message(ros_node, String, "/fake_out",
                                   predicate=lambda m: m.data.startswith("fromfile "))
    assert msg.data.startswith("fromfile ")
    assert harness.param_get(ros_node, "/fake1", "rate") == 20.0
    refused = harness.param_set(ros_node, "/fake1", "rate", -1.0)
    assert not refused.successful and refused.reason == "rate must be > 0"

    messages = harness.collect(ros_node, String, "/fake_out", 1.0)
    assert 12 <= len(messages) <= 28  # 20 Hz over 1 s, with slack for a loaded machine

    assert proc.wait_for_log(r"up as /fake1")
    assert proc.stop() == 0
    assert "shutting down" in proc.log_text()
    assert not proc.running


def test_child_gets_the_domain(start_node, fake_exe, ros_domain_id):
    proc = start_node(str(fake_exe))
    proc.wait_for_log("up as")  # exec'd: /proc/PID/environ is the child's own now
    # The environment the child was started with (the domain is how tests stay isolated).
    environ = Path(f"/proc/{proc.pid}/environ").read_bytes().split(b"\0")
    assert f"ROS_DOMAIN_ID={ros_domain_id}".encode() in environ
    assert os.environ["ROS_DOMAIN_ID"] == str(ros_domain_id)


def test_stop_kills_a_node_ignoring_sigint(tmp_path):
    exe = executable_script(tmp_path / "stubborn", "trap '' INT\necho ready\nexec sleep 60")
    proc = harness.launch_node(str(exe), log_dir=tmp_path)
    proc.wait_for_log("ready")
    with pytest.raises(harness.NodeProcessError, match="killed"):
        proc.stop(timeout=0.5)
    assert not proc.running and proc.killed
    assert proc.stop() == proc.returncode  # idempotent, no second error


def test_stop_reports_a_crash(tmp_path):
    exe = executable_script(tmp_path / "crasher", "echo boom\nexit 3")
    proc = harness.launch_node(str(exe), "-p", "x:=1", log_dir=tmp_path)
    proc.proc.wait(10)
    with pytest.raises(harness.NodeProcessError, match="exited by itself with code 3"):
        proc.stop()
    assert "boom" in proc.log_text()
    # A test that expects the exit collects it with wait() instead:
    proc2 = harness.launch_node(str(exe), log_dir=tmp_path)
    assert proc2.wait(10) == 3
    assert proc2.stop() == 3


def test_missing_executable_is_a_clear_error():
    with pytest.raises(FileNotFoundError, match="cargo build --release"):
        harness.resolve_executable("no_such_node_exe")


def test_wait_for_message_timeout_explains(ros_node):
    start_talker(ros_node, "/selftest/explain", lambda i: String(data=f"n{i}"), String)
    with pytest.raises(TimeoutError) as info:
        harness.wait_for_message(ros_node, String, "/selftest/explain",
                                 predicate=lambda m: m.data == "never", timeout=1.0)
    text = str(info.value)
    assert "no matching message" in text and "last:" in text and "publishers:" in text


def test_publish_until(ros_node):
    pub = ros_node.create_publisher(Twist, "/selftest/until", 10)
    with harness.subscribe(ros_node, Twist, "/selftest/until", rosutil.qos_default()) as rec:
        sent = harness.publish_until(ros_node, pub, lambda: twist(0.1, 0.0),
                                     lambda: len(rec) >= 3, rate_hz=50, timeout=10)
        assert sent >= 3
        assert rec.latest.linear.x == 0.1
    with pytest.raises(TimeoutError):
        harness.publish_until(ros_node, pub, twist(0, 0), lambda: False, rate_hz=50, timeout=0.3)


# --------------------------------------------------------------------------------------------
# YAML <-> message
# --------------------------------------------------------------------------------------------

def test_set_message_fields_nested_arrays_and_stamps():
    odom = rosutil.fill_message(Odometry(), {
        "header": "auto", "child_frame_id": "base_link",
        "pose": {"pose": {"position": {"x": 1, "y": 2.5}}, "covariance": [0] * 36}})
    assert odom.header.stamp.sec > 0
    assert odom.pose.pose.position.x == 1.0 and odom.child_frame_id == "base_link"
    path = rosutil.fill_message(PathMsg(), {
        "header": {"frame_id": "odom", "stamp": "now"},
        "poses": [{"pose": {"position": {"x": 1.0}}}, {"pose": {"orientation": {"w": 1}}}]})
    assert len(path.poses) == 2 and path.poses[1].pose.orientation.w == 1.0
    assert path.header.stamp.sec > 0
    with pytest.raises(rosutil.MessageFieldError, match="36"):
        rosutil.fill_message(Odometry(), {"pose": {"covariance": [0.0]}})
    with pytest.raises(rosutil.MessageFieldError, match="integer"):
        rosutil.fill_message(Odometry(), {"header": {"stamp": {"sec": 1.5}}})


def test_message_to_yaml_round_trip():
    msg = rosutil.set_message_fields(Odometry(), {"pose": {"pose": {"position": {"x": 0.25}}},
                                                  "child_frame_id": "base_link"})
    data = yaml.safe_load(rosutil.message_to_yaml(msg))
    assert list(data) == ["header", "child_frame_id", "pose", "twist"]  # field order kept
    again = rosutil.set_message_fields(Odometry(), data)
    assert again == msg
    assert math.isclose(data["pose"]["pose"]["position"]["x"], 0.25)


# --------------------------------------------------------------------------------------------
# Environment: Fast DDS profile, the wrapper script, the suite's own messages
# --------------------------------------------------------------------------------------------

def test_fastdds_profile_loads_cleanly(ros2cli, tmp_path):
    assert os.environ["FASTRTPS_DEFAULT_PROFILES_FILE"] == str(rosutil.FASTDDS_PROFILE)
    good = ros2cli("node", "list", "--spin-time", "0.2")
    assert good.returncode == 0, good.stderr
    output = good.stdout + good.stderr  # Fast DDS logs its errors to stdout
    assert "XMLPARSER" not in output and "Error" not in output, output
    # The check above would see a broken profile:
    bad_profile = tmp_path / "bad.xml"
    bad_profile.write_text(rosutil.FASTDDS_PROFILE.read_text().replace(
        "<listenSocketBufferSize>", "<bogus/><listenSocketBufferSize>"))
    bad = ros2cli("node", "list", "--spin-time", "0.2",
                  env={"FASTRTPS_DEFAULT_PROFILES_FILE": str(bad_profile)})
    assert "XMLPARSER" in bad.stdout + bad.stderr


def test_wrapper_script(ros_node):
    import subprocess
    start_talker(ros_node, "/selftest/wrapped", lambda i: String(data="via wrapper"), String)
    env = rosutil.ros_environ()
    env["MOBIL_ROS2CLI_NO_SETUP"] = "1"  # the venv is there; do not depend on a msgs rebuild
    for key in ("PYTHONPATH", "FASTRTPS_DEFAULT_PROFILES_FILE", "RMW_IMPLEMENTATION"):
        env.pop(key)  # the wrapper sets them
    result = subprocess.run([str(harness.ROOT / "launch_scripts" / "ros2cli"), "topic", "echo",
                             "/selftest/wrapped", "--once", "--timeout", "20"],
                            env=env, capture_output=True, text=True, timeout=60)
    assert result.returncode == 0, result.stderr
    assert yaml_docs(result.stdout) == [{"data": "via wrapper"}]
    help_text = subprocess.run([str(harness.ROOT / "launch_scripts" / "ros2cli"), "--help"],
                               env=env, capture_output=True, text=True, timeout=60)
    assert help_text.returncode == 0 and "topic" in help_text.stdout


def _mobil_msg_types() -> list[type]:
    import mobil_msgs.msg
    return [getattr(mobil_msgs.msg, n) for n in dir(mobil_msgs.msg)
            if hasattr(getattr(mobil_msgs.msg, n), "get_fields_and_field_types")]


def test_mobil_msgs_through_cli(ros_node, ros2cli):
    """The suite's own message package works in-process and in ros2cli (both directions)."""
    types = _mobil_msg_types()
    assert types, "mobil_msgs has no message types"
    msg_type = types[0]
    name = rosutil.type_name(msg_type)
    start_talker(ros_node, "/selftest/mobil", lambda i: msg_type(), msg_type)
    result = ros2cli("topic", "echo", "/selftest/mobil", "--once", "--timeout", "20")
    assert result.returncode == 0, result.stderr
    assert list(yaml_docs(result.stdout)[0]) == list(msg_type.get_fields_and_field_types())

    with harness.subscribe(ros_node, msg_type, "/selftest/mobil_in", rosutil.qos_default()) as rec:
        result = ros2cli("topic", "pub", "/selftest/mobil_in", name, "{}", "--once")
        assert result.returncode == 0, result.stderr
        assert rec.wait_for(timeout=10) == msg_type()


def test_call_service_retries_and_ignores_late_answers(ros_node, rclpy_context):
    """A request that gets no answer in time is forgotten and sent again (the first-call stall
    of ROS2-NOTES); the late answer to the forgotten one must not confuse the client."""
    from std_srvs.srv import Trigger
    server_node = rclpy.create_node("mobil_selftest_slow_server")
    calls = []

    def handle(request: Any, response: Any) -> Any:
        calls.append(time.monotonic())
        if len(calls) == 1:
            time.sleep(1.0)  # the first request "stalls"
        response.success, response.message = True, f"call {len(calls)}"
        return response

    server_node.create_service(Trigger, "/selftest/slow", handle)
    with rosutil.Spinner(server_node, context=rclpy_context):  # its own thread: may block
        start = time.monotonic()
        response = rosutil.call_service(ros_node, Trigger, "/selftest/slow", Trigger.Request(),
                                        timeout=10, attempt_timeout=0.3)
        assert response.success
        # The answer to a retry (which one depends on timing), never the stalled first call's.
        assert response.message != "call 1"
        assert len(calls) >= 2 and time.monotonic() - start < 5
    server_node.destroy_node()


def test_sim_clock_and_publishing_on_simulated_time(ros_node):
    """SimClock and publish_on_sim_time against a /clock published here at exactly 3× real time
    (simulated seconds = 3 × wall seconds since the start), then paused."""
    import threading
    from rosgraph_msgs.msg import Clock
    clock_pub = ros_node.create_publisher(Clock, "/clock", rosutil.make_qos("reliable", "volatile", 1))
    cmd_pub = ros_node.create_publisher(String, "scenario_cmd", rosutil.qos_default())
    stop, paused = threading.Event(), threading.Event()
    t0 = time.monotonic()

    def run_clock() -> None:
        while not stop.is_set():
            if not paused.is_set():
                sim = 3.0 * (time.monotonic() - t0)
                msg = Clock()
                msg.clock.sec, msg.clock.nanosec = int(sim), int((sim % 1.0) * 1e9)
                clock_pub.publish(msg)
            time.sleep(0.005)

    thread = threading.Thread(target=run_clock, daemon=True)
    thread.start()
    try:
        with harness.SimClock(ros_node) as clock, \
                harness.subscribe(ros_node, String, "scenario_cmd", qos=rosutil.qos_default()) as cmds:
            clock.wait_started(timeout=10)
            # Discovery of the command topic first: its first message may be lost otherwise.
            harness.publish_until(ros_node, cmd_pub, String(data="hello"), lambda: len(cmds) > 0)
            mark = clock.mark()
            # 3 simulated seconds take 1 wall second at 3×.
            reached = clock.wait_until(mark[0] + 3.0, timeout=10)
            assert reached >= mark[0] + 3.0
            assert time.monotonic() - mark[1] == pytest.approx(1.0, abs=0.15)
            assert clock.factor(since=mark) == pytest.approx(3.0, rel=0.05)

            # Every 0.3 simulated seconds over 3 of them: one at once, then one at each multiple
            # of 0.3 crossed, 10 (9 if the start falls on one, fewer if this loop stalls across
            # two of them on a loaded machine); no wall-clock repeats, which would make dozens.
            cmds.clear()
            t_start = clock.now()
            count = harness.publish_on_sim_time(cmd_pub, lambda t: String(data=repr(t)), clock,
                                                until=t_start + 3.0, period=0.3, max_wall_gap=10.0)
            assert 8 <= count <= 11
            rosutil.wait_until(lambda: len(cmds) >= count, timeout=5)
            sent = [float(m.data) for m in cmds.snapshot()]
            assert all(t_start <= t < t_start + 3.0 for t in sent)  # msg(t) gets simulated time

            # Paused clock: nothing more on simulated time; at least every 0.1 wall s with the
            # wall-clock rule: 1 at once + 4 or 5 over 0.5 s (3 if the loop runs late under load).
            paused.set()
            time.sleep(0.05)
            end = time.monotonic() + 0.5
            assert harness.publish_on_sim_time(cmd_pub, String(), clock, until=math.inf, period=0.3,
                                               max_wall_gap=10.0, done=lambda: time.monotonic() >= end) == 1
            end = time.monotonic() + 0.5
            assert harness.publish_on_sim_time(cmd_pub, String(), clock, until=math.inf, period=0.3,
                                               max_wall_gap=0.1, done=lambda: time.monotonic() >= end) in (4, 5, 6)
            assert clock.max_gap < 0.2  # not yet resumed
            paused.clear()
            clock.wait_until(clock.now() + 0.3, timeout=5)
            assert clock.max_gap > 1.0  # the pause, about 1.05 s
    finally:
        stop.set()
        thread.join(5)
