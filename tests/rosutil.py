"""Shared rclpy helpers for mobil's Python side: the pytest harness and tests/ros2cli.py.

Everything that both need lives here, so the tests exercise exactly what users run:

* process environment (``setup_process_environment``, ``ros_environ``): the Fast DDS profile, the
  RMW implementation and the suite's own ``mobil_msgs`` type support from target/msgs-install;
* dynamic type import (``import_type``), YAML <-> message (``set_message_fields``,
  ``message_to_yaml``);
* QoS selection like ``ros2 topic echo`` (``qos_matching_publishers``);
* a background executor (``Spinner``) and a thread-safe message recorder (``TopicRecorder``);
* service calls with retries and the rcl_interfaces parameter services (``call_service``,
  ``get_parameters``, ``set_parameters``, ``list_parameters``) plus ParameterValue conversions.

Every helper that waits assumes the node is spun by *another* thread (see ``Spinner``): helpers
never spin by themselves, so they can be used from a test body or a CLI's main thread alike.
"""

from __future__ import annotations

import array
import ctypes
import importlib
import os
import sys
import threading
import time
import traceback
from collections.abc import Callable, Iterable, Sequence
from pathlib import Path
from typing import Any, Optional

ROOT = Path(__file__).resolve().parent.parent
TESTS_DIR = ROOT / "tests"
PY_VERSION = f"{sys.version_info.major}.{sys.version_info.minor}"
# Built by tests/setup_env.sh, one per Python version (the type support is a C extension).
MSGS_INSTALL = ROOT / "target" / f"msgs-install-py{PY_VERSION}"
MSGS_LIB = MSGS_INSTALL / "lib"
MSGS_PYTHONPATH = MSGS_INSTALL / "lib" / f"python{PY_VERSION}" / "site-packages"
FASTDDS_PROFILE = TESTS_DIR / "fastdds_profile.xml"
RMW_IMPLEMENTATION = "rmw_fastrtps_cpp"

# Set by setup_process_environment() if the mobil_msgs libraries could not be preloaded.
_msgs_preload_error: Optional[str] = None


# --------------------------------------------------------------------------------------------
# Environment
# --------------------------------------------------------------------------------------------

def _prepend_path(value: Optional[str], entry: str) -> str:
    parts = [p for p in (value or "").split(os.pathsep) if p]
    if entry in parts:
        return os.pathsep.join(parts)
    return os.pathsep.join([entry, *parts])


def ros_environ(base: Optional[dict[str, str]] = None, domain_id: Optional[int] = None) -> dict[str, str]:
    """Environment for a child process that uses ROS 2 (rclpy or a Rust node).

    Starts from ``base`` (default: ``os.environ``) and adds, without overriding what is already
    set: the RMW implementation, the Fast DDS profile, ROS_DISTRO, and PYTHONPATH /
    LD_LIBRARY_PATH for the mobil_msgs (and nav2_msgs) install. ``domain_id`` overrides ROS_DOMAIN_ID.
    """
    env = dict(os.environ if base is None else base)
    if base is None:
        # A developer's shell must not reshape the tests' graph: discovery range and peers are
        # set by the tests that need them (tests/test_multi_host.py).
        for key in ("ROS_AUTOMATIC_DISCOVERY_RANGE", "ROS_STATIC_PEERS", "ROS_LOCALHOST_ONLY"):
            env.pop(key, None)
    env.setdefault("RMW_IMPLEMENTATION", RMW_IMPLEMENTATION)
    env.setdefault("FASTRTPS_DEFAULT_PROFILES_FILE", str(FASTDDS_PROFILE))
    env.setdefault("ROS_DISTRO", "jazzy")  # ros2-client warns at start-up when it is unset
    env["PYTHONPATH"] = _prepend_path(env.get("PYTHONPATH"), str(MSGS_PYTHONPATH))
    env["LD_LIBRARY_PATH"] = _prepend_path(env.get("LD_LIBRARY_PATH"), str(MSGS_LIB))
    if domain_id is not None:
        env["ROS_DOMAIN_ID"] = str(domain_id)
    return env


