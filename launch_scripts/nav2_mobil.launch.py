"""mobil's Nav2-role nodes (local_nav, planner, drive) brought up by nav2_lifecycle_manager.

    ros2 launch launch_scripts/nav2_mobil.launch.py robot_params:=params/omr3.yaml

The executables are found on PATH (put target/release on it). The nodes start unconfigured
(params/nav2_mobil.yaml: autostart false); the manager configures and activates them in the
order of its node_names and keeps a bond with each (docs/nav2.md). Set cmd_vel_topic:=cmd_vel_nav
to feed Nav2's velocity smoother and collision monitor instead of the chassis directly.
"""

import os

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

HERE = os.path.dirname(os.path.abspath(__file__))
PARAMS = os.path.normpath(os.path.join(HERE, "..", "params"))


def generate_launch_description():
    robot_params = LaunchConfiguration("robot_params")
    nav2_params = LaunchConfiguration("params_file")
    cmd_vel = LaunchConfiguration("cmd_vel_topic")
    remap = [("cmd_vel", cmd_vel)]
    managed = [
        Node(executable=exe, name=name, output="screen", parameters=[robot_params, nav2_params],
             remappings=remap)
        for exe, name in (("local_nav_node", "local_nav"), ("planner_node", "planner"),
                          ("drive_node", "drive"))
    ]
    return LaunchDescription([
        DeclareLaunchArgument("robot_params", default_value=os.path.join(PARAMS, "omr3.yaml")),
        DeclareLaunchArgument("params_file", default_value=os.path.join(PARAMS, "nav2_mobil.yaml")),
        DeclareLaunchArgument("cmd_vel_topic", default_value="cmd_vel"),
        *managed,
        Node(package="nav2_lifecycle_manager", executable="lifecycle_manager",
             name="lifecycle_manager_mobil", output="screen", parameters=[nav2_params]),
    ])
