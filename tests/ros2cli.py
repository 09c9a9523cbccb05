#!/usr/bin/env python3
"""A small stand-in for the ``ros2`` command line, on rclpy alone (no ROS install needed).

Run it through ``launch_scripts/ros2cli`` (which prepares the venv and the environment), e.g.::

    ros2cli node list
    ros2cli topic list -t
    ros2cli topic echo /odom --once
    ros2cli topic echo scan sensor_msgs/msg/LaserScan --count 5 --timeout 10
    ros2cli topic pub cmd_vel geometry_msgs/msg/Twist '{linear: {x: 0.2}}' --rate 10
    ros2cli topic hz scan
    ros2cli param list /chassis
    ros2cli param get /chassis v_max
    ros2cli param set /chassis v_max 0.3

Exit codes: 0 success, 1 failure or timeout (2 for usage errors, from argparse).
ROS_DOMAIN_ID is honoured as by any ROS 2 program.
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time
from pathlib import Path
from typing import Any, Optional

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rosutil  # noqa: E402

rosutil.setup_process_environment()

CLI_NODE_PREFIX = "_ros2cli_"  # leading underscore: hidden from `node list` by default


class CliError(Exception):
    """A failure reported to the user as ``error: ...`` with exit code 1."""


def _positive_float(text: str) -> float:
    value = float(text)
    if not value > 0 or math.isinf(value):
        raise argparse.ArgumentTypeError(f"must be a positive number: {text}")
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value <= 0:
        raise argparse.ArgumentTypeError(f"must be a positive integer: {text}")
    return value


# --------------------------------------------------------------------------------------------
# rclpy session
# --------------------------------------------------------------------------------------------

class Session:
    """rclpy context + one hidden node spun in the background for the command's lifetime."""

    def __init__(self, name: str) -> None:
        import rclpy
        from rclpy.signals import SignalHandlerOptions
        # No rclpy signal handlers: Ctrl-C raises KeyboardInterrupt in the main thread.
        rclpy.init(signal_handler_options=SignalHandlerOptions.NO)
        self.node = rclpy.create_node(f"{CLI_NODE_PREFIX}{name}_{os.getpid()}",
                                      start_parameter_services=False, enable_rosout=False)
        self.spinner = rosutil.Spinner(self.node).start()

    def close(self) -> None:
        import rclpy
        self.spinner.stop()
        self.node.destroy_node()
        rclpy.try_shutdown()

    def __enter__(self) -> "Session":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


def settle_graph(node: Any, snapshot, spin_time: float, min_time: float = 1.0,
                 stable_time: float = 1.2) -> Any:
    """Discovery has no end signal: return ``snapshot()`` once it is unchanged for
    ``stable_time`` after at least ``min_time`` (or at ``spin_time`` at the latest).

    ``stable_time`` exceeds Fast DDS's 1 s heartbeat period of its discovery (SEDP) writers: a
    discovery sample lost on the way is repaired after the next heartbeat, so a graph that stood
    still for only 0.5 s could still lack an endpoint (seen: a topic list without the other
    process's topics while a node list of the same moment had its node)."""
    start = time.monotonic()
    last = snapshot()
    last_change = start
    while True:
        now = time.monotonic()
        if now - start >= spin_time or (now - start >= min(min_time, spin_time)
                                        and now - last_change >= stable_time):
            return last
        time.sleep(0.05)
        current = snapshot()
        if current != last:
            last, last_change = current, time.monotonic()


# --------------------------------------------------------------------------------------------
# node / topic list
# --------------------------------------------------------------------------------------------

def cmd_node_list(args: argparse.Namespace) -> int:
    with Session("node_list") as s:
        names = settle_graph(s.node, lambda: rosutil.node_names(s.node), args.spin_time)
    for name in names:
        if args.all or not name.rsplit("/", 1)[-1].startswith("_"):
            print(name)
    return 0


def print_names_and_types(entries, include_hidden: bool, show_types: bool) -> int:
    """Print a `ros2 topic list` / `ros2 service list` style listing."""
    for name, types in entries:
        if not include_hidden and any(p.startswith("_") for p in name.split("/")):
            continue
        print(f"{name} [{', '.join(types)}]" if show_types else name)
    return 0