def setup_process_environment() -> None:
    """Prepare *this* interpreter for rclpy; call before ``rclpy.init()``.

    Sets the environment defaults of ``ros_environ`` in ``os.environ`` (Fast DDS reads the profile
    when the first participant is created), puts the mobil_msgs Python package on ``sys.path`` and
    preloads its shared libraries, which the dynamic loader would otherwise only find through an
    LD_LIBRARY_PATH set before the interpreter started. Idempotent.
    """
    global _msgs_preload_error
    for key, value in ros_environ().items():
        if os.environ.get(key) != value:
            os.environ[key] = value
    if str(MSGS_PYTHONPATH) not in sys.path and MSGS_PYTHONPATH.is_dir():
        sys.path.append(str(MSGS_PYTHONPATH))
    if MSGS_LIB.is_dir():
        # mobil_msgs, and nav2_msgs (Nav2's action types) and bond, which setup_env.sh installs
        # beside it.
        _msgs_preload_error = _preload_libraries(
            [lib for package in ("mobil_msgs", "nav2_msgs", "bond")
             for lib in sorted(MSGS_LIB.glob(f"lib{package}__*.so"))])


def _preload_libraries(libs: Sequence[Path]) -> Optional[str]:
    """dlopen libraries (RTLD_GLOBAL) in dependency order by retrying; return the last error."""
    pending = list(libs)
    error: Optional[str] = None
    while pending:
        progress = False
        for lib in list(pending):
            try:
                ctypes.CDLL(str(lib), mode=ctypes.RTLD_GLOBAL)
            except OSError as exc:
                error = str(exc)
                continue
            pending.remove(lib)
            progress = True
        if not progress:
            return error
    return None


# --------------------------------------------------------------------------------------------
# Types
# --------------------------------------------------------------------------------------------

class TypeNotFound(Exception):
    """A message or service type could not be imported."""


def import_type(name: str, default_kind: str = "msg") -> type:
    """Import a ROS interface class from ``pkg/msg/Type``, ``pkg/Type`` or ``pkg.msg.Type``."""
    parts = [p for p in name.strip().replace(".", "/").split("/") if p]
    if len(parts) == 2:
        pkg, kind, typ = parts[0], default_kind, parts[1]
    elif len(parts) == 3:
        pkg, kind, typ = parts
    else:
        raise TypeNotFound(f"invalid type name {name!r}: expected pkg/msg/Type or pkg/Type")
    try:
        module = importlib.import_module(f"{pkg}.{kind}")
        cls = getattr(module, typ)
    except (ImportError, AttributeError) as exc:
        hint = ""
        if pkg == "mobil_msgs":
            hint = " (build it with tests/setup_env.sh"
            if _msgs_preload_error:
                hint += f"; preloading its libraries failed: {_msgs_preload_error}"
            hint += ")"
        raise TypeNotFound(f"cannot import {pkg}/{kind}/{typ}: {exc}{hint}") from exc
    if kind == "msg" and not hasattr(cls, "get_fields_and_field_types"):
        raise TypeNotFound(f"{name!r} is not a message type")
    if kind == "srv" and not hasattr(cls, "Request"):
        raise TypeNotFound(f"{name!r} is not a service type")
    return cls


def type_name(cls: type) -> str:
    """``geometry_msgs.msg.Twist`` -> ``geometry_msgs/msg/Twist``."""
    module = cls.__module__.split(".")
    return f"{module[0]}/{module[1]}/{cls.__name__}"


# --------------------------------------------------------------------------------------------
# YAML <-> message
# --------------------------------------------------------------------------------------------

try:  # The real thing, where a rosidl_runtime_py wheel is installed (it is not on PyPI for Jazzy).
    from rosidl_runtime_py import set_message_fields as _rrp_set_message_fields  # type: ignore
    from rosidl_runtime_py import message_to_yaml as _rrp_message_to_yaml  # type: ignore
except ImportError:  # pragma: no cover - depends on the installation
    _rrp_set_message_fields = None
    _rrp_message_to_yaml = None

_FLOAT_TYPES = {"float", "double", "long double", "float32", "float64"}
_INT_TYPES = {"int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"}


class MessageFieldError(ValueError):
    """Values that do not fit a message's fields."""


def set_message_fields(msg: Any, values: Any, *, now: Optional[Callable[[], Any]] = None) -> Any:
    """Fill ``msg`` from a (YAML-loaded) mapping, recursively; returns ``msg``.

    Uses rosidl_runtime_py's ``set_message_fields`` (with header/time expansion) where that
    package is installed; it is not on PyPI for Jazzy, so normally ``fill_message`` does it.
    """
    if values is None:
        return msg
    if _rrp_set_message_fields is not None:  # pragma: no cover - depends on the installation
        _rrp_set_message_fields(msg, values, expand_header_auto=True, expand_time_now=True)
        return msg
    return fill_message(msg, values, now=now)


