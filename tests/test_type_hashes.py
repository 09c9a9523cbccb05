"""REP-2011 type hashes (RIHS01) that mobil_msgs computes at build time from the `.msg` /
`.srv` / `.action` closure, against the hashes rosidl generated into the type-description JSON
files: of the ROS 2 Jazzy packages installed with rclpy (std_msgs, geometry_msgs, ...) and of
the mobil_msgs / nav2_msgs / bond build that tests/setup_env.sh makes. Every type the suite
builds must be found there, with the same hash.

On the wire, each of mobil's topic endpoints announces its type's hash in DDS USER_DATA
(`typehash=RIHS01_…;`) as rmw_fastrtps and rmw_cyclonedds do; rclpy reads it back as the
endpoint's `topic_type_hash`."""

from __future__ import annotations

import json
import subprocess

import harness
from harness import ROOT, wait_until


def reference_hashes() -> dict[str, str]:
    refs: dict[str, str] = {}
    roots = [ROOT / ".venv" / "share", *sorted((ROOT / "target").glob("msgs-install-py*/share"))]
    for root in roots:
        for path in root.glob("*/*/*.json"):
            try:
                doc = json.loads(path.read_text())
            except (OSError, ValueError):
                continue
            if isinstance(doc, dict):
                for entry in doc.get("type_hashes", []):
                    refs.setdefault(entry["type_name"], entry["hash_string"])
    return refs


def test_every_type_hash_is_rosidls():
    exe = harness.BIN_DIR / "examples" / "type_hashes"
    out = subprocess.run([str(exe)], capture_output=True, text=True, check=True, timeout=30).stdout
    ours = dict(line.split() for line in out.splitlines())
    refs = reference_hashes()
    assert len(ours) >= 249, len(ours)
    missing = sorted(set(ours) - set(refs))
    assert not missing, f"no rosidl hash to compare with for {missing}"
    differ = {name: (ours[name], refs[name]) for name in ours if ours[name] != refs[name]}
    assert not differ, differ
    # The four the suite's topics use most, by name.
    for name in ("nav_msgs/msg/Odometry", "sensor_msgs/msg/LaserScan", "geometry_msgs/msg/Twist",
                 "mobil_msgs/msg/NavStatus"):
        assert name in ours
    # And the types rosidl derives from services and actions, by name.
    for name in ("lifecycle_msgs/srv/GetState", "lifecycle_msgs/srv/GetState_Event",
                 "nav2_msgs/action/NavigateToPose", "nav2_msgs/action/NavigateToPose_SendGoal_Request",
                 "mobil_msgs/action/DriveDistance_FeedbackMessage", "rmw_dds_common/msg/ParticipantEntitiesInfo"):
        assert name in ours


# (topic, endpoint kind, mobil node, ROS type): odometry and status out, commands and scans in.
ENDPOINTS = [
    ("/odom", "publisher", "chassis", "nav_msgs/msg/Odometry"),
    ("/cmd_vel", "subscription", "chassis", "geometry_msgs/msg/Twist"),
    ("/scan", "subscription", "local_nav", "sensor_msgs/msg/LaserScan"),
    ("/local_nav/status", "publisher", "local_nav", "mobil_msgs/msg/NavStatus"),
]


