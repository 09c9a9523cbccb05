"""The suite across hosts: three network namespaces on one link (a bridge in a fourth), as three
computers on a switch. sim_node (the robot's hardware: wheels and LIDAR) on the first,
chassis_node and local_nav_node on the second, and an rclpy (Fast DDS) client on the third that
sends a goal on ``goal_pose`` and watches ``odom`` until the robot is there. The scan, the wheel
feedback and the wheel commands cross between the first two; the goal and the odometry between
the last two.

- with multicast (ROS_AUTOMATIC_DISCOVERY_RANGE unset: SUBNET), the goal is reached;
- with multicast off on every link and ROS_STATIC_PEERS naming the other hosts, the goal is
  reached (discovery by unicast only);
- without the peers, it is not;
- with ROS_AUTOMATIC_DISCOVERY_RANGE=LOCALHOST on the nodes, a client on their host sees them and
  one on the third host none.
"""

from __future__ import annotations

import json
import os
import shutil
import subprocess
from pathlib import Path
from typing import Iterator

import pytest

import rosutil

ROOT = Path(__file__).resolve().parent.parent
PYTHON = ROOT / ".venv" / "bin" / "python"
PARAMS = "params/omr3.yaml"
WORLD = str(ROOT / "params" / "worlds" / "local_nav_open.yaml")
GOAL = ("1.5", "0.5")


def _ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, text=True, timeout=10)


class Hosts:
    """Three namespaces with an address each on one bridged link."""

    def __init__(self, tag: str, names: list[str], addresses: list[str]) -> None:
        self.tag = tag
        self.names = names
        self.addresses = addresses

    def exec(self, i: int) -> list[str]:
        return ["ip", "netns", "exec", self.names[i]]

    def peers_of(self, i: int) -> str:
        return ";".join(a for j, a in enumerate(self.addresses) if j != i)

    def multicast(self, on: bool) -> None:
        """Multicast on or off on every host's link (off: the kernel sends none)."""
        for i, ns in enumerate(self.names):
            _ip("-n", ns, "link", "set", f"mh{self.tag}h{i}", "multicast", "on" if on else "off")
            if on:
                subprocess.run(["ip", "-n", ns, "route", "replace", "224.0.0.0/4", "dev", f"mh{self.tag}h{i}"],
                               capture_output=True, timeout=10)
            else:
                subprocess.run(["ip", "-n", ns, "route", "del", "224.0.0.0/4"], capture_output=True, timeout=10)


@pytest.fixture
def three_hosts() -> Iterator[Hosts]:
    if os.geteuid() != 0 or shutil.which("ip") is None:
        pytest.skip("network namespaces need root and iproute2's ip")
    tag = f"{os.getpid() % 10000}"
    switch = f"mobil_mh_{tag}_sw"
    names = [f"mobil_mh_{tag}_{i}" for i in range(3)]
    net = f"10.214.{os.getpid() % 250}"
    addresses = [f"{net}.{i + 1}" for i in range(3)]
    # Namespaces a killed run left behind.
    listed = subprocess.run(["ip", "netns", "list"], capture_output=True, text=True, timeout=10).stdout
    for stale in (line.split()[0] for line in listed.splitlines() if line.startswith("mobil_mh_")):
        subprocess.run(["ip", "netns", "del", stale], capture_output=True, timeout=10)
    try:
        _ip("netns", "add", switch)
        _ip("-n", switch, "link", "add", "br0", "type", "bridge", "mcast_snooping", "0")
        _ip("-n", switch, "link", "set", "br0", "up")
        for i, ns in enumerate(names):
            host, port = f"mh{tag}h{i}", f"mh{tag}s{i}"
            _ip("netns", "add", ns)
            _ip("link", "add", host, "type", "veth", "peer", "name", port)
            _ip("link", "set", host, "netns", ns)
            _ip("link", "set", port, "netns", switch)
            _ip("-n", switch, "link", "set", port, "master", "br0", "up")
            _ip("-n", ns, "addr", "add", f"{addresses[i]}/24", "dev", host)
            _ip("-n", ns, "link", "set", "lo", "up")
            _ip("-n", ns, "link", "set", host, "up", "multicast", "on")
            _ip("-n", ns, "route", "add", "224.0.0.0/4", "dev", host)
        yield Hosts(tag, names, addresses)
    finally:
        for i in range(3):  # a host end not moved yet
            subprocess.run(["ip", "link", "del", f"mh{tag}h{i}"], capture_output=True, timeout=10)
        for ns in [*names, switch]:
            subprocess.run(["ip", "netns", "del", ns], capture_output=True, timeout=10)