def fill_message(msg: Any, values: Any, *, now: Optional[Callable[[], Any]] = None) -> Any:
    """Our own recursive setter: ``msg`` filled from a mapping; returns ``msg``.

    A ``builtin_interfaces/Time`` given as ``now`` and a ``std_msgs/Header`` given as ``auto``
    take the current time from ``now()`` (a callable returning a ``builtin_interfaces/Time``;
    default: the system clock). Numbers are coerced to the field's type (1 -> 1.0 for a float64);
    unknown fields, wrong types and wrong array sizes raise ``MessageFieldError``.
    """
    if values is not None:
        _set_fields(msg, values, "", now)
    return msg


def _set_fields(msg: Any, values: Any, path: str, now: Optional[Callable[[], Any]]) -> None:
    if not isinstance(values, dict):
        raise MessageFieldError(
            f"{path or type(msg).__name__}: expected a mapping of fields, got {values!r}")
    fields = msg.get_fields_and_field_types()
    slots = dict(zip(fields.keys(), msg.SLOT_TYPES))
    for name, value in values.items():
        if name not in fields:
            raise MessageFieldError(
                f"{path}{name}: {type_name(type(msg))} has no such field "
                f"(fields: {', '.join(fields) or 'none'})")
        converted = _convert(slots[name], value, f"{path}{name}", now)
        try:
            setattr(msg, name, converted)
        except (AssertionError, TypeError, ValueError) as exc:
            raise MessageFieldError(f"{path}{name}: {exc}") from exc


def _namespaced_class(slot: Any) -> type:
    module = importlib.import_module(".".join(slot.namespaces))
    return getattr(module, slot.name)


def _convert(slot: Any, value: Any, path: str, now: Optional[Callable[[], Any]]) -> Any:
    from rosidl_parser import definition as d

    if isinstance(slot, d.NamespacedType):
        cls = _namespaced_class(slot)
        if isinstance(value, cls):
            return value
        full = "/".join([*slot.namespaces, slot.name])
        if value == "now" and full == "builtin_interfaces/msg/Time":
            return _now(now)
        if value == "auto" and full == "std_msgs/msg/Header":
            return cls(stamp=_now(now))
        sub = cls()
        _set_fields(sub, value if value is not None else {}, path + ".", now)
        return sub
    if isinstance(slot, d.AbstractNestedType):
        if isinstance(value, (bytes, bytearray)) and isinstance(slot.value_type, d.BasicType):
            value = list(value)
        if not isinstance(value, (list, tuple)):
            raise MessageFieldError(f"{path}: expected a list, got {value!r}")
        if isinstance(slot, d.Array) and len(value) != slot.size:
            raise MessageFieldError(f"{path}: expected {slot.size} values, got {len(value)}")
        return [_convert(slot.value_type, v, f"{path}[{i}]", now) for i, v in enumerate(value)]
    if isinstance(slot, d.AbstractGenericString):
        return value if isinstance(value, str) else ("" if value is None else str(value))
    if isinstance(slot, d.BasicType):
        t = slot.typename
        if t == "boolean":
            if isinstance(value, bool):
                return value
            raise MessageFieldError(f"{path}: expected a boolean, got {value!r}")
        if t in _FLOAT_TYPES:
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                return float(value)
            raise MessageFieldError(f"{path}: expected a number, got {value!r}")
        if t in _INT_TYPES:
            if isinstance(value, bool) or not isinstance(value, (int, float)) or int(value) != value:
                raise MessageFieldError(f"{path}: expected an integer, got {value!r}")
            return int(value)
        if t == "octet":
            if isinstance(value, int) and not isinstance(value, bool):
                return bytes([value])
            if isinstance(value, (bytes, str)) and len(value) == 1:
                return value if isinstance(value, bytes) else value.encode("latin-1")
            raise MessageFieldError(f"{path}: expected a byte (0..255), got {value!r}")
        if t in ("char", "wchar"):
            if isinstance(value, int) and not isinstance(value, bool):
                return chr(value)
            return str(value)
    return value


