#!/usr/bin/env bash
# Build the typed interface package gryffin_ros_msgs (msg/, srv/, action/ here) into a virtual environment that holds
# the ROS 2 wheels and their interface generators (the `interfaces` extra), without colcon:
#   gryffin_ros_msgs/build.sh VENV [BUILD_DIR]
# An ordinary out-of-source cmake build with the environment as prefix; nothing needs sourcing afterwards.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
venv="$(cd "${1:?usage: gryffin_ros_msgs/build.sh VENV [BUILD_DIR]}" && pwd)"
build="${2:-$here/../build/gryffin_ros_msgs}"
python="$venv/bin/python"

missing=()
command -v cmake >/dev/null || missing+=("cmake (Debian: apt-get install cmake)")
command -v c++ >/dev/null || command -v g++ >/dev/null || missing+=("a C++ compiler (Debian: apt-get install g++)")
command -v cc >/dev/null || command -v gcc >/dev/null || missing+=("a C compiler (Debian: apt-get install gcc)")
if [ ${#missing[@]} -gt 0 ]; then
  joined="$(printf '%s; ' "${missing[@]}")"
  echo "gryffin_ros_msgs cannot be built: missing ${joined%; }." >&2
  echo "The planner node's typed interfaces need it; install what is missing and run make again." >&2
  exit 2
fi
if ! "$python" -c "import rosidl_generator_py, catkin_pkg" 2>/dev/null; then
  echo "gryffin_ros_msgs cannot be built: $venv lacks the ROS 2 interface generators;" \
       "install the package with its 'interfaces' extra (make does)." >&2
  exit 2
fi

# a build folder configured from another source folder (a checkout from before the packages moved) is made anew
if [ -f "$build/CMakeCache.txt" ] && ! grep -qx "CMAKE_HOME_DIRECTORY:INTERNAL=$here" "$build/CMakeCache.txt"; then
  rm -rf "$build"
fi
mkdir -p "$build"
# colcon skips the build folder: a workspace holding this checkout under src/ must not find the generated setup.py here
touch "$build/COLCON_IGNORE"
cmake -S "$here" -B "$build" -DCMAKE_PREFIX_PATH="$venv" -DCMAKE_INSTALL_PREFIX="$venv" \
  -DPython3_EXECUTABLE="$python" -DBUILD_TESTING=OFF -DCMAKE_BUILD_TYPE=Release >"$build/configure.log" 2>&1 \
  || { tail -30 "$build/configure.log" >&2; echo "gryffin_ros_msgs: cmake configure failed (log: $build/configure.log)" >&2; exit 1; }
cmake --build "$build" --parallel "$(nproc 2>/dev/null || echo 2)" >"$build/build.log" 2>&1 \
  || { tail -30 "$build/build.log" >&2; echo "gryffin_ros_msgs: build failed (log: $build/build.log)" >&2; exit 1; }
cmake --install "$build" >"$build/install.log" 2>&1 \
  || { tail -30 "$build/install.log" >&2; echo "gryffin_ros_msgs: install failed (log: $build/install.log)" >&2; exit 1; }
"$python" -c "from gryffin_ros_msgs.action import Recommend; from gryffin_ros_msgs.msg import Observation" \
  || { echo "gryffin_ros_msgs was installed into $venv but does not import" >&2; exit 1; }
