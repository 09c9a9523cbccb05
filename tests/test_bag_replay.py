"""rosbag2 (MCAP) record and replay: chassis_node's inputs of a live simulated run, `/clock` and
`joint_states`, recorded with the `rosbags` library into an MCAP rosbag2 as `ros2 bag record`
would store them (CDR as received, the receive time as the bag time), then replayed into a
fresh chassis_node under `use_sim_time`: the odometry is the live run's, sample for sample.

The simulation is noise-free (params/omr3.yaml: no wheel speed noise, no slip), so the only way
the two runs can differ is in what chassis_node is given: the check is exact.
"""

from __future__ import annotations

import threading
import time

import pytest

import harness

rosbags = pytest.importorskip("rosbags")

from geometry_msgs.msg import Twist  # noqa: E402
from nav_msgs.msg import Odometry  # noqa: E402
from rclpy.serialization import serialize_message  # noqa: E402
from rosgraph_msgs.msg import Clock  # noqa: E402
from sensor_msgs.msg import JointState  # noqa: E402

PARAMS = "params/omr3.yaml"
RECORDED = {"/clock": ("rosgraph_msgs/msg/Clock", Clock), "/joint_states": ("sensor_msgs/msg/JointState", JointState)}


def stamp_ns(msg) -> int:
    return msg.header.stamp.sec * 1_000_000_000 + msg.header.stamp.nanosec


def JointState_from(raw: bytes):  # noqa: N802 - reads like the type it returns
    from rclpy.serialization import deserialize_message
    return deserialize_message(raw, JointState)


def pose_of(msg) -> tuple[float, float, float, float]:
    p, q = msg.pose.pose.position, msg.pose.pose.orientation
    return (p.x, p.y, q.z, q.w)


@pytest.mark.closed_loop  # a real-time drive: never beside the demo or the soak (RUNNING_ALONE)
def test_a_replayed_mcap_bag_gives_the_live_runs_odometry(start_node, ros_node, tmp_path):
    from rosbags.rosbag2 import Reader, StoragePlugin, Writer
    from rosbags.typesys import Stores, get_typestore

    typestore = get_typestore(Stores.ROS2_JAZZY)
    bag = tmp_path / "chassis_inputs"

    # --- the live run, recorded ---
    sim, chassis = harness.launch_scenario(PARAMS, real_time_factor=2.0, launch=start_node)
    live: dict[int, tuple[float, float, float, float]] = {}
    recorded = 0
    with Writer(bag, version=8, storage_plugin=StoragePlugin.MCAP) as writer:
        connections = {topic: writer.add_connection(topic, name, typestore=typestore)
                       for topic, (name, _) in RECORDED.items()}
        lock = threading.Lock()

        def record(topic: str):
            def callback(msg) -> None:
                nonlocal recorded
                with lock:
                    writer.write(connections[topic], time.time_ns(), serialize_message(msg))
                    recorded += 1
            return callback

        subs = [ros_node.create_subscription(cls, topic, record(topic), 100)
                for topic, (_, cls) in RECORDED.items()]
        odom_sub = ros_node.create_subscription(
            Odometry, "/odom", lambda m: live.__setitem__(stamp_ns(m), pose_of(m)), harness.qos_default())
        with harness.SimClock(ros_node) as clock:
            clock.wait_started(timeout=15)
            # The recording runs before the robot moves: the replay starts from rest, as the live
            # chassis did (a recording that missed the first motion would start elsewhere).
            assert harness.wait_until(lambda: recorded >= 50, 15), "the recorder matched no sim"
            cmd = ros_node.create_publisher(Twist, "/cmd_vel", 10)
            drive = Twist()
            drive.linear.x, drive.linear.y, drive.angular.z = 0.3, 0.1, 0.4
            start = clock.now()
            harness.publish_on_sim_time(cmd, drive, clock, until=start + 3.0)
            harness.publish_on_sim_time(cmd, Twist(), clock, until=start + 4.0)
        for s in subs:
            ros_node.destroy_subscription(s)
        ros_node.destroy_subscription(odom_sub)
    chassis.stop()
    sim.stop()
    moved = max(abs(p[0]) + abs(p[1]) for p in live.values())
    assert moved > 0.5, f"the live run hardly moved ({moved:.3f} m)"

    # --- the replay, into a fresh chassis_node ---
    start_node("chassis_node", "-p", "use_sim_time:=true", params_file=PARAMS)
    assert harness.wait_for_node(ros_node, "/chassis", timeout=15)
    replayed: dict[int, tuple[float, float, float, float]] = {}
    # A deep queue: with depth 10 a loaded run once lost 4 of 210 samples here to the callback
    # thread falling behind (the samples after them matched, so chassis_node had sent them).
    odom_sub = ros_node.create_subscription(
        Odometry, "/odom", lambda m: replayed.__setitem__(stamp_ns(m), pose_of(m)), harness.make_qos(depth=1000))
    pubs = {topic: ros_node.create_publisher(cls, topic, 100) for topic, (_, cls) in RECORDED.items()}
    with Reader(bag) as reader:
        messages = [(c.topic, stamp, raw) for c, stamp, raw in reader.messages()]
    assert len(messages) == recorded
    # Prime: the first /clock and joint_states again and again until chassis_node answers with
    # odometry, so every endpoint on the way is matched before the replay (volatile topics drop
    # what comes before). The robot is at rest there, so the repeats change no pose.
    first = {topic: next(raw for t, _, raw in messages if t == topic) for topic in RECORDED}
    deadline = time.monotonic() + 15
    while not replayed and time.monotonic() < deadline:
        for topic in ("/clock", "/joint_states"):
            pubs[topic].publish(first[topic])
        time.sleep(0.1)
    assert replayed, "chassis_node gave no odometry for the first recorded sample"
    count = 0
    first_bag, first_wall = messages[0][1], time.monotonic()
    for topic, stamp, raw in messages:
        # At the recorded pace: chassis_node's feedback watchdog runs on the steady clock.
        delay = (stamp - first_bag) * 1e-9 - (time.monotonic() - first_wall)
        if delay > 0:
            time.sleep(delay)
        pubs[topic].publish(raw)  # the CDR bytes as recorded
        count += 1
    assert count == recorded
    last_live = max(live)
    assert harness.wait_until(lambda: last_live in replayed, 10), "the live run's last odometry never came"
    ros_node.destroy_subscription(odom_sub)

    # Every odometry sample of the live run from the first recorded wheel feedback on is in the
    # replay, equal.
    first_js = min(stamp_ns(JointState_from(raw)) for topic, _, raw in messages if topic == "/joint_states")
    wanted = sorted(t for t in live if t >= first_js)
    missing = [t for t in wanted if t not in replayed]
    assert not missing, (len(missing), len(wanted), missing[:5])
    for t in wanted:
        assert replayed[t] == pytest.approx(live[t], abs=1e-9), (t, live[t], replayed[t])
