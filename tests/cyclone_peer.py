#!/usr/bin/env python3
"""A Cyclone DDS peer of mobil's nodes: Eclipse Cyclone DDS (the `cyclonedds` wheel, its C
library inside) speaking to them as rmw_cyclonedds_cpp does, with the ROS 2 types declared here
as IDL structs (the names rmw gives them, `<pkg>::msg::dds_::<Type>_`).

Services use rmw_cyclonedds_cpp's request/reply layout (serdata.hpp, Serialization.cpp of
ros2/rmw_cyclonedds, jazzy): after the 4-byte encapsulation, a 16-byte header
`struct { uint64_t guid; int64_t seq; }` in the payload's byte order, then the request; the reply
echoes the header. `guid` is the client's request writer's instance handle and `seq` its request
counter; a client keeps the replies whose guid is its own. Here the header is the struct's first
two members, which in XCDR1 is the same bytes.

    cyclone_peer.py [--domain N] [--names-repeat K]

checks in one run, printing one JSON line per step and exiting 0 only if all passed:
odom and scan received (rt/odom, rt/scan), cmd_vel sent (rt/cmd_vel, the robot moves: odom's
twist follows), `/chassis/get_parameters` answered (once small, once large enough to travel as
DATA_FRAGs), and a `drive_distance` goal accepted and its result received.

    cyclone_peer.py --serve-gait SECONDS [--domain N]

serves `gait/compute_plan` (mobil_msgs/srv/PlanGait) as an rmw_cyclonedds_cpp server would, for
mobil's clients: prints `{"step": "ready"}`, then one JSON line per request (its header and
fields), answering each with a two-state plan from the request's start to its goal, 7 states
expanded and 11 generated; exits 0 after SECONDS if it served at least one request.
"""

import argparse
import json
import os
import sys
import time
from dataclasses import dataclass, field

from cyclonedds.core import Policy, Qos
from cyclonedds.domain import DomainParticipant
from cyclonedds.idl import IdlStruct
from cyclonedds.idl.types import array, float32, float64, int8, int32, int64, sequence, uint8, uint32, uint64
from cyclonedds.pub import DataWriter
from cyclonedds.sub import DataReader
from cyclonedds.topic import Topic
from cyclonedds.util import duration

# Loopback only; lo has no MULTICAST flag, so Cyclone is told multicast works there (it does).
CYCLONE_LOOPBACK = ('<CycloneDDS><Domain Id="any"><General><Interfaces>'
                    '<NetworkInterface name="lo" multicast="true"/>'
                    '</Interfaces></General></Domain></CycloneDDS>')


# ---- messages ------------------------------------------------------------------------------

@dataclass
class Time(IdlStruct, typename="builtin_interfaces::msg::dds_::Time_"):
    sec: int32 = 0
    nanosec: uint32 = 0


@dataclass
class Header(IdlStruct, typename="std_msgs::msg::dds_::Header_"):
    stamp: Time = field(default_factory=Time)
    frame_id: str = ""


