"""The fuzz tests' shared part: the seed, hostile numbers, broken CDR buffers, and ``Fuzz``, which
gathers every violation of the invariants with the case that caused it and fails once, listing
them (tests/test_fuzz.py: chassis_node and sim_node; tests/test_fuzz_nav.py: local_nav_node,
planner_node, terrain_node, gait_node).
"""

from __future__ import annotations

import math
import os
import random
import re
import struct
import time
from collections import Counter
from pathlib import Path
from typing import Any, Callable, Optional

import harness
from harness import param_get
from rosutil import message_to_dict

SEED = int(os.environ.get("MOBIL_FUZZ_SEED", "20261129"))
print(f"test_fuzz: seed {SEED} (replay with MOBIL_FUZZ_SEED={SEED})")

NAN, INF = float("nan"), float("inf")
# Non-finite, the largest finite, denormal, the smallest normal and a negative zero.
SPECIALS = [NAN, INF, -INF, 1e308, -1e308, 5e-324, -5e-324, 2.2250738585072014e-308, -0.0]
PER_CALL_TIMEOUT = 5.0
# Lines chassis_node and sim_node log about bad input, and how many kinds of fault each throttles separately
# (the keys of its warn_throttled! calls whose lines BAD_INPUT_LINE can match: chassis_node's
# cmd_nan, clamp, cmd_decode, feedback_gap, feedback_kinematics, feedback_time,
# feedback_implausible, joints_lengths, joints_missing, joints_field, joints_nan, stamp,
# joints_decode; sim_node's cmd, decode).
BAD_INPUT_LINE = re.compile(r"dropped|deserializ|clamped|NaN/inf|stamps jumped")
THROTTLE_KEYS = {"chassis_node": 13, "sim_node": 2}


def rng_for(test: str) -> random.Random:
    """One generator per test, from the seed and the test's name, so each replays alone."""
    return random.Random(f"{SEED}:{test}")


def number(rng: random.Random, lo: float = -2.0, hi: float = 2.0, special: float = 0.5) -> float:
    return rng.choice(SPECIALS) if rng.random() < special else rng.uniform(lo, hi)


def non_finite_numbers(msg: Any) -> list[str]:
    """Paths of the non-finite floats anywhere in a message."""
    bad: list[str] = []

    def walk(value: Any, path: str) -> None:
        if isinstance(value, float):
            if not math.isfinite(value):
                bad.append(f"{path}={value}")
        elif isinstance(value, dict):
            for k, v in value.items():
                walk(v, f"{path}.{k}" if path else k)
        elif isinstance(value, list):
            for i, v in enumerate(value):
                walk(v, f"{path}[{i}]")

    walk(message_to_dict(msg), "")
    return bad


