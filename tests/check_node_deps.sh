#!/usr/bin/env bash
# No node crate (a `*_node` package) depends on another one: what two shells share is kit
# (mobil_ros) or method (a ROS-free crate), never another shell. Normal, build and dev
# dependencies all count.
set -euo pipefail
cd "$(dirname "$0")/.."
cargo metadata --format-version 1 --no-deps | python3 -c '
import json, sys
packages = json.load(sys.stdin)["packages"]
names = {p["name"] for p in packages}
bad = []
for p in packages:
    if not p["name"].endswith("_node"):
        continue
    for d in p["dependencies"]:
        if d["name"].endswith("_node") and d["name"] in names:
            kind = d["kind"] or "normal"
            bad.append(p["name"] + " -> " + d["name"] + " (" + kind + ")")
for b in bad:
    print(f"check_node_deps: a node crate depends on another: {b}", file=sys.stderr)
nodes = sorted(n for n in names if n.endswith("_node"))
if not bad:
    print(f"check_node_deps: {len(nodes)} node crates, none depends on another")
sys.exit(1 if bad else 0)
'