def cmd_topic_list(args: argparse.Namespace) -> int:
    with Session("topic_list") as s:
        topics = settle_graph(s.node, lambda: sorted(
            (n, tuple(t)) for n, t in s.node.get_topic_names_and_types()), args.spin_time)
    return print_names_and_types(topics, args.include_hidden_topics, args.show_types)


def cmd_topic_info(args: argparse.Namespace) -> int:
    with Session("topic_info") as s:
        topic = rosutil.resolve_topic(s.node, args.topic)
        settle_graph(s.node, lambda: rosutil.topic_types(s.node, topic), args.spin_time)
        types = rosutil.topic_types(s.node, topic)
        if not types:
            raise CliError(f"unknown topic {topic}")
        pubs = s.node.get_publishers_info_by_topic(topic)
        subs = [i for i in s.node.get_subscriptions_info_by_topic(topic)
                if not i.node_name.startswith(CLI_NODE_PREFIX)]
        print(f"Type: {', '.join(types)}")
        for label, infos in (("Publisher", pubs), ("Subscription", subs)):
            print(f"{label} count: {len(infos)}")
            if args.verbose:
                for i in infos:
                    print(f"  {i.node_namespace.rstrip('/')}/{i.node_name}: {i.topic_type} "
                          f"[{rosutil.describe_qos(i.qos_profile)}]")
    return 0


# --------------------------------------------------------------------------------------------
# topic echo / hz
# --------------------------------------------------------------------------------------------

def _discover_type(node: Any, topic: str, given: Optional[str], timeout: float) -> type:
    if given:
        return rosutil.import_type(given)
    found = rosutil.wait_for_topic_type(node, topic, timeout)
    if found is None:
        raise CliError(f"could not determine the type of {topic} (not in the graph within "
                       f"{timeout:g} s); give the type explicitly")
    types = rosutil.topic_types(node, topic)
    if len(types) > 1:
        raise CliError(f"{topic} has several types ({', '.join(types)}); give one explicitly")
    return rosutil.import_type(found)


def _subscription_qos(node: Any, topic: str, args: argparse.Namespace, discovery: float) -> Any:
    """QoS for echo/hz: matched to the publishers unless given on the command line."""
    rosutil.wait_for_publishers(node, topic, discovery)
    qos, count = rosutil.qos_matching_publishers(node, topic, depth=args.qos_depth)
    if args.qos_reliability:
        qos.reliability = rosutil.make_qos(reliability=args.qos_reliability).reliability
    if args.qos_durability:
        qos.durability = rosutil.make_qos(durability=args.qos_durability).durability
    if args.verbose:
        print(f"# {topic}: {count} publisher(s), subscribing with {rosutil.describe_qos(qos)}",
              file=sys.stderr)
    return qos


def _field(msg: Any, path: Optional[str]) -> Any:
    if not path:
        return msg
    value = msg
    for part in path.split("."):
        if not hasattr(value, "get_fields_and_field_types") or \
                part not in value.get_fields_and_field_types():
            raise CliError(f"invalid field {path!r}: no {part!r}")
        value = getattr(value, part)
    return value


def _format(value: Any, args: argparse.Namespace) -> str:
    truncate = None if args.full_length else args.truncate_length
    if hasattr(value, "get_fields_and_field_types"):
        return rosutil.message_to_yaml(value, truncate_length=truncate, flow_style=args.flow_style)
    import yaml
    return yaml.dump(rosutil.message_to_dict(value, truncate), default_flow_style=args.flow_style,
                     sort_keys=False, width=10_000)


def cmd_topic_echo(args: argparse.Namespace) -> int:
    wanted = 1 if args.once else args.count
    discovery = args.timeout if args.timeout is not None else args.discovery_timeout
    deadline = None if args.timeout is None else time.monotonic() + args.timeout
    with Session("echo") as s:
        topic = rosutil.resolve_topic(s.node, args.topic)
        msg_type = _discover_type(s.node, topic, args.type, discovery)
        qos = _subscription_qos(s.node, topic, args, min(discovery, 2.0) if args.type else discovery)
        recorder = rosutil.TopicRecorder(s.node, msg_type, topic, qos)
        printed = 0
        try:
            while wanted is None or printed < wanted:
                timeout = 1.0 if deadline is None else deadline - time.monotonic()
                try:
                    msg = recorder.wait_for(timeout=max(0.0, timeout), start=printed)
                except TimeoutError:
                    if deadline is None:
                        continue
                    raise CliError(f"timeout: {printed} message(s) on {topic} within "
                                   f"{args.timeout:g} s"
                                   + (f" (wanted {wanted})" if wanted else ""))
                printed += 1
                sys.stdout.write(_format(_field(msg, args.field), args) + "---\n")
                sys.stdout.flush()
        finally:
            recorder.close()
    return 0


