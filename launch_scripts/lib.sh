# Shared by the launch scripts: build once, start nodes, stop them all on exit/Ctrl-C.
# shellcheck shell=bash
set -euo pipefail
MOBIL_ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
MOBIL_BIN="${MOBIL_BIN_DIR:-$MOBIL_ROOT/target/release}"
MOBIL_PIDS=()

mobil_build() {
  if [ "${MOBIL_SKIP_BUILD:-0}" != 1 ]; then
    echo "building (cargo build --release; first time a few minutes, then seconds)..." >&2
    (cd "$MOBIL_ROOT" && cargo build --release --quiet --bins)
  fi
}

# mobil_start NAME ARGS...: start target/release/NAME in the background, remember its pid.
mobil_start() {
  local exe="$1"; shift
  "$MOBIL_BIN/$exe" "$@" &
  MOBIL_PIDS+=("$!")
}

# Stop every started node: SIGINT first (clean DDS leave), SIGKILL after 5 s.
mobil_stop_all() {
  local pid
  for pid in "${MOBIL_PIDS[@]}"; do kill -INT "$pid" 2>/dev/null || true; done
  for _ in $(seq 50); do
    local alive=0
    for pid in "${MOBIL_PIDS[@]}"; do kill -0 "$pid" 2>/dev/null && alive=1; done
    [ "$alive" = 0 ] && break
    sleep 0.1
  done
  for pid in "${MOBIL_PIDS[@]}"; do kill -KILL "$pid" 2>/dev/null || true; done
  wait 2>/dev/null || true
  MOBIL_PIDS=()
}

trap 'mobil_stop_all' EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

# mobil_robot PARAMS_FILE [--no-sim] [--nav] [--plan] [extra --ros-args...]: run a robot's
# nodes until Ctrl-C; --nav adds local_nav_node (goals from goal_pose / navigate_to_pose),
# --plan adds planner_node (dock_pose, waypoints, dock_robot, undock_robot, follow_waypoints).
# Both publish cmd_vel only while a goal of theirs runs.
mobil_robot() {
  local params="$1"; shift
  local sim=1 nav=0 plan=0
  while [ "${1:-}" = "--no-sim" ] || [ "${1:-}" = "--nav" ] || [ "${1:-}" = "--plan" ]; do
    case "$1" in
      --no-sim) sim=0 ;;
      --nav) nav=1 ;;
      --plan) plan=1 ;;
    esac
    shift
  done
  mobil_build
  [ "$sim" = 1 ] && mobil_start sim_node --ros-args --params-file "$params" "$@"
  mobil_start chassis_node --ros-args --params-file "$params" "$@"
  [ "$nav" = 1 ] && mobil_start local_nav_node --ros-args --params-file "$params" "$@"
  [ "$plan" = 1 ] && mobil_start planner_node --ros-args --params-file "$params" "$@"
  echo "running (Ctrl-C stops every node): pids ${MOBIL_PIDS[*]}" >&2
  # Return as soon as any node exits, so a crash is not hidden.
  wait -n "${MOBIL_PIDS[@]}" || true
}
