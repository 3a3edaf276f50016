#!/usr/bin/env bash
# msf_ros_node against a real ROS master: a roscore of its own on a free port, a bag of KITTI
# odometry 04 frames 0..LAST written by msf_kitti2bag, the node and the player started by
# launch/kitti_bag.launch, what the node publishes recorded by `rosbag record`; then
#  - each frame's depth and weight image, fused points and the mesh marker checked against the
#    engine on the same frames (check_node_output),
#  - the mesh the node saves on shutdown equal, byte for byte, to msf_reconstruct's of the bag
#    (both read the poses and the extrinsic through tf's quaternions, so no rounding differs),
#  - the node's account at shutdown: every frame reconstructed, none dropped.
# Everything it starts runs in process groups of its own, stopped on any exit (trap).
#   ros_node.sh BUILD_DIR KITTI_DIR [LAST_FRAME]
set -euo pipefail
build=$1
kitti=$2
last=${3:-3}
frames=$((last + 1))
sequence=$kitti/odometry/sequences/04
if [ ! -d "$sequence" ]; then
  if [ "${CI:-}" = true ]; then
    echo "KITTI odometry 04 not found in '$kitti'; CI=true requires it" >&2
    exit 1
  fi
  echo "SKIPPED: KITTI odometry 04 not found in '$kitti' (set MSF_KITTI_DIR)"
  exit 77
fi

work=$(mktemp -d "${TMPDIR:-/tmp}/msf_ros_node.XXXXXX")
groups=() # process groups started (set -m: each background job leads its own)
set -m

stop_group() { # SIGINT (a ROS process's orderly stop), then SIGKILL after $2 s
  local pgid=$1 wait_s=$2
  kill -INT -- "-$pgid" 2>/dev/null || return 0
  for ((k = 0; k < wait_s * 10; ++k)); do
    kill -0 -- "-$pgid" 2>/dev/null || return 0
    sleep 0.1
  done
  kill -KILL -- "-$pgid" 2>/dev/null || true
}

# roslaunch starts each node in a session of its own (setsid): what is left of them after
# their launcher stopped is found by the unique folder in their command line or log path.
leftovers() { pgrep -f -- "$work" || true; }