# The DDS topics of services, an action's parts and rosout (no ROS name mangling): (DDS topic,
# endpoint kind, mobil node, the type whose hash it carries, the same endpoint of rclpy's: `{ref}`
# is the reference servers' namespace, `{me}` the rclpy node). As rmw_fastrtps does, a service's
# request endpoints carry the hash of `Name_Request`, its reply endpoints `Name_Response`'s.
SERVICE_ENDPOINTS = [
    ("rq/local_nav/get_stateRequest", "subscription", "local_nav", "lifecycle_msgs/srv/GetState_Request",
     "rq/{ref}/get_stateRequest"),
    ("rr/local_nav/get_stateReply", "publisher", "local_nav", "lifecycle_msgs/srv/GetState_Response",
     "rr/{ref}/get_stateReply"),
    ("rq/local_nav/get_parametersRequest", "subscription", "local_nav",
     "rcl_interfaces/srv/GetParameters_Request", "rq/{me}/get_parametersRequest"),
    ("rr/local_nav/get_parametersReply", "publisher", "local_nav",
     "rcl_interfaces/srv/GetParameters_Response", "rr/{me}/get_parametersReply"),
    ("rt/rosout", "publisher", "local_nav", "rcl_interfaces/msg/Log", "rt/rosout"),
    ("rt/parameter_events", "publisher", "local_nav", "rcl_interfaces/msg/ParameterEvent",
     "rt/parameter_events"),
    ("rq/navigate_to_pose/_action/send_goalRequest", "subscription", "local_nav",
     "nav2_msgs/action/NavigateToPose_SendGoal_Request", "rq/{ref}/navigate_to_pose/_action/send_goalRequest"),
    ("rr/navigate_to_pose/_action/get_resultReply", "publisher", "local_nav",
     "nav2_msgs/action/NavigateToPose_GetResult_Response", "rr/{ref}/navigate_to_pose/_action/get_resultReply"),
    ("rq/navigate_to_pose/_action/cancel_goalRequest", "subscription", "local_nav",
     "action_msgs/srv/CancelGoal_Request", "rq/{ref}/navigate_to_pose/_action/cancel_goalRequest"),
    ("rt/navigate_to_pose/_action/feedback", "publisher", "local_nav",
     "nav2_msgs/action/NavigateToPose_FeedbackMessage", "rt/{ref}/navigate_to_pose/_action/feedback"),
    ("rt/navigate_to_pose/_action/status", "publisher", "local_nav", "action_msgs/msg/GoalStatusArray",
     "rt/{ref}/navigate_to_pose/_action/status"),
]


def endpoints_of(ros_node, topic: str, kind: str, node: str, no_mangle: bool = False) -> list:
    query = (ros_node.get_publishers_info_by_topic if kind == "publisher"
             else ros_node.get_subscriptions_info_by_topic)
    return [e for e in query(topic, no_mangle=no_mangle) if e.node_name == node]


def test_endpoints_announce_their_type_hash_as_rclpys_do(start_node, ros_node):
    import rclpy
    from lifecycle_msgs.srv import GetState
    from nav2_msgs.action import NavigateToPose
    from rclpy.action import ActionServer
    start_node("chassis_node", params_file="params/omr3.yaml")
    start_node("local_nav_node", params_file="params/omr3.yaml")
    refs = reference_hashes()
    # rclpy's own endpoints of the same types (Fast DDS takes their hashes from the type
    # support), on a node of their own that is never spun: nothing runs in them, and they go
    # with the node.
    reference = rclpy.create_node("hash_reference", context=ros_node.context)
    me = reference.get_name()
    try:
        for i, (_, _, _, t) in enumerate(ENDPOINTS):
            reference.create_publisher(harness.import_type(t), f"/hash_reference/t{i}", 1)
        reference.create_service(GetState, "/hash_reference/get_state", lambda _req, resp: resp)
        ActionServer(reference, NavigateToPose, "/hash_reference/navigate_to_pose",
                     lambda handle: NavigateToPose.Result())
        for i, (topic, kind, node, type_name) in enumerate(ENDPOINTS):
            found = wait_until(lambda: endpoints_of(ros_node, topic, kind, node), 15)
            assert found, f"no {kind} of {node} on {topic}"
            ours = wait_until(lambda i=i: endpoints_of(ros_node, f"/hash_reference/t{i}", "publisher", me), 5)
            assert ours and len(ours) == 1, ours
            rclpys = str(ours[0].topic_type_hash)
            for endpoint in found:
                assert endpoint.topic_type == type_name
                assert str(endpoint.topic_type_hash) == rclpys == refs[type_name], (topic, node)
        # Services, rosout and the parts of an action.
        for topic, kind, node, type_name, reference_topic in SERVICE_ENDPOINTS:
            found = wait_until(lambda: endpoints_of(ros_node, topic, kind, node, no_mangle=True), 15)
            assert found, f"no {kind} of {node} on {topic}"
            reference_topic = reference_topic.format(ref="hash_reference", me=me)
            ours = wait_until(lambda: endpoints_of(ros_node, reference_topic, kind, me, no_mangle=True), 5)
            assert ours and len(ours) == 1, (reference_topic, ours)
            rclpys = str(ours[0].topic_type_hash)
            for endpoint in found:
                assert str(endpoint.topic_type_hash) == rclpys == refs[type_name], (topic, node)
    finally:
        reference.destroy_node()