@dataclass
class Vector3(IdlStruct, typename="geometry_msgs::msg::dds_::Vector3_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Point(IdlStruct, typename="geometry_msgs::msg::dds_::Point_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0


@dataclass
class Quaternion(IdlStruct, typename="geometry_msgs::msg::dds_::Quaternion_"):
    x: float64 = 0.0
    y: float64 = 0.0
    z: float64 = 0.0
    w: float64 = 1.0


@dataclass
class Pose(IdlStruct, typename="geometry_msgs::msg::dds_::Pose_"):
    position: Point = field(default_factory=Point)
    orientation: Quaternion = field(default_factory=Quaternion)


@dataclass
class PoseWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::PoseWithCovariance_"):
    pose: Pose = field(default_factory=Pose)
    covariance: array[float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Twist(IdlStruct, typename="geometry_msgs::msg::dds_::Twist_"):
    linear: Vector3 = field(default_factory=Vector3)
    angular: Vector3 = field(default_factory=Vector3)


@dataclass
class TwistWithCovariance(IdlStruct, typename="geometry_msgs::msg::dds_::TwistWithCovariance_"):
    twist: Twist = field(default_factory=Twist)
    covariance: array[float64, 36] = field(default_factory=lambda: [0.0] * 36)


@dataclass
class Odometry(IdlStruct, typename="nav_msgs::msg::dds_::Odometry_"):
    header: Header = field(default_factory=Header)
    child_frame_id: str = ""
    pose: PoseWithCovariance = field(default_factory=PoseWithCovariance)
    twist: TwistWithCovariance = field(default_factory=TwistWithCovariance)


@dataclass
class LaserScan(IdlStruct, typename="sensor_msgs::msg::dds_::LaserScan_"):
    header: Header = field(default_factory=Header)
    angle_min: float32 = 0.0
    angle_max: float32 = 0.0
    angle_increment: float32 = 0.0
    time_increment: float32 = 0.0
    scan_time: float32 = 0.0
    range_min: float32 = 0.0
    range_max: float32 = 0.0
    ranges: sequence[float32] = field(default_factory=list)
    intensities: sequence[float32] = field(default_factory=list)


@dataclass
class ParameterValue(IdlStruct, typename="rcl_interfaces::msg::dds_::ParameterValue_"):
    type: uint8 = 0
    bool_value: bool = False
    integer_value: int64 = 0
    double_value: float64 = 0.0
    string_value: str = ""
    byte_array_value: sequence[uint8] = field(default_factory=list)
    bool_array_value: sequence[bool] = field(default_factory=list)
    integer_array_value: sequence[int64] = field(default_factory=list)
    double_array_value: sequence[float64] = field(default_factory=list)
    string_array_value: sequence[str] = field(default_factory=list)


# ---- services, with rmw_cyclonedds_cpp's header as the first two members ---------------------

@dataclass
class GetParametersRequest(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Request_"):
    guid: uint64 = 0
    seq: int64 = 0
    names: sequence[str] = field(default_factory=list)


@dataclass
class GetParametersResponse(IdlStruct, typename="rcl_interfaces::srv::dds_::GetParameters_Response_"):
    guid: uint64 = 0
    seq: int64 = 0
    values: sequence[ParameterValue] = field(default_factory=list)


@dataclass
class UUID(IdlStruct, typename="unique_identifier_msgs::msg::dds_::UUID_"):
    uuid: array[uint8, 16] = field(default_factory=lambda: [0] * 16)


@dataclass
class DriveDistanceGoal(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_Goal_"):
    distance: float64 = 0.0
    speed: float64 = 0.0


@dataclass
class DriveDistanceResult(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_Result_"):
    travelled: float64 = 0.0
    reason: str = ""


@dataclass
class SendGoalRequest(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_SendGoal_Request_"):
    guid: uint64 = 0
    seq: int64 = 0
    goal_id: UUID = field(default_factory=UUID)
    goal: DriveDistanceGoal = field(default_factory=DriveDistanceGoal)


@dataclass
class SendGoalResponse(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_SendGoal_Response_"):
    guid: uint64 = 0
    seq: int64 = 0
    accepted: bool = False
    stamp: Time = field(default_factory=Time)


@dataclass
class GetResultRequest(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_GetResult_Request_"):
    guid: uint64 = 0
    seq: int64 = 0
    goal_id: UUID = field(default_factory=UUID)


@dataclass
class GetResultResponse(IdlStruct, typename="mobil_msgs::action::dds_::DriveDistance_GetResult_Response_"):
    guid: uint64 = 0
    seq: int64 = 0
    status: int8 = 0
    result: DriveDistanceResult = field(default_factory=DriveDistanceResult)


@dataclass
class Pose2D(IdlStruct, typename="geometry_msgs::msg::dds_::Pose2D_"):
    x: float64 = 0.0
    y: float64 = 0.0
    theta: float64 = 0.0


@dataclass
class GaitStep(IdlStruct, typename="mobil_msgs::msg::dds_::GaitStep_"):
    rule: uint8 = 0
    rule_name: str = ""
    body: Pose2D = field(default_factory=Pose2D)
    feet: array[Point, 4] = field(default_factory=lambda: [Point() for _ in range(4)])
    moving_leg: int8 = -1
    evaluation: float64 = 0.0


@dataclass
class GaitPlan(IdlStruct, typename="mobil_msgs::msg::dds_::GaitPlan_"):
    header: Header = field(default_factory=Header)
    rule_set: str = ""
    evaluation: uint8 = 0
    success: bool = False
    reason: str = ""
    states_expanded: uint32 = 0
    states_generated: uint32 = 0
    steps: sequence[GaitStep] = field(default_factory=list)


@dataclass
class PlanGaitRequest(IdlStruct, typename="mobil_msgs::srv::dds_::PlanGait_Request_"):
    guid: uint64 = 0
    seq: int64 = 0
    start: Pose2D = field(default_factory=Pose2D)
    goal: Point = field(default_factory=Point)
    rule_set: str = ""
    evaluation: uint8 = 0
    max_expansions: uint32 = 0


@dataclass
class PlanGaitResponse(IdlStruct, typename="mobil_msgs::srv::dds_::PlanGait_Response_"):
    guid: uint64 = 0
    seq: int64 = 0
    plan: GaitPlan = field(default_factory=GaitPlan)


# ---- the peer --------------------------------------------------------------------------------

XCDR1 = Policy.DataRepresentation(use_cdrv0_representation=True)
# Readers best effort (they match reliable and best-effort writers alike), writers reliable.
READER = Qos(Policy.Reliability.BestEffort, Policy.Durability.Volatile, Policy.History.KeepLast(10), XCDR1)
WRITER = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile,
             Policy.History.KeepLast(10), XCDR1)
SERVICE = Qos(Policy.Reliability.Reliable(duration(seconds=1)), Policy.Durability.Volatile,
              Policy.History.KeepLast(10), XCDR1)


def report(step: str, ok: bool, **details: object) -> bool:
    print(json.dumps({"step": step, "ok": ok, **details}), flush=True)
    return ok


class ServiceClient:
    """A client in rmw_cyclonedds_cpp's layout on rq/<name>Request, rr/<name>Reply."""

    def __init__(self, dp: DomainParticipant, name: str, req_type: type, resp_type: type) -> None:
        self.writer = DataWriter(dp, Topic(dp, f"rq/{name}Request", req_type), qos=SERVICE)
        self.reader = DataReader(dp, Topic(dp, f"rr/{name}Reply", resp_type), qos=SERVICE)
        # What rmw_cyclonedds puts in the header: the writer's instance handle, as unsigned.
        self.guid = self.writer.get_instance_handle() & 0xFFFF_FFFF_FFFF_FFFF
        self.seq = 0
        self.skipped = 0  # samples that did not decode (other clients' replies)

    def wait_matched(self, timeout: float) -> bool:
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            if self.writer.get_matched_subscriptions() and self.reader.get_matched_publications():
                return True
            time.sleep(0.05)
        return False

    def call(self, request: IdlStruct, timeout: float, attempts: int = 3) -> IdlStruct | None:
        """Sends ``request`` (its header filled here) and waits for the reply with its header;
        a reply for another client (another guid), or of another layout, is skipped. Retries
        (a new seq) when no reply comes: the server's reply writer may match our reader only
        after our first request."""
        for _ in range(attempts):
            self.seq += 1
            request.guid, request.seq = self.guid, self.seq
            self.writer.write(request)
            deadline = time.monotonic() + timeout
            while time.monotonic() < deadline:
                try:
                    samples = self.reader.take(N=16)
                except Exception:  # noqa: BLE001 - another client's reply in Fast DDS's layout
                    # (no header) need not decode as ours: skipped, as rmw_cyclonedds skips
                    # what it cannot read.
                    self.skipped += 1
                    continue
                for sample in samples:
                    if getattr(sample, "guid", None) == self.guid and sample.seq == self.seq:
                        return sample
                time.sleep(0.01)
        return None


def first_sample(reader: DataReader, timeout: float):
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        for sample in reader.take(N=1):
            return sample
        time.sleep(0.02)
    return None


def serve_gait(dp: DomainParticipant, seconds: float) -> int:
    """A `gait/compute_plan` server in rmw_cyclonedds_cpp's layout: the reply echoes the
    request's header (its writer's guid and its seq)."""
    requests = DataReader(dp, Topic(dp, "rq/gait/compute_planRequest", PlanGaitRequest), qos=SERVICE)
    replies = DataWriter(dp, Topic(dp, "rr/gait/compute_planReply", PlanGaitResponse), qos=SERVICE)
    report("ready", True)
    served = 0
    end = time.monotonic() + seconds
    while time.monotonic() < end:
        try:
            samples = requests.take(N=16)
        except Exception as e:  # noqa: BLE001 - a request in another layout does not decode
            report("request", False, error=repr(e))
            continue
        for r in samples:
            report("request", True, guid=r.guid, seq=r.seq, start=[r.start.x, r.start.y, r.start.theta],
                   goal=[r.goal.x, r.goal.y], rule_set=r.rule_set, evaluation=r.evaluation)
            steps = [GaitStep(rule_name="start", body=Pose2D(r.start.x, r.start.y, r.start.theta)),
                     GaitStep(rule=1, rule_name="cyclone", body=Pose2D(r.goal.x, r.goal.y, r.start.theta))]
            plan = GaitPlan(rule_set=r.rule_set, evaluation=r.evaluation, success=True,
                            states_expanded=7, states_generated=11, steps=steps)
            replies.write(PlanGaitResponse(guid=r.guid, seq=r.seq, plan=plan))
            served += 1
        time.sleep(0.01)
    return 0 if served else 1


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--domain", type=int, default=int(os.environ.get("ROS_DOMAIN_ID", "0")))
    ap.add_argument("--serve-gait", type=float, metavar="SECONDS",
                    help="only serve gait/compute_plan, this long")
    ap.add_argument("--names-repeat", type=int, default=40,
                    help="the large get_parameters call asks for its names this many times")
    ap.add_argument("--timeout", type=float, default=20.0)
    args = ap.parse_args()
    os.environ.setdefault("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
    dp = DomainParticipant(args.domain)
    if args.serve_gait is not None:
        return serve_gait(dp, args.serve_gait)
    ok = True

    odom_reader = DataReader(dp, Topic(dp, "rt/odom", Odometry), qos=READER)
    scan_reader = DataReader(dp, Topic(dp, "rt/scan", LaserScan), qos=READER)
    cmd_writer = DataWriter(dp, Topic(dp, "rt/cmd_vel", Twist), qos=WRITER)

    odom = first_sample(odom_reader, args.timeout)
    ok &= report("odom", odom is not None,
                 frame=None if odom is None else odom.header.frame_id,
                 child=None if odom is None else odom.child_frame_id)
    scan = first_sample(scan_reader, args.timeout)
    ok &= report("scan", scan is not None, beams=None if scan is None else len(scan.ranges))

    # cmd_vel: 0.2 m/s for 1.5 s at 20 Hz (chassis_node's watchdog wants one at least every
    # 0.5 s); odometry's twist must follow.
    deadline = time.monotonic() + args.timeout
    while not cmd_writer.get_matched_subscriptions() and time.monotonic() < deadline:
        time.sleep(0.05)
    peak = 0.0
    end = time.monotonic() + 1.5
    while time.monotonic() < end:
        cmd_writer.write(Twist(linear=Vector3(x=0.2)))
        for sample in odom_reader.take(N=16):
            peak = max(peak, sample.twist.twist.linear.x)
        time.sleep(0.05)
    for _ in range(5):
        cmd_writer.write(Twist())
        time.sleep(0.05)
    ok &= report("cmd_vel", peak > 0.1, peak_odom_speed=round(peak, 4))

    params = ServiceClient(dp, "chassis/get_parameters", GetParametersRequest, GetParametersResponse)
    matched = params.wait_matched(args.timeout)
    reply = params.call(GetParametersRequest(names=["v_max", "model"]), timeout=2.0) if matched else None
    ok &= report("get_parameters", reply is not None and len(reply.values) == 2,
                 values=None if reply is None else [
                     (v.type, v.double_value, v.string_value) for v in reply.values])
    many = ["v_max", "model", "odom_frame", "wheelbase"] * args.names_repeat
    reply = params.call(GetParametersRequest(names=many), timeout=2.0) if matched else None
    ok &= report("get_parameters_large", reply is not None and len(reply.values) == len(many),
                 count=None if reply is None else len(reply.values))

    send_goal = ServiceClient(dp, "drive_distance/_action/send_goal", SendGoalRequest, SendGoalResponse)
    get_result = ServiceClient(dp, "drive_distance/_action/get_result", GetResultRequest, GetResultResponse)
    matched = send_goal.wait_matched(args.timeout) and get_result.wait_matched(args.timeout)
    goal_id = UUID(uuid=list(os.urandom(16)))
    accepted = None
    deadline = time.monotonic() + args.timeout
    while matched and time.monotonic() < deadline:
        # drive_node rejects goals until its first odometry: ask again until accepted.
        response = send_goal.call(SendGoalRequest(goal_id=goal_id, goal=DriveDistanceGoal(distance=0.2, speed=0.2)),
                                  timeout=2.0)
        if response is not None and response.accepted:
            accepted = response
            break
        time.sleep(0.5)
    ok &= report("send_goal", accepted is not None)
    result = get_result.call(GetResultRequest(goal_id=goal_id), timeout=args.timeout, attempts=1) \
        if accepted is not None else None
    ok &= report("get_result", result is not None and result.status == 4,  # SUCCEEDED
                 status=None if result is None else result.status,
                 travelled=None if result is None else round(result.result.travelled, 4),
                 reason=None if result is None else result.result.reason)
    return 0 if ok else 1


if __name__ == "__main__":
    sys.exit(main())