def cmd_topic_hz(args: argparse.Namespace) -> int:
    discovery = args.timeout if args.timeout is not None else args.discovery_timeout
    with Session("hz") as s:
        topic = rosutil.resolve_topic(s.node, args.topic)
        msg_type = _discover_type(s.node, topic, args.type, discovery)
        qos = _subscription_qos(s.node, topic, args, min(discovery, 2.0) if args.type else discovery)
        recorder = rosutil.TopicRecorder(s.node, msg_type, topic, qos, raw=True)
        start = time.monotonic()
        reported = False
        try:
            while args.duration is None or time.monotonic() - start < args.duration:
                time.sleep(1.0 if args.duration is None else
                           min(1.0, max(0.0, args.duration - (time.monotonic() - start))))
                times = recorder.times[-(args.window + 1):]
                if len(times) < 2:
                    if args.timeout is not None and not reported and \
                            time.monotonic() - start > args.timeout:
                        raise CliError(f"timeout: fewer than 2 messages on {topic} within "
                                       f"{args.timeout:g} s")
                    if args.verbose or args.duration is not None:
                        print("no new messages", file=sys.stderr)
                    continue
                gaps = [b - a for a, b in zip(times, times[1:])]
                mean = sum(gaps) / len(gaps)
                std = math.sqrt(sum((g - mean) ** 2 for g in gaps) / len(gaps))
                print(f"average rate: {1.0 / mean:.3f}\n\tmin: {min(gaps):.3f}s "
                      f"max: {max(gaps):.3f}s std dev: {std:.5f}s window: {len(times)}",
                      flush=True)
                reported = True
        finally:
            recorder.close()
    return 0 if reported else 1


# --------------------------------------------------------------------------------------------
# topic pub
# --------------------------------------------------------------------------------------------

def cmd_topic_pub(args: argparse.Namespace) -> int:
    import yaml
    try:
        values = yaml.safe_load(args.values) if args.values else {}
    except yaml.YAMLError as exc:
        raise CliError(f"the values are not valid YAML: {exc}")
    if values is not None and not isinstance(values, dict):
        raise CliError(f"the values must be a YAML mapping, e.g. '{{data: hello}}', got {values!r}")
    times = 1 if args.once else args.times
    msg_type = rosutil.import_type(args.type)
    wait_subs = args.wait_matching_subscriptions
    if wait_subs is None:
        wait_subs = 1 if times is not None else 0
    qos = rosutil.make_qos(args.qos_reliability, args.qos_durability, args.qos_depth)
    with Session("pub") as s:
        clock = s.node.get_clock()

        def build() -> Any:  # rebuilt each time so `now` / `auto` stamps are fresh
            return rosutil.set_message_fields(msg_type(), values,
                                              now=lambda: clock.now().to_msg())

        try:
            build()
        except (ValueError, TypeError, AttributeError) as exc:
            raise CliError(f"failed to populate the message: {exc}")
        topic = rosutil.resolve_topic(s.node, args.topic)
        pub = s.node.create_publisher(msg_type, topic, qos)
        if wait_subs > 0:
            if not rosutil.wait_until(lambda: pub.get_subscription_count() >= wait_subs,
                                      args.max_wait_time, 0.02):
                raise CliError(f"{pub.get_subscription_count()} matching subscription(s) on "
                               f"{topic} within {args.max_wait_time:g} s (wanted {wait_subs}; "
                               f"publishing with {rosutil.describe_qos(qos)})")
        print("publisher: beginning loop", flush=True)
        period = 1.0 / args.rate
        next_time = time.monotonic()
        count = 0
        while times is None or count < times:
            msg = build()
            pub.publish(msg)
            count += 1
            if args.print_nth and count % args.print_nth == 0:
                print(f"publishing #{count}: {msg!r}\n", flush=True)
            if times is not None and count >= times:
                break
            next_time += period
            time.sleep(max(0.0, next_time - time.monotonic()))
        if args.qos_reliability == "reliable":
            from rclpy.duration import Duration
            if not pub.wait_for_all_acked(Duration(seconds=args.max_wait_time)):
                print("warning: not every subscription acknowledged the messages",
                      file=sys.stderr)
        time.sleep(args.keep_alive)
    return 0