def _now(now: Optional[Callable[[], Any]]) -> Any:
    if now is not None:
        return now()
    from builtin_interfaces.msg import Time
    ns = time.time_ns()
    return Time(sec=ns // 1_000_000_000, nanosec=ns % 1_000_000_000)


def message_to_dict(msg: Any, truncate_length: Optional[int] = None) -> Any:
    """Message -> plain Python (dicts in field order, lists, numbers, strings).

    Sequences and strings longer than ``truncate_length`` are cut and end with ``'...'``,
    as ``ros2 topic echo`` does.
    """
    if hasattr(msg, "get_fields_and_field_types"):
        return {name: message_to_dict(getattr(msg, name), truncate_length)
                for name in msg.get_fields_and_field_types()}
    if hasattr(msg, "tolist") and not isinstance(msg, (bytes, str)):  # numpy arrays and scalars
        msg = msg.tolist()
        if not isinstance(msg, list):
            return msg
    if isinstance(msg, array.array):
        msg = msg.tolist()
    if isinstance(msg, bytes):
        return msg[0] if len(msg) == 1 else list(msg)
    if isinstance(msg, str):
        if truncate_length is not None and len(msg) > truncate_length:
            return msg[:truncate_length] + "..."
        return msg
    if isinstance(msg, (list, tuple)):
        items = list(msg)
        cut = truncate_length is not None and len(items) > truncate_length
        if cut:
            items = items[:truncate_length]
        out = [message_to_dict(v, truncate_length) for v in items]
        if cut:
            out.append("...")
        return out
    return msg


def message_to_yaml(msg: Any, truncate_length: Optional[int] = None, flow_style: bool = False) -> str:
    """Message -> YAML text as ``ros2 topic echo`` prints it (without the ``---`` separator)."""
    if _rrp_message_to_yaml is not None:  # pragma: no cover
        return _rrp_message_to_yaml(msg, truncate_length=truncate_length, flow_style=flow_style)
    import yaml
    return yaml.dump(message_to_dict(msg, truncate_length), default_flow_style=flow_style,
                     sort_keys=False, allow_unicode=True, width=10_000)


# --------------------------------------------------------------------------------------------
# QoS
# --------------------------------------------------------------------------------------------

def _qos():
    from rclpy import qos
    return qos


def make_qos(reliability: str = "reliable", durability: str = "volatile", depth: int = 10):
    """A keep-last QoS profile from names (``reliable``/``best_effort``,
    ``volatile``/``transient_local``)."""
    q = _qos()
    return q.QoSProfile(
        history=q.HistoryPolicy.KEEP_LAST, depth=depth,
        reliability={"reliable": q.ReliabilityPolicy.RELIABLE,
                     "best_effort": q.ReliabilityPolicy.BEST_EFFORT}[reliability],
        durability={"volatile": q.DurabilityPolicy.VOLATILE,
                    "transient_local": q.DurabilityPolicy.TRANSIENT_LOCAL}[durability])


def qos_default():
    """The suite's default: reliable, volatile, depth 10."""
    return make_qos("reliable", "volatile", 10)


def qos_sensor():
    """Sensor data (``scan``): best effort, volatile, depth 5."""
    return make_qos("best_effort", "volatile", 5)


def qos_latched():
    """Latched status / plans: reliable, transient local, depth 1."""
    return make_qos("reliable", "transient_local", 1)


def resolve_topic(node: Any, topic: str) -> str:
    """Fully qualified name of ``topic`` as ``node`` sees it (``chatter`` -> ``/chatter``)."""
    return node.resolve_topic_name(topic)


def qos_matching_publishers(node: Any, topic: str, depth: int = 10):
    """QoS compatible with the current publishers of ``topic``, as ``ros2 topic echo`` picks it.

    Best effort if any publisher is best effort (else reliable); transient local if every
    publisher is transient local (else volatile). Returns ``(profile, publisher_count)``; with
    no publisher it is the default reliable/volatile profile.
    """
    q = _qos()
    infos = node.get_publishers_info_by_topic(resolve_topic(node, topic))
    profile = make_qos("reliable", "volatile", depth)
    if not infos:
        return profile, 0
    if any(i.qos_profile.reliability != q.ReliabilityPolicy.RELIABLE for i in infos):
        profile.reliability = q.ReliabilityPolicy.BEST_EFFORT
    if all(i.qos_profile.durability == q.DurabilityPolicy.TRANSIENT_LOCAL for i in infos):
        profile.durability = q.DurabilityPolicy.TRANSIENT_LOCAL
    return profile, len(infos)


def describe_qos(profile: Any) -> str:
    """Short text for a QoS profile, e.g. ``reliable/volatile depth 10``."""
    rel = getattr(profile.reliability, "name", str(profile.reliability)).lower()
    dur = getattr(profile.durability, "name", str(profile.durability)).lower()
    # Remote endpoints' depth is not part of discovery data (shows as 0): leave it out then.
    return f"{rel}/{dur}" + (f" depth {profile.depth}" if profile.depth else "")


def wait_until(predicate: Callable[[], Any], timeout: float, interval: float = 0.02) -> Any:
    """Poll ``predicate`` until it returns something truthy (returned) or ``timeout`` passes
    (returns the last falsy result)."""
    deadline = time.monotonic() + timeout
    while True:
        result = predicate()
        if result or time.monotonic() >= deadline:
            return result
        time.sleep(min(interval, max(0.0, deadline - time.monotonic())))


def wait_for_publishers(node: Any, topic: str, timeout: float, count: int = 1) -> list:
    """Wait until at least ``count`` publishers of ``topic`` are in the graph; return their info
    (possibly fewer after ``timeout``)."""
    name = resolve_topic(node, topic)
    infos: list = []

    def enough() -> bool:
        nonlocal infos
        infos = node.get_publishers_info_by_topic(name)
        return len(infos) >= count

    wait_until(enough, timeout, 0.05)
    return infos


def topic_types(node: Any, topic: str) -> list[str]:
    """Types of ``topic`` currently in the graph (usually one)."""
    name = resolve_topic(node, topic)
    for topic_name, types in node.get_topic_names_and_types():
        if topic_name == name:
            return list(types)
    return []


def wait_for_topic_type(node: Any, topic: str, timeout: float) -> Optional[str]:
    """Wait until ``topic`` is in the graph and return its (first) type name, else None."""
    types = wait_until(lambda: topic_types(node, topic), timeout, 0.05)
    return types[0] if types else None


def wait_for_node(node: Any, name: str, timeout: float = 10.0) -> bool:
    """Wait until a node (``/ns/name`` or ``name`` in ``/``) is in the graph."""
    fqn = fully_qualified_node_name(name)
    return bool(wait_until(lambda: fqn in node_names(node), timeout, 0.05))


def fully_qualified_node_name(name: str) -> str:
    return name if name.startswith("/") else "/" + name


def node_names(node: Any) -> list[str]:
    """Fully qualified names of the nodes in the graph, sorted."""
    out = []
    for name, ns in node.get_node_names_and_namespaces():
        out.append(ns.rstrip("/") + "/" + name)
    return sorted(out)


# --------------------------------------------------------------------------------------------
# Executor in a background thread, message recording
# --------------------------------------------------------------------------------------------

class Spinner:
    """Spins nodes in a background thread with a SingleThreadedExecutor.

    Callbacks run on that thread; the caller's thread only waits (on events, queues, futures).
    Exceptions raised by callbacks are kept in ``errors`` (and printed) instead of killing the
    thread. ``stop()`` joins the thread, then destroys the nodes it was told to own.
    """

    def __init__(self, *nodes: Any, context: Any = None) -> None:
        from rclpy.executors import SingleThreadedExecutor
        self.executor = SingleThreadedExecutor(context=context)
        self.errors: list[BaseException] = []
        self._owned: list[Any] = []
        self._stop = threading.Event()
        self._thread: Optional[threading.Thread] = None
        for node in nodes:
            self.add_node(node)

    def add_node(self, node: Any, own: bool = False) -> Any:
        """Spin ``node`` too; with ``own`` it is destroyed by ``stop()``. Returns ``node``."""
        self.executor.add_node(node)
        if own:
            self._owned.append(node)
        return node

    def start(self) -> "Spinner":
        if self._thread is None:
            self._thread = threading.Thread(target=self._run, name="rclpy-spinner", daemon=True)
            self._thread.start()
        return self

    def _run(self) -> None:
        from rclpy.exceptions import InvalidHandle
        from rclpy.executors import ExternalShutdownException, ShutdownException
        invalid_in_a_row = 0
        while not self._stop.is_set():
            try:
                self.executor.spin_once(timeout_sec=0.05)
                invalid_in_a_row = 0
            except (ExternalShutdownException, ShutdownException):
                break
            except InvalidHandle as exc:
                # A subscription (or its QoS event handler) destroyed by the test's thread while
                # this one was building the wait set: rclpy's executor guards callbacks against
                # that, not event handlers (Jazzy, event_handler.add_to_wait_set). Not a callback
                # failure; the next spin_once no longer sees the entity. One that stays is.
                invalid_in_a_row += 1
                if invalid_in_a_row == 20:
                    self.errors.append(exc)
                    traceback.print_exc()
                time.sleep(0.001)
            except Exception as exc:  # a callback failed: record, keep spinning
                if not self.executor.context.ok():
                    break
                self.errors.append(exc)
                traceback.print_exc()

    def stop(self) -> None:
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
            self._thread = None
        for node in reversed(self._owned):
            try:
                self.executor.remove_node(node)
                node.destroy_node()
            except Exception:  # pragma: no cover - best effort at shutdown
                traceback.print_exc()
        self._owned.clear()
        self.executor.shutdown(timeout_sec=1.0)

    def __enter__(self) -> "Spinner":
        return self.start()

    def __exit__(self, *exc: Any) -> None:
        self.stop()


class TopicRecorder:
    """Subscribes to a topic and keeps every message (with its monotonic arrival time).

    ``qos=None`` picks a QoS that matches the publishers (waiting up to ``discovery_timeout`` for
    at least one to appear), like ``ros2 topic echo``.
    """

    def __init__(self, node: Any, msg_type: type, topic: str, qos: Any = None,
                 discovery_timeout: float = 10.0, raw: bool = False) -> None:
        self.node = node
        self.msg_type = msg_type
        self.topic = resolve_topic(node, topic)
        if qos is None:
            wait_for_publishers(node, self.topic, discovery_timeout)
            qos, _ = qos_matching_publishers(node, self.topic)
        elif isinstance(qos, int):  # a depth, as rclpy takes it: reliable, volatile
            qos = make_qos("reliable", "volatile", qos)
        self.qos = qos
        self.messages: list[Any] = []
        self.times: list[float] = []
        self._cond = threading.Condition()
        self._sub = node.create_subscription(msg_type, self.topic, self._callback, qos, raw=raw)

    def _callback(self, msg: Any) -> None:
        with self._cond:
            self.messages.append(msg)
            self.times.append(time.monotonic())
            self._cond.notify_all()

    def __len__(self) -> int:
        with self._cond:
            return len(self.messages)

    @property
    def latest(self) -> Any:
        with self._cond:
            return self.messages[-1] if self.messages else None

    def snapshot(self) -> list[Any]:
        with self._cond:
            return list(self.messages)

    def clear(self) -> None:
        with self._cond:
            self.messages.clear()
            self.times.clear()

    def wait_for(self, predicate: Optional[Callable[[Any], bool]] = None, timeout: float = 10.0,
                 start: int = 0) -> Any:
        """First message at index >= ``start`` for which ``predicate`` holds (any message if
        None). Raises TimeoutError, describing what was received, after ``timeout``."""
        deadline = time.monotonic() + timeout
        index = start
        with self._cond:
            while True:
                while index < len(self.messages):
                    msg = self.messages[index]
                    index += 1
                    if predicate is None or predicate(msg):
                        return msg
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError(self.describe_timeout(timeout, predicate is not None, start))
                self._cond.wait(remaining)

    def wait_count(self, count: int, timeout: float = 10.0) -> list[Any]:
        """Wait until ``count`` messages were received; return them all."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while len(self.messages) < count:
                remaining = deadline - time.monotonic()
                if remaining <= 0:
                    raise TimeoutError(
                        f"{self.topic}: {len(self.messages)} of {count} messages within {timeout} s"
                        f" ({self._graph_info()})")
                self._cond.wait(remaining)
            return list(self.messages)

    def describe_timeout(self, timeout: float, had_predicate: bool, start: int = 0) -> str:
        received = len(self.messages) - start
        text = f"no {'matching ' if had_predicate else ''}message on {self.topic} " \
               f"({type_name(self.msg_type)}) within {timeout:g} s; {received} received"
        if received > 0:
            last = message_to_yaml(self.messages[-1], truncate_length=16).strip()
            text += f"; last:\n{last}"
        return text + f"\n({self._graph_info()})"

    def _graph_info(self) -> str:
        try:
            pubs = self.node.get_publishers_info_by_topic(self.topic)
        except Exception:  # pragma: no cover
            return "graph unavailable"
        desc = ", ".join(f"{p.node_namespace.rstrip('/')}/{p.node_name} "
                         f"[{describe_qos(p.qos_profile)}]" for p in pubs) or "none"
        try:
            nodes = ", ".join(sorted(f"{ns.rstrip('/')}/{n}"
                                     for n, ns in self.node.get_node_names_and_namespaces()))
        except Exception:  # pragma: no cover
            nodes = "unavailable"
        return (f"subscription QoS {describe_qos(self.qos)}; publishers: {desc}; "
                f"nodes in the graph: {nodes or 'none'}")

    def close(self) -> None:
        self.node.destroy_subscription(self._sub)

    def __enter__(self) -> "TopicRecorder":
        return self

    def __exit__(self, *exc: Any) -> None:
        self.close()


# --------------------------------------------------------------------------------------------
# Services and parameters
# --------------------------------------------------------------------------------------------

class ServiceUnavailable(TimeoutError):
    """No server for the service appeared in time."""


def wait_for_future(future: Any, timeout: float) -> bool:
    """Wait (without spinning: another thread spins) until ``future`` is done."""
    done = threading.Event()
    future.add_done_callback(lambda _f: done.set())
    return done.wait(timeout) or future.done()


def call_service(node: Any, srv_type: type, service: str, request: Any, *, timeout: float = 10.0,
                 attempt_timeout: float = 0.5) -> Any:
    """Call a service with retries; return the response.

    Waits for the server (up to ``timeout`` in all), then sends the request and, if no answer
    comes within ``attempt_timeout`` (doubled on each retry, at most 2 s), forgets that request and
    sends it again (a late answer to a forgotten request is ignored). Requests must therefore be
    idempotent (get/set/list parameters are). Raises ``ServiceUnavailable`` or ``TimeoutError``.

    Measured against a ros2-client server: the first request of a new client is often held until
    the client writer's next heartbeat (the server had not matched the writer yet and delivers in
    order), 3 s with Fast DDS defaults; a retry on the same writer does not beat that. The mobil
    Fast DDS profile (100 ms heartbeat) and the per-node client cache (``_cached_client``) do.
    """
    deadline = time.monotonic() + timeout
    client = _cached_client(node, srv_type, service)  # kept: later calls need no matching
    if not wait_until(client.service_is_ready, timeout, 0.02):
        raise ServiceUnavailable(f"service {service} not available within {timeout:g} s "
                                 f"({_service_graph_info(node, service)})")
    attempt_wait = attempt_timeout
    attempts = 0
    while True:
        attempts += 1
        future = client.call_async(request)
        wait = max(0.0, min(attempt_wait, deadline - time.monotonic()))
        if wait_for_future(future, wait):
            exc = future.exception()
            if exc is not None:
                raise exc
            return future.result()
        client.remove_pending_request(future)
        future.cancel()
        if time.monotonic() >= deadline:
            raise TimeoutError(f"service {service}: no response within {timeout:g} s "
                               f"({attempts} attempts)")
        attempt_wait = min(attempt_wait * 2, 2.0)


def _service_graph_info(node: Any, service: str) -> str:
    """What this participant's graph knows of a service's two DDS topics, and the nodes."""
    def endpoints(infos: Any) -> str:
        return ", ".join(f"{i.node_namespace.rstrip('/')}/{i.node_name}" for i in infos) or "none"
    try:
        request_readers = node.get_subscriptions_info_by_topic(f"rq{service}Request", no_mangle=True)
        reply_writers = node.get_publishers_info_by_topic(f"rr{service}Reply", no_mangle=True)
        nodes = ", ".join(node_names(node)) or "none"
    except Exception as exc:  # pragma: no cover
        return f"graph unavailable: {exc}"
    return (f"request readers: {endpoints(request_readers)}; reply writers: {endpoints(reply_writers)}; "
            f"nodes in the graph: {nodes}")


_client_cache_lock = threading.Lock()


def _cached_client(node: Any, srv_type: type, service: str) -> Any:
    """One client per (node, type, service), kept for the node's lifetime.

    Each new client is a new DDS writer/reader pair that the server must match again, and its
    first request can stall until the writer's next heartbeat (100 ms with the mobil profile,
    3 s without); reusing the client pays that once.
    """
    with _client_cache_lock:
        cache = node.__dict__.setdefault("_rosutil_clients", {})
        key = (srv_type, service)
        if key not in cache:
            cache[key] = node.create_client(srv_type, service)
        return cache[key]


def parameter_value_from_python(value: Any) -> Any:
    """Python value -> rcl_interfaces/ParameterValue (type inferred like ``ros2 param set``)."""
    from rcl_interfaces.msg import ParameterType, ParameterValue
    pv = ParameterValue()
    if value is None:
        pv.type = ParameterType.PARAMETER_NOT_SET
    elif isinstance(value, bool):
        pv.type, pv.bool_value = ParameterType.PARAMETER_BOOL, value
    elif isinstance(value, int):
        pv.type, pv.integer_value = ParameterType.PARAMETER_INTEGER, value
    elif isinstance(value, float):
        pv.type, pv.double_value = ParameterType.PARAMETER_DOUBLE, value
    elif isinstance(value, str):
        pv.type, pv.string_value = ParameterType.PARAMETER_STRING, value
    elif isinstance(value, (bytes, bytearray)):
        pv.type, pv.byte_array_value = ParameterType.PARAMETER_BYTE_ARRAY, [bytes([b]) for b in value]
    elif isinstance(value, (list, tuple)):
        values = list(value)
        if all(isinstance(v, bool) for v in values):
            pv.type, pv.bool_array_value = ParameterType.PARAMETER_BOOL_ARRAY, values
        elif all(isinstance(v, int) and not isinstance(v, bool) for v in values):
            pv.type, pv.integer_array_value = ParameterType.PARAMETER_INTEGER_ARRAY, values
        elif all(isinstance(v, float) for v in values):
            pv.type, pv.double_array_value = ParameterType.PARAMETER_DOUBLE_ARRAY, values
        elif all(isinstance(v, str) for v in values):
            pv.type, pv.string_array_value = ParameterType.PARAMETER_STRING_ARRAY, values
        else:
            raise ValueError(f"a parameter array must hold one type (bool, int, float or str): "
                             f"{value!r}")
    else:
        raise ValueError(f"unsupported parameter value {value!r}")
    return pv


def parameter_value_from_string(text: str) -> Any:
    """Parse a command-line value as YAML into a ParameterValue, as ``ros2 param set`` does:
    ``3`` is an integer, ``3.0`` a double, ``true`` a bool, ``[1, 2]`` an integer array; anything
    else (or mixed lists) is a string."""
    import yaml
    try:
        value = yaml.safe_load(text)
    except yaml.YAMLError:
        value = text
    if value is None or isinstance(value, (dict, bytes)) or (
            isinstance(value, list) and not _uniform_list(value)):
        value = text
    return parameter_value_from_python(value)


def _uniform_list(values: list) -> bool:
    return any(all(check(v) for v in values) for check in (
        lambda v: isinstance(v, bool),
        lambda v: isinstance(v, int) and not isinstance(v, bool),
        lambda v: isinstance(v, float),
        lambda v: isinstance(v, str)))


def parameter_value_to_python(pv: Any) -> Any:
    """rcl_interfaces/ParameterValue -> Python value (None when not set)."""
    from rcl_interfaces.msg import ParameterType as T
    return {
        T.PARAMETER_NOT_SET: lambda: None,
        T.PARAMETER_BOOL: lambda: pv.bool_value,
        T.PARAMETER_INTEGER: lambda: pv.integer_value,
        T.PARAMETER_DOUBLE: lambda: pv.double_value,
        T.PARAMETER_STRING: lambda: pv.string_value,
        T.PARAMETER_BYTE_ARRAY: lambda: b"".join(pv.byte_array_value),
        T.PARAMETER_BOOL_ARRAY: lambda: list(pv.bool_array_value),
        T.PARAMETER_INTEGER_ARRAY: lambda: list(pv.integer_array_value),
        T.PARAMETER_DOUBLE_ARRAY: lambda: list(pv.double_array_value),
        T.PARAMETER_STRING_ARRAY: lambda: list(pv.string_array_value),
    }.get(pv.type, lambda: None)()


PARAMETER_TYPE_LABELS = {
    # ParameterType -> (label, as ros2 param get prints it)
    1: "Boolean value is:",
    2: "Integer value is:",
    3: "Double value is:",
    4: "String value is:",
    5: "Byte values are:",
    6: "Boolean values are:",
    7: "Integer values are:",
    8: "Double values are:",
    9: "String values are:",
}


def _param_service(target_node: str, service: str) -> str:
    return fully_qualified_node_name(target_node).rstrip("/") + "/" + service


def get_parameters(node: Any, target_node: str, names: Iterable[str], *, timeout: float = 10.0) -> list:
    """``target_node``'s ParameterValues for ``names`` via ``<node>/get_parameters``."""
    from rcl_interfaces.srv import GetParameters
    request = GetParameters.Request(names=list(names))
    response = call_service(node, GetParameters, _param_service(target_node, "get_parameters"),
                            request, timeout=timeout)
    return list(response.values)


def set_parameters(node: Any, target_node: str, values: dict[str, Any], *,
                   timeout: float = 10.0) -> list:
    """Set parameters via ``<node>/set_parameters``; values are ParameterValue messages or plain
    Python values. Returns one rcl_interfaces/SetParametersResult per parameter."""
    from rcl_interfaces.msg import Parameter, ParameterValue
    from rcl_interfaces.srv import SetParameters
    params = [Parameter(name=name, value=v if isinstance(v, ParameterValue)
                        else parameter_value_from_python(v)) for name, v in values.items()]
    response = call_service(node, SetParameters, _param_service(target_node, "set_parameters"),
                            SetParameters.Request(parameters=params), timeout=timeout)
    return list(response.results)


def list_parameters(node: Any, target_node: str, *, timeout: float = 10.0) -> list[str]:
    """Names of all of ``target_node``'s parameters, sorted."""
    from rcl_interfaces.srv import ListParameters
    response = call_service(node, ListParameters, _param_service(target_node, "list_parameters"),
                            ListParameters.Request(depth=ListParameters.Request.DEPTH_RECURSIVE),
                            timeout=timeout)
    return sorted(response.result.names)
