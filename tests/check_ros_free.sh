#!/usr/bin/env bash
# The algorithm crates must build without the ROS stack: their normal dependency tree (without
# default features) holds none of ros2-client, rustdds or tokio, so a planner that needs the
# chassis model or the geometry does not inherit DDS, and no ROS code creeps into the methods.
# Every new algorithm crate is added to CRATES.
set -euo pipefail
cd "$(dirname "$0")/.."

CRATES=(mobil_geom mobil_world mobil_chassis mobil_motion mobil_lifecycle mobil_tf mobil_sim mobil_local_nav mobil_tools mobil_planner mobil_terrain mobil_gait mobil_ga_step mobil_ga_step_sim)
FORBIDDEN='^(ros2-client|rustdds|tokio) '

status=0
for crate in "${CRATES[@]}"; do
    tree=$(cargo tree -e normal --no-default-features -p "$crate" --prefix none 2>&1) || {
        echo "check_ros_free: cargo tree -p $crate failed:" >&2
        echo "$tree" >&2
        exit 2
    }
    found=$(grep -E "$FORBIDDEN" <<<"$tree" | sort -u | tr '\n' ' ' || true)
    if [[ -n "$found" ]]; then
        echo "check_ros_free: $crate depends on the ROS stack: $found" >&2
        echo "  (cargo tree -e normal --no-default-features -i <dep> -p $crate shows the path)" >&2
        status=1
    else
        echo "check_ros_free: $crate is ROS-free"
    fi
done
exit "$status"