# --------------------------------------------------------------------------------------------
# param list / get / set
# --------------------------------------------------------------------------------------------

def _service_error(node_name: str, exc: Exception) -> CliError:
    if isinstance(exc, rosutil.ServiceUnavailable):
        return CliError(f"node {rosutil.fully_qualified_node_name(node_name)} not found "
                        f"(its parameter services did not appear): {exc}")
    return CliError(str(exc))


def cmd_param_list(args: argparse.Namespace) -> int:
    with Session("param") as s:
        if args.node:
            targets = [rosutil.fully_qualified_node_name(args.node)]
        else:
            targets = [n for n in settle_graph(s.node, lambda: rosutil.node_names(s.node),
                                               args.spin_time)
                       if not n.rsplit("/", 1)[-1].startswith("_")]
        failed = False
        for target in targets:
            try:
                names = rosutil.list_parameters(s.node, target, timeout=args.timeout)
            except TimeoutError as exc:
                if args.node:
                    raise _service_error(target, exc)
                print(f"{target}: no parameter services ({exc})", file=sys.stderr)
                failed = True
                continue
            if not args.node:
                print(f"{target}:")
            for name in names:
                print(f"  {name}")
    return 1 if failed and args.node else 0


def cmd_param_get(args: argparse.Namespace) -> int:
    with Session("param") as s:
        try:
            values = rosutil.get_parameters(s.node, args.node, [args.name], timeout=args.timeout)
        except TimeoutError as exc:
            raise _service_error(args.node, exc)
    if not values or values[0].type == 0:
        print("Parameter not set.", file=sys.stderr)
        return 1
    pv = values[0]
    label = rosutil.PARAMETER_TYPE_LABELS.get(pv.type)
    if label is None:
        raise CliError(f"unknown parameter type {pv.type}")
    value = rosutil.parameter_value_to_python(pv)
    print(value if args.hide_type else f"{label} {value}")
    return 0


def cmd_param_set(args: argparse.Namespace) -> int:
    value = rosutil.parameter_value_from_string(args.value)
    with Session("param") as s:
        try:
            results = rosutil.set_parameters(s.node, args.node, {args.name: value},
                                             timeout=args.timeout)
        except TimeoutError as exc:
            raise _service_error(args.node, exc)
    if not results:
        raise CliError("the node returned no result")
    result = results[0]
    if result.successful:
        print("Set parameter successful" + (f": {result.reason}" if result.reason else ""))
        return 0
    print("Setting parameter failed" + (f": {result.reason}" if result.reason else ""),
          file=sys.stderr)
    return 1


# --------------------------------------------------------------------------------------------
# service list / call
# --------------------------------------------------------------------------------------------

def cmd_service_list(args: argparse.Namespace) -> int:
    with Session("service_list") as s:
        services = settle_graph(s.node, lambda: sorted(
            (n, tuple(t)) for n, t in s.node.get_service_names_and_types()), args.spin_time)
    return print_names_and_types(services, args.include_hidden_services, args.show_types)


def cmd_service_call(args: argparse.Namespace) -> int:
    import yaml
    srv_type = rosutil.import_type(args.type, default_kind="srv")
    try:
        values = yaml.safe_load(args.values) if args.values else {}
        request = rosutil.set_message_fields(srv_type.Request(), values)
    except (yaml.YAMLError, ValueError, TypeError, AttributeError) as exc:
        raise CliError(f"failed to populate the request: {exc}")
    with Session("service_call") as s:
        print(f"requester: making request: {request!r}\n", flush=True)
        response = rosutil.call_service(s.node, srv_type, rosutil.resolve_topic(s.node, args.service),
                                        request, timeout=args.timeout)
    print("response:\n" + rosutil.message_to_yaml(response), end="")
    return 0


# --------------------------------------------------------------------------------------------
# argument parsing
# --------------------------------------------------------------------------------------------

