# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# A ROS 1 session of a script's own, sourced by tests/ros/ros_node.sh and bench/ros_node.sh:
# a scratch folder ($work), a roscore on a free port (ROS_MASTER_URI and ROS_HOME exported for
# the children), each process started with `background` in a process group of its own, and all
# of them stopped on any exit of the script, a process left over being an error.
#   source ros_session.sh; ros_session_start BUILD_DIR; background CMD...; ...; ros_session_stop

set -m # each background job leads a process group of its own
ros_groups=()

fail() {
  echo "FAILED: $*"
  exit 1
}

# Starts CMD... in the background (output to $work/NAME.log); its pid (= its group) in $started.
background() {
  local name=$1
  shift
  "$@" >"$work/$name.log" 2>&1 &
  started=$!
  ros_groups+=("$started")
}

# SIGINT (a ROS process's orderly stop) to a group, then SIGKILL after WAIT_S seconds.
stop_group() {
  local pgid=$1 wait_s=$2
  kill -INT -- "-$pgid" 2>/dev/null || return 0
  for ((k = 0; k < wait_s * 10; ++k)); do
    kill -0 -- "-$pgid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL -- "-$pgid" 2>/dev/null || true
}

# roslaunch starts each node in a session of its own (setsid): what is left of them after their
# launcher stopped is found by the scratch folder in their command line (their log path).
ros_leftovers() { pgrep -f -- "$work" || true; }

# Stops every group, newest first; fails naming what was still running after.
ros_session_stop() {
  for ((g = ${#ros_groups[@]} - 1; g >= 0; --g)); do
    stop_group "${ros_groups[g]}" 10
  done
  ros_groups=()
  local left
  left=$(ros_leftovers)
  [ -z "$left" ] || fail "processes left after the stop: $(ps -o pid=,args= -p "${left//$'\n'/,}" | cut -c1-120)"
}

ros_session_cleanup() {
  local status=$?
  for ((g = ${#ros_groups[@]} - 1; g >= 0; --g)); do
    stop_group "${ros_groups[g]}" 5
  done
  local left
  left=$(ros_leftovers)
  if [ -n "$left" ]; then
    echo "processes left running, killed: $(ps -o pid=,args= -p "${left//$'\n'/,}" | cut -c1-120)"
    kill -KILL $left 2>/dev/null || true
    status=1
  fi
  rm -rf "$work"
  exit "$status"
}

# A scratch folder, the build tree's ROS package, and a roscore on a port the kernel picks.
ros_session_start() {
  local build=$1
  work=$(mktemp -d "${TMPDIR:-/tmp}/msf_ros.XXXXXX")
  trap ros_session_cleanup EXIT
  trap 'exit 130' INT TERM
  local port
  port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
  export ROS_MASTER_URI=http://localhost:$port ROS_HOME=$work/ros_home ROS_LOG_DIR=$work/ros_home/log
  export ROS_PACKAGE_PATH=$build/ros${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}
  background roscore roscore -p "$port"
}

# Waits for the master started by ros_session_start.
ros_session_wait_master() {
  for ((k = 0; ; ++k)); do
    rosparam get /run_id >/dev/null 2>&1 && return 0
    ((k < 300)) || fail "roscore did not answer at $ROS_MASTER_URI in 30 s: $(tail -5 "$work/roscore.log")"
    sleep 0.1
  done
}

# The node's lines in a roslaunch log, without colours and the parameter listing.
node_lines() { grep -a -A3 "msf_ros_node: " "$1" | grep -a -v -e "^ \*" -e "^--" | sed 's/\x1b\[[0-9;]*m//g'; }
