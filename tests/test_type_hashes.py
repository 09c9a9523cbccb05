"""REP-2011 type hashes (RIHS01) that mobil_msgs computes at build time from the `.msg` /
`.srv` / `.action` closure, against the hashes rosidl generated into the type-description JSON
files: of the ROS 2 Jazzy packages installed with rclpy (std_msgs, geometry_msgs, ...) and of
the mobil_msgs / nav2_msgs / bond build that tests/setup_env.sh makes. Every type the suite
builds must be found there, with the same hash."""

from __future__ import annotations

import json
import subprocess

import harness
from harness import ROOT


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
    assert len(ours) >= 90, len(ours)
    missing = sorted(set(ours) - set(refs))
    assert not missing, f"no rosidl hash to compare with for {missing}"
    differ = {name: (ours[name], refs[name]) for name in ours if ours[name] != refs[name]}
    assert not differ, differ
    # The four the suite's topics use most, by name.
    for name in ("nav_msgs/msg/Odometry", "sensor_msgs/msg/LaserScan", "geometry_msgs/msg/Twist",
                 "mobil_msgs/msg/NavStatus"):
        assert name in ours