def _add_spin_time(p: argparse.ArgumentParser, default: float = 3.0) -> None:
    p.add_argument("--spin-time", type=_positive_float, default=default, metavar="S",
                   help="longest time to wait for discovery to settle (default %(default)s s)")


def _add_sub_qos(p: argparse.ArgumentParser) -> None:
    p.add_argument("--qos-reliability", choices=["reliable", "best_effort"],
                   help="override the reliability matched to the publishers")
    p.add_argument("--qos-durability", choices=["volatile", "transient_local"],
                   help="override the durability matched to the publishers")
    p.add_argument("--qos-depth", type=_positive_int, default=10, help="queue depth (default 10)")
    p.add_argument("--discovery-timeout", type=_positive_float, default=5.0, metavar="S",
                   help="how long to wait for the topic to appear when --timeout is not given "
                        "(default %(default)s s)")
    p.add_argument("-v", "--verbose", action="store_true", help="report the chosen QoS on stderr")


def build_parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="ros2cli", description=__doc__.split("\n\n")[0] + " Honours ROS_DOMAIN_ID.",
        formatter_class=argparse.RawDescriptionHelpFormatter,
        epilog="Run '<command> <verb> --help' for the options of each verb.")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)

    # node
    node = commands.add_parser("node", help="nodes in the graph").add_subparsers(
        dest="verb", metavar="VERB", required=True)
    p = node.add_parser("list", help="list the nodes")
    p.add_argument("-a", "--all", action="store_true", help="also hidden nodes (leading _)")
    _add_spin_time(p)
    p.set_defaults(func=cmd_node_list)

    # topic
    topic = commands.add_parser("topic", help="topics: list, info, echo, pub, hz").add_subparsers(
        dest="verb", metavar="VERB", required=True)
    p = topic.add_parser("list", help="list the topics")
    p.add_argument("-t", "--show-types", action="store_true", help="also print the types")
    p.add_argument("--include-hidden-topics", action="store_true")
    _add_spin_time(p)
    p.set_defaults(func=cmd_topic_list)

    p = topic.add_parser("info", help="type, publishers and subscriptions of a topic")
    p.add_argument("topic")
    p.add_argument("-v", "--verbose", action="store_true", help="list endpoints with their QoS")
    _add_spin_time(p)
    p.set_defaults(func=cmd_topic_info)

    p = topic.add_parser(
        "echo", help="print the messages of a topic as YAML",
        description="Print messages as YAML documents ending in '---'. The QoS is matched to the "
                    "publishers (best effort if any is, transient local if all are).")
    p.add_argument("topic")
    p.add_argument("type", nargs="?", help="pkg/msg/Type (default: from the graph)")
    p.add_argument("--once", action="store_true", help="print one message and exit")
    p.add_argument("--count", type=_positive_int, metavar="N", help="print N messages and exit")
    p.add_argument("--timeout", type=_positive_float, metavar="S",
                   help="fail (exit 1) unless the wanted messages arrive within S seconds")
    p.add_argument("--field", metavar="A.B", help="print only this field, e.g. pose.pose.position")
    p.add_argument("--truncate-length", type=_positive_int, default=128, metavar="N",
                   help="cut arrays and strings longer than N (default 128)")
    p.add_argument("--full-length", action="store_true", help="never truncate")
    p.add_argument("--flow-style", action="store_true", help="YAML flow style")
    _add_sub_qos(p)
    p.set_defaults(func=cmd_topic_echo)

    p = topic.add_parser("pub", help="publish a message given as YAML")
    p.add_argument("topic")
    p.add_argument("type", help="pkg/msg/Type")
    p.add_argument("values", nargs="?", default="{}",
                   help="YAML mapping of the fields, e.g. '{linear: {x: 0.5}}'; a Time given as "
                        "'now' and a Header given as 'auto' get the current time")
    p.add_argument("-r", "--rate", type=_positive_float, default=1.0, help="Hz (default 1)")
    p.add_argument("-1", "--once", action="store_true", help="publish once and exit")
    p.add_argument("-t", "--times", type=_positive_int, metavar="N", help="publish N times and exit")
    p.add_argument("-w", "--wait-matching-subscriptions", type=int, metavar="N",
                   help="wait for N matching subscriptions first (default 1 with --once/--times, "
                        "else 0)")
    p.add_argument("--max-wait-time", type=_positive_float, default=10.0, metavar="S",
                   help="fail if the subscriptions do not match within S (default %(default)s s); "
                        "also the time to wait for acknowledgements before exiting")
    p.add_argument("--keep-alive", type=float, default=0.1, metavar="S",
                   help="stay S seconds after the last message (default %(default)s)")
    p.add_argument("-p", "--print", dest="print_nth", type=int, default=1, metavar="N",
                   help="print every N-th message (0: none; default 1)")
    p.add_argument("--qos-reliability", choices=["reliable", "best_effort"], default="reliable")
    p.add_argument("--qos-durability", choices=["volatile", "transient_local"], default="volatile")
    p.add_argument("--qos-depth", type=_positive_int, default=10)
    p.set_defaults(func=cmd_topic_pub)

    p = topic.add_parser("hz", help="print the rate of a topic every second")
    p.add_argument("topic")
    p.add_argument("type", nargs="?", help="pkg/msg/Type (default: from the graph)")
    p.add_argument("--window", type=_positive_int, default=10000, metavar="N",
                   help="messages in the averaging window (default %(default)s)")
    p.add_argument("--duration", type=_positive_float, metavar="S",
                   help="stop after S seconds (exit 1 if no rate could be printed)")
    p.add_argument("--timeout", type=_positive_float, metavar="S",
                   help="fail (exit 1) if no rate can be computed within S seconds")
    _add_sub_qos(p)
    p.set_defaults(func=cmd_topic_hz)

    # param
    param = commands.add_parser("param", help="parameters: list, get, set").add_subparsers(
        dest="verb", metavar="VERB", required=True)
    p = param.add_parser("list", help="list the parameters of a node (or of all nodes)")
    p.add_argument("node", nargs="?", help="node name, e.g. /chassis (default: all nodes)")
    p.add_argument("--timeout", type=_positive_float, default=5.0, metavar="S")
    _add_spin_time(p)
    p.set_defaults(func=cmd_param_list)

    p = param.add_parser("get", help="print a parameter's value")
    p.add_argument("node", help="node name, e.g. /chassis")
    p.add_argument("name")
    p.add_argument("--hide-type", action="store_true", help="print the value only")
    p.add_argument("--timeout", type=_positive_float, default=5.0, metavar="S",
                   help="how long to wait for the node (default %(default)s s)")
    p.set_defaults(func=cmd_param_get)

    p = param.add_parser(
        "set", help="set a parameter (the value is YAML: 3 int, 3.0 double, true, [1, 2], text)")
    p.add_argument("node", help="node name, e.g. /chassis")
    p.add_argument("name")
    p.add_argument("value")
    p.add_argument("--timeout", type=_positive_float, default=5.0, metavar="S",
                   help="how long to wait for the node (default %(default)s s)")
    p.set_defaults(func=cmd_param_set)

    # service
    service = commands.add_parser("service", help="services: list, call").add_subparsers(
        dest="verb", metavar="VERB", required=True)
    p = service.add_parser("list", help="list the services")
    p.add_argument("-t", "--show-types", action="store_true")
    p.add_argument("--include-hidden-services", action="store_true")
    _add_spin_time(p)
    p.set_defaults(func=cmd_service_list)

    p = service.add_parser("call", help="call a service with a request given as YAML")
    p.add_argument("service")
    p.add_argument("type", help="pkg/srv/Type")
    p.add_argument("values", nargs="?", default="{}")
    p.add_argument("--timeout", type=_positive_float, default=10.0, metavar="S")
    p.set_defaults(func=cmd_service_call)
    return parser


def main(argv: Optional[list[str]] = None) -> int:
    args = build_parser().parse_args(argv)
    if getattr(args, "once", False) and getattr(args, "count", None):
        print("error: --once and --count exclude each other", file=sys.stderr)
        return 2
    try:
        return args.func(args)
    except KeyboardInterrupt:
        return 0
    except (CliError, rosutil.TypeNotFound, TimeoutError) as exc:
        print(f"error: {exc}", file=sys.stderr)
        return 1
    except BrokenPipeError:  # e.g. `| head`
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        return 0


if __name__ == "__main__":
    sys.exit(main())
