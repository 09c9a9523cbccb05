"""mobil's Nav2-role nodes (local_nav, planner, drive) brought up by nav2_lifecycle_manager.

    ros2 launch launch_scripts/nav2_mobil.launch.py robot_params:=params/omr3.yaml

The executables are found on PATH (put target/release on it). The nodes start unconfigured
(params/nav2_mobil.yaml: autostart false); the manager configures and activates them in the
order of its node_names and keeps a bond with each (docs/nav2.md). Set cmd_vel_topic:=cmd_vel_nav
to feed Nav2's velocity smoother and collision monitor instead of the chassis directly.

Both local_nav and planner serve Nav2's controller role; controller:=local_nav (the default) or
controller:=planner names the one that answers `follow_path`, the other's server is moved to
`<its name>/follow_path`, so one controller drives the robot.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

HERE = os.path.dirname(os.path.abspath(__file__))
PARAMS = os.path.normpath(os.path.join(HERE, "..", "params"))


def nodes(context):
    robot_params = LaunchConfiguration("robot_params")
    nav2_params = LaunchConfiguration("params_file")
    cmd_vel = LaunchConfiguration("cmd_vel_topic")
    controller = LaunchConfiguration("controller").perform(context)
    if controller not in ("local_nav", "planner"):
        raise RuntimeError(f"controller:={controller}: give local_nav or planner")
    managed = []
    for exe, name in (("local_nav_node", "local_nav"), ("planner_node", "planner"), ("drive_node", "drive")):
        remap = [("cmd_vel", cmd_vel)]
        if name in ("local_nav", "planner") and name != controller:
            remap.append(("follow_path", f"{name}/follow_path"))
        managed.append(Node(executable=exe, name=name, output="screen",
                            parameters=[robot_params, nav2_params], remappings=remap))
    return managed


def generate_launch_description():
    nav2_params = LaunchConfiguration("params_file")
    return LaunchDescription([
        DeclareLaunchArgument("robot_params", default_value=os.path.join(PARAMS, "omr3.yaml")),
        DeclareLaunchArgument("params_file", default_value=os.path.join(PARAMS, "nav2_mobil.yaml")),
        DeclareLaunchArgument("cmd_vel_topic", default_value="cmd_vel"),
        DeclareLaunchArgument("controller", default_value="local_nav",
                              description="the node that answers follow_path: local_nav or planner"),
        OpaqueFunction(function=nodes),
        Node(package="nav2_lifecycle_manager", executable="lifecycle_manager",
             name="lifecycle_manager_mobil", output="screen", parameters=[nav2_params]),
    ])