def start_robot(start_node, hosts: Hosts, env: dict[int, dict[str, str]]) -> None:
    """sim_node on host 0, chassis_node and local_nav_node on host 1."""
    start_node("sim_node", "-p", f"world_file:={WORLD}", params_file=PARAMS, prefix=hosts.exec(0), env=env[0])
    start_node("chassis_node", params_file=PARAMS, prefix=hosts.exec(1), env=env[1])
    start_node("local_nav_node", params_file=PARAMS, prefix=hosts.exec(1), env=env[1])


def goal_from(hosts: Hosts, env: dict[str, str], timeout: float = 40.0) -> tuple[int, dict]:
    child = rosutil.ros_environ()
    child.update(env)
    done = subprocess.run([*hosts.exec(2), str(PYTHON), str(ROOT / "tests" / "netns_goal_client.py"), *GOAL,
                           "--timeout", str(timeout)],
                          capture_output=True, text=True, timeout=timeout + 30, env=child)
    lines = [line for line in done.stdout.splitlines() if line.startswith("{")]
    return done.returncode, (json.loads(lines[-1]) if lines else {"stderr": done.stderr[-2000:]})


@pytest.mark.closed_loop  # a real-time drive: never beside the demo or the soak (RUNNING_ALONE)
def test_a_goal_across_three_hosts_with_multicast(three_hosts, start_node):
    start_robot(start_node, three_hosts, {0: {}, 1: {}})
    rc, result = goal_from(three_hosts, {})
    assert rc == 0 and result["reached"], result


@pytest.mark.closed_loop
def test_a_goal_across_three_hosts_without_multicast_by_static_peers(three_hosts, start_node):
    three_hosts.multicast(False)
    env = {i: {"ROS_STATIC_PEERS": three_hosts.peers_of(i)} for i in range(3)}
    start_robot(start_node, three_hosts, env)
    rc, result = goal_from(three_hosts, env[2])
    assert rc == 0 and result["reached"], result


@pytest.mark.closed_loop
def test_without_multicast_and_without_static_peers_the_graph_does_not_form(three_hosts, start_node):
    """The control of the test above: the same links, no peers named, no goal reached."""
    three_hosts.multicast(False)
    start_robot(start_node, three_hosts, {0: {}, 1: {}})
    rc, result = goal_from(three_hosts, {}, timeout=8.0)
    assert rc == 1 and not result["odom_seen"], result


def node_list(hosts: Hosts, i: int, env: dict[str, str]) -> list[str]:
    child = rosutil.ros_environ()
    child.update(env)
    done = subprocess.run([*hosts.exec(i), str(PYTHON), str(ROOT / "tests" / "ros2cli.py"), "node", "list",
                           "--spin-time", "4"], capture_output=True, text=True, timeout=60, env=child)
    assert done.returncode == 0, done.stderr[-2000:]
    return done.stdout.split()


@pytest.mark.closed_loop
def test_localhost_range_keeps_the_nodes_from_other_hosts(three_hosts, start_node):
    local = {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    start_robot(start_node, three_hosts, {0: local, 1: local})
    # Their own host sees them (a LOCALHOST client beside chassis and local_nav) ...
    assert {"/chassis", "/local_nav"} <= set(node_list(three_hosts, 1, local))
    # ... the third host, by multicast, sees none of the three.
    seen = node_list(three_hosts, 2, {})
    assert not {"/chassis", "/local_nav", "/sim"} & set(seen), seen
