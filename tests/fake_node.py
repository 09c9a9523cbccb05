"""A stand-in node executable for the harness self-test (tests/test_harness.py).

Behaves like the suite's nodes as the harness sees them: takes ``--ros-args`` (remaps, ``-p``,
``--params-file``), honours ROS_DOMAIN_ID, serves the parameter services, publishes
std_msgs/String on ``chatter`` at parameter ``rate`` Hz with ``data = "<prefix> <n>"``, refuses
``rate <= 0`` with a reason, and exits 0 on SIGINT.
"""

from __future__ import annotations

import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import rosutil  # noqa: E402

rosutil.setup_process_environment()

import rclpy  # noqa: E402
from rcl_interfaces.msg import SetParametersResult  # noqa: E402
from rclpy.executors import ExternalShutdownException  # noqa: E402
from rclpy._rclpy_pybind11 import RCLError  # noqa: E402
from rclpy.node import Node  # noqa: E402
from std_msgs.msg import String  # noqa: E402


class FakeNode(Node):
    def __init__(self) -> None:
        super().__init__("fake_talker")
        self.declare_parameter("rate", 10.0)
        self.declare_parameter("prefix", "tick")
        self.count = 0
        self.pub = self.create_publisher(String, "chatter", 10)
        self.timer = self.create_timer(1.0 / self.get_parameter("rate").value, self.tick)
        self.add_on_set_parameters_callback(self.on_set)
        print(f"fake_talker up as {self.get_fully_qualified_name()}", flush=True)

    def on_set(self, params: list) -> SetParametersResult:
        for p in params:
            if p.name == "rate":
                if p.value <= 0:
                    return SetParametersResult(successful=False, reason="rate must be > 0")
                self.timer.timer_period_ns = int(1e9 / p.value)
        return SetParametersResult(successful=True)

    def tick(self) -> None:
        self.count += 1
        try:
            self.pub.publish(String(data=f"{self.get_parameter('prefix').value} {self.count}"))
        except RCLError:
            # SIGINT shuts the context down under a timer callback already running: the node
            # is stopping, not failing (a CI run once exited 1 here).
            if rclpy.ok():
                raise


def main() -> int:
    rclpy.init(args=sys.argv)
    node = FakeNode()
    try:
        try:
            rclpy.spin(node)
        except RCLError:
            # SIGINT shut the context down between two waits: the executor's next wait set
            # fails on the dead context (a CI run exited 1 here); the node is stopping, not
            # failing. (Inside the outer try: the KeyboardInterrupt SIGINT also queued may
            # surface here.)
            if rclpy.ok():
                raise
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    print("fake_talker: shutting down", flush=True)
    node.destroy_node()
    rclpy.try_shutdown()
    return 0


if __name__ == "__main__":
    sys.exit(main())
