#!/usr/bin/env bash
# Finds a Python interpreter of a version that ROS 2 Jazzy's wheels support (3.11, 3.12) and
# prints its path; exit 1 if there is none.
#   find_python.sh 3.12              an interpreter of that version
#   find_python.sh --other PYTHON    one of the other supported version than PYTHON's
# Looks on PATH (pythonX.Y), in /usr/bin and /usr/local/bin, and in pyenv's versions, and checks
# that each candidate actually runs (a pyenv shim of a version not selected does not).
set -uo pipefail
SUPPORTED="3.11 3.12"

version_of() { "$1" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")' 2>/dev/null; }

find_version() {
  local want="$1" c
  local candidates=("python$want" "/usr/bin/python$want" "/usr/local/bin/python$want")
  local root="${PYENV_ROOT:-$HOME/.pyenv}"
  for c in "$root"/versions/"$want"*/bin/python"$want"; do candidates+=("$c"); done
  for c in "${candidates[@]}"; do
    local path
    path="$(command -v "$c" 2>/dev/null)" || continue
    if [ "$(version_of "$path")" = "$want" ]; then
      # A pyenv shim resolves through pyenv each time; print the interpreter itself.
      "$path" -c 'import sys; print(sys.executable)'
      return 0
    fi
  done
  return 1
}

if [ "${1:-}" = --other ]; then
  have="$(version_of "${2:?--other needs a Python}")" || exit 1
  for v in $SUPPORTED; do
    [ "$v" = "$have" ] && continue
    find_version "$v" && exit 0
  done
  exit 1
fi
find_version "${1:?usage: find_python.sh X.Y | --other PYTHON}"
