#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# msf_ros_node fed a bag by `rosbag play` at RATE (1.0 = as recorded; KITTI: 10 Hz) with QUEUE
# frames waiting at most (the node's default 1): prints the node's account at shutdown (frames
# received, reconstructed, dropped and why, the engine's time a frame). A roscore of its own on
# a free port; everything it starts is stopped on exit (tests/ros/ros_session.sh).
#   bench/ros_node.sh BUILD_DIR BAG RATE [QUEUE]
set -euo pipefail
build=$1
bag=$(realpath "$2")
rate=$3
queue=${4:-1}
source "$(dirname "$0")/../tests/ros/ros_session.sh"
ros_session_start "$build"
ros_session_wait_master
background launch roslaunch --wait msfusion kitti_bag.launch bag:="$bag" rate:="$rate" queue_size:="$queue"
launcher=$started
for ((k = 0; ; ++k)); do
  grep -q -a "player-2. process has finished" "$work/launch.log" && break
  kill -0 "$launcher" 2>/dev/null || fail "roslaunch stopped: $(tail -5 "$work/launch.log")"
  sleep 0.2
done
stop_group "$launcher" 60 # the node finishes the frames waiting, then gives its account
echo "rate $rate, queue $queue: $(node_lines "$work/launch.log" | grep -a -A3 "scans received")"
ros_session_stop