cleanup() {
  local status=$?
  for ((g = ${#groups[@]} - 1; g >= 0; --g)); do
    stop_group "${groups[g]}" 5
  done
  local left
  left=$(leftovers)
  if [ -n "$left" ]; then
    echo "processes left running, killed: $(ps -o pid=,args= -p "${left//$'\n'/,}" | cut -c1-120)"
    kill -KILL $left 2>/dev/null || true
    status=1
  fi
  rm -rf "$work"
  exit "$status"
}
trap cleanup EXIT
trap 'exit 130' INT TERM

fail() {
  echo "FAILED: $*"
  exit 1
}

# A free port for the master (the kernel's pick), and ROS's files in the scratch folder.
port=$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
export ROS_MASTER_URI=http://localhost:$port ROS_HOME=$work/ros_home ROS_LOG_DIR=$work/ros_home/log
export ROS_PACKAGE_PATH=$build/ros${ROS_PACKAGE_PATH:+:$ROS_PACKAGE_PATH}
roscore -p "$port" >"$work/roscore.log" 2>&1 &
groups+=($!)

"$build/bin/msf_kitti2bag" "$sequence" -frames "0:$last" -o "$work/04.bag" >/dev/null
for ((k = 0; ; ++k)); do
  rosparam get /run_id >/dev/null 2>&1 && break
  ((k < 300)) || fail "roscore did not answer on port $port in 30 s: $(tail -5 "$work/roscore.log")"
  sleep 0.1
done

# Bad parameters: each stops the node at once, exit 1, with an error that names the parameter.
refuse() { # NAME EXPECTED _param:=value...
  local name=$1 expected=$2 out status=0
  shift 2
  out=$(timeout 30 "$build/bin/msf_ros_node" __name:="$name" "$@" 2>&1) || status=$?
  [ "$status" = 1 ] && [[ "$out" == *"msf_ros_node: error: $expected"* ]] ||
    fail "msf_ros_node $*: exit $status, '$out' (expected exit 1 and '$expected')"
  echo "ok: msf_ros_node $* refused: $expected"
}
touch "$work/mine.ply"
refuse bad_path "parameter /bad_path/mesh_path: '$work/mine.ply' exists, and a mesh is never written over a file" \
  _mesh_path:="$work/mine.ply"
[ ! -s "$work/mine.ply" ] || fail "the node wrote over '$work/mine.ply'"
refuse bad_name "unknown parameter /bad_name/queue_sise" _queue_sise:=2
refuse bad_type "parameter /bad_type/queue_size must be an integer" _queue_size:=two
refuse bad_range "parameter /bad_range/queue_size must be 1..8 frames, not 20" _queue_size:=20
refuse bad_poses "parameter /bad_poses/poses must be auto, tf or odometry, not 'gps'" _poses:=gps
refuse bad_config "parameter /bad_config/config: config '$work/none.yaml' does not exist" _config:="$work/none.yaml"

# The recorder first, so that it hears the first frame; then the node, and the player, which
# waits for the node's subscriptions. queue_size: every frame, however slow the machine.
rosbag record -q -O "$work/published.bag" /msf_ros_node/depth /msf_ros_node/weight /msf_ros_node/points \
  /msf_ros_node/mesh >"$work/record.log" 2>&1 &
groups+=($!)
recorder=$!
rostopic echo -n "$frames" /msf_ros_node/depth/header/seq >"$work/depth_seen.txt" 2>&1 &
groups+=($!)
counter=$!
roslaunch --wait msfusion kitti_bag.launch bag:="$work/04.bag" rate:=0.5 queue_size:=$frames \
  mesh_path:="$work/node_mesh.ply" >"$work/launch.log" 2>&1 &
groups+=($!)
launcher=$!

# The node is done when it has published a depth image per frame: rostopic echo -n exits then.
for ((k = 0; ; ++k)); do
  kill -0 "$counter" 2>/dev/null || break
  ((k < 600)) || fail "the node published $(grep -c '^---' "$work/depth_seen.txt") depth images of $frames in 60 s"
  sleep 0.1
done
stop_group "$launcher" 30 # the node publishes the last mesh marker, saves the mesh, gives its account
stop_group "$recorder" 10
grep -a "msf_ros_node" "$work/launch.log" | grep -a -v "^ \*" | sed 's/\x1b\[[0-9;]*m//g'

account=$(grep -a -A3 "scans received" "$work/launch.log" | sed 's/\x1b\[[0-9;]*m//g')
echo "the node's account: $account"
[[ "$account" == *"$frames scans received, $frames frames, $frames reconstructed, 0 dropped"* ]] ||
  fail "the node's account at shutdown is not every frame reconstructed: '$account'"
[ -f "$work/node_mesh.ply" ] || fail "the node saved no mesh"

"$build/tests/check_node_output" "$work/04.bag" "$work/published.bag" "$work/node_mesh.ply" ||
  fail "what the node published is not the engine's"

"$build/bin/msf_reconstruct" "$work/04.bag" -panels 0 -o "$work/reconstruct" >"$work/reconstruct.log" 2>&1 ||
  fail "msf_reconstruct: $(tail -5 "$work/reconstruct.log")"
cmp "$work/node_mesh.ply" "$work/reconstruct/mesh.ply" ||
  fail "the node's mesh differs from msf_reconstruct's of the same bag"
echo "ok: the node's mesh is msf_reconstruct's, byte for byte ($(stat -c %s "$work/node_mesh.ply") bytes)"

# All stopped in order: nothing of the run is left.
for ((g = ${#groups[@]} - 1; g >= 0; --g)); do
  stop_group "${groups[g]}" 10
done
groups=()
left=$(leftovers)
[ -z "$left" ] || fail "processes left after the stop: $(ps -o pid=,args= -p "${left//$'\n'/,}" | cut -c1-120)"
echo "ok: roscore, the node, the player and the recorder stopped; no process left"