class Fuzz:
    """Violations of the invariants, with the case that was running when each was seen."""

    def __init__(self, test: str) -> None:
        self.test = test
        self.case = "start-up"
        self.problems: list[tuple[str, str]] = []  # (with its case, as seen)
        self._seen: dict[str, int] = {}
        self.counts: dict[str, int] = {}
        self._subs: list[tuple[Any, Any]] = []

    def fail(self, text: str) -> None:
        """Record a violation; a repeat of the same one is only counted."""
        if text in self._seen:
            self._seen[text] += 1
            return
        self._seen[text] = 1
        if len(self.problems) < 40:
            self.problems.append((f"[{self.case}] {text}", text))

    def repeated(self, times: int) -> bool:
        """Whether the last violation has now been seen ``times`` times: a loop that keeps
        timing out on a known failure stops there, so a failing run stays short."""
        last = self.problems[-1][1] if self.problems else None
        if last is not None and self._seen.get(last, 0) >= times:
            self.fail(f"(stopped repeating after {times} times)")
            return True
        return False

    def check(self, ok: bool, text: str) -> bool:
        if not ok:
            self.fail(text)
        return ok

    def count(self, kind: str, n: int = 1) -> None:
        self.counts[kind] = self.counts.get(kind, 0) + n

    def watch(self, node: Any, msg_type: type, topic: str,
              extra: Optional[Callable[[Any], list[str]]] = None,
              nan_allowed: frozenset[str] = frozenset()) -> None:
        """Check every message of ``topic`` as it arrives: finite numbers (NaN allowed in the
        top-level fields named), plus ``extra``."""
        def callback(msg: Any) -> None:
            self.count(f"received {topic}")
            bad = [b for b in non_finite_numbers(msg)
                   if not (b.split("=")[0] in nan_allowed and b.endswith("=nan"))]
            problems = [f"non-finite {', '.join(bad[:4])}{' …' if len(bad) > 4 else ''}"] if bad else []
            problems += extra(msg) if extra else []
            for p in problems:
                self.fail(f"{topic}: {p}")
        qos = harness.make_qos("reliable", "volatile", 1000)
        self._subs.append((node, node.create_subscription(msg_type, topic, callback, qos)))

    def wheel_limits(self, limits: tuple[float, float]) -> Callable[[Any], list[str]]:
        """Wheel speeds and steering angles within (max wheel speed, max steering angle)."""
        max_speed, max_steer = limits

        def check(msg: Any) -> list[str]:
            out = []
            if any(abs(v) > max_speed * (1 + 1e-9) for v in msg.velocity):
                out.append(f"wheel speed beyond {max_speed} rad/s: {list(msg.velocity)}")
            if any(abs(p) > max_steer * (1 + 1e-9) for p in msg.position):
                out.append(f"steering beyond {max_steer} rad: {list(msg.position)}")
            return out
        return check

    def status_checks(self) -> Callable[[Any], list[str]]:
        """The rejected count never decreases; with a watchdog expired nothing is commanded."""
        last = [0]

        def check(msg: Any) -> list[str]:
            out = []
            if msg.rejected_messages < last[0]:
                out.append(f"rejected_messages went back from {last[0]} to {msg.rejected_messages}")
            last[0] = max(last[0], msg.rejected_messages)
            c = msg.commanded
            if (msg.watchdog_expired or msg.feedback_stale) and (c.linear.x, c.linear.y, c.angular.z) != (0, 0, 0):
                out.append(f"commanded {message_to_dict(c)} with watchdog_expired {msg.watchdog_expired}, "
                           f"feedback_stale {msg.feedback_stale}")
            return out
        return check

    def close(self) -> None:
        for node, sub in self._subs:
            node.destroy_subscription(sub)
        self._subs.clear()

    def finish(self, *procs: harness.NodeProcess) -> None:
        """The processes still run, never panicked and logged bad input at a limited rate; then
        fail with every problem seen."""
        self.case = "end"
        for proc in procs:
            self.check(proc.running, f"{proc.name} exited with {proc.proc.poll()}")
            log = proc.log_text()
            elapsed = time.monotonic() - proc.started_at
            exe = Path(next(c for c in proc.cmd if c.endswith(("_node", "_sim")))).name
            if exe in THROTTLE_KEYS:
                # One line per kind of fault per 2 s (mobil_ros's LogThrottle), whatever the flood.
                kinds = THROTTLE_KEYS[exe]
                about_input = [line for line in log.splitlines() if BAD_INPUT_LINE.search(line)]
                self.count(f"{proc.name} log lines about bad input", len(about_input))
                self.check(len(about_input) <= kinds * (elapsed / 2 + 1),
                           f"{proc.name} logged {len(about_input)} lines about bad input in {elapsed:.1f} s "
                           f"(at most {kinds} kinds every 2 s), e.g. {about_input[-1:]}")
            else:
                # Every call site of the log: a burst of 10 lines, then one a second
                # (mobil_ros::log::LineBudget); lines told apart by their text, numbers aside.
                kinds = Counter(re.sub(r"[-+\d.e]+", "#", line.split(" ", 2)[-1])[:60]
                                for line in log.splitlines())
                worst, n = kinds.most_common(1)[0] if kinds else ("", 0)
                self.count(f"{proc.name} log lines", sum(kinds.values()))
                self.check(n <= 10 + elapsed + 1,
                           f"{proc.name} logged {n} lines like `{worst}` in {elapsed:.1f} s "
                           f"(a call site may write 10, then one a second)")
            self.check("panicked" not in log, f"{proc.name} panicked:\n"
                       + "\n".join(line for line in log.splitlines() if "panick" in line)[:2000])
        self.close()
        summary = ", ".join(f"{k}: {v}" for k, v in sorted(self.counts.items()))
        print(f"{self.test} (seed {SEED}): {summary}")
        listed = [f"{shown} (×{self._seen[text]})" if self._seen[text] > 1 else shown
                  for shown, text in self.problems]
        assert not listed, (f"{self.test}, seed {SEED} (replay with MOBIL_FUZZ_SEED={SEED}): "
                            f"{sum(self._seen.values())} violation(s)\n  " + "\n  ".join(listed)
                            + f"\ncounts: {summary}")


def answers_parameter_get(fuzz: Fuzz, ros_node: Any, node: str, name: str, expected: Any) -> None:
    """Called once at start-up too: the service client is then matched before the fuzz (a new
    client's matching can take seconds while the nodes are busy)."""
    try:
        value = param_get(ros_node, node, name, timeout=10.0)
        fuzz.check(value == expected, f"{node} {name} = {value!r}, expected {expected!r}")
    except TimeoutError as exc:
        fuzz.fail(f"{node} no longer answers get_parameters: {exc}")


def mutate(rng: random.Random, valid: bytes) -> tuple[bytes, str]:
    """A broken serialization of a message: cut, extended, bit-flipped, random, or with a
    sequence length of ~4 billion. Returns the bytes and what was done."""
    kind = rng.randrange(6)
    if kind == 0:
        return valid[:rng.randrange(0, len(valid))], "truncated"
    if kind == 1:
        return valid + bytes(rng.randrange(256) for _ in range(rng.randint(1, 200))), "over-long"
    if kind == 2:
        buf = bytearray(valid)
        for _ in range(rng.randint(1, 8)):
            buf[rng.randrange(len(buf))] ^= 1 << rng.randrange(8)
        return bytes(buf), "bit flips"
    if kind == 3:
        return valid[:4] + bytes(rng.randrange(256) for _ in range(rng.randint(0, 120))), "random body"
    if kind == 4:
        return bytes(rng.randrange(256) for _ in range(rng.randint(0, 120))), "random bytes"
    # A sequence or string length field (4-byte aligned in the body) set huge.
    buf = bytearray(valid)
    offsets = list(range(4, len(buf) - 3, 4))
    off = rng.choice(offsets)
    buf[off:off + 4] = struct.pack("<I", rng.choice([0xFFFFFFFF, 0x7FFFFFFF, 0x10000000]))
    return bytes(buf), "huge length"


WRONG_TYPES = [True, 7, 1.5, "text", [1.5, 2.5], [1, 2], [True, False], ["a", "b"], b"\x01\x02"]


def same_type(a: Any, b: Any) -> bool:
    if isinstance(a, list) and isinstance(b, list):
        return bool(a) and bool(b) and type(a[0]) is type(b[0])
    return type(a) is type(b)
