#!/usr/bin/env bash
# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# msf_ros_node against a real ROS master: a roscore of its own on a free port, a bag of KITTI
# odometry 04 frames 0..LAST written by msf_kitti2bag, the node and the player started by
# launch/kitti_bag.launch, what the node publishes recorded by `rosbag record`; then
#  - its wait for a master that is not there, which a SIGTERM ends, and a master URI it refuses,
#  - its help (-h), every parameter of launch/kitti_bag.launch's YAML with the same default,
#  - its refusals of bad parameters,
#  - each frame's depth and weight image, fused points and the mesh marker checked against the
#    engine on the same frames (check_node_output),
#  - the mesh the node saves on shutdown equal, byte for byte, to msf_reconstruct's of the bag
#    (both read the poses and the extrinsic through tf's quaternions, so no rounding differs),
#  - the node's account at shutdown: every frame reconstructed, none dropped,
#  - ~sweeping_scans false (the rig's scans taken at one instant) making another map,
#  - nothing it started left running (ros_session.sh).
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
source "$(dirname "$0")/ros_session.sh"
ros_session_start "$build"
"$build/bin/msf_kitti2bag" "$sequence" -frames "0:$last" -o "$work/04.bag" >/dev/null
ros_session_wait_master

# No master at the URI: the node waits for one, says so, and a SIGTERM ends the wait (exit 130),
# also with a parameter to set on the master (ros::init would wait for it in silence).
no_master=http://localhost:$(python3 -c 'import socket; s = socket.socket(); s.bind(("localhost", 0)); print(s.getsockname()[1])')
ROS_MASTER_URI=$no_master "$build/bin/msf_ros_node" __name:=waiting _queue_size:=2 >"$work/waiting.log" 2>&1 &
waiting=$!
for _ in $(seq 100); do
  grep -q "waiting for the ROS master at $no_master" "$work/waiting.log" && break
  sleep 0.1
done
kill -TERM "$waiting"
for _ in $(seq 50); do
  kill -0 "$waiting" 2>/dev/null || break
  sleep 0.1
done
if kill -0 "$waiting" 2>/dev/null; then
  kill -KILL "$waiting"
  fail "msf_ros_node waiting for a master went on 5 s after a SIGTERM: $(tr '\n' ' ' <"$work/waiting.log")"
fi
status=0
wait "$waiting" || status=$?
[ "$status" = 130 ] && grep -q "waiting for the ROS master at $no_master" "$work/waiting.log" &&
  grep -q "stopped while waiting for the ROS master; nothing was done" "$work/waiting.log" ||
  fail "msf_ros_node without a master: exit $status, '$(tr '\n' ' ' <"$work/waiting.log")'"
echo "ok: without a master the node waits for one, and a SIGTERM ends the wait"
# A master URI that ROS cannot parse (it would stop the node with a breakpoint trap): exit 1,
# naming the URI and where it came from.
for bad in "env:notauri" "arg:http//localhost"; do
  status=0
  if [ "${bad%%:*}" = env ]; then
    out=$(ROS_MASTER_URI=${bad#env:} timeout 30 "$build/bin/msf_ros_node" __name:=bad_uri 2>&1) || status=$?
    expected="the ROS master's URI '${bad#env:}' (ROS_MASTER_URI) is not of the form http://host:port"
  else
    out=$(timeout 30 "$build/bin/msf_ros_node" __name:=bad_uri "__master:=${bad#arg:}" 2>&1) || status=$?
    expected="the ROS master's URI '${bad#arg:}' (the argument __master:=) is not of the form http://host:port"
  fi
  [ "$status" = 1 ] && [[ "$out" == *"msf_ros_node: error: $expected"* ]] ||
    fail "msf_ros_node with the master URI ${bad#*:}: exit $status, '$out' (expected exit 1 and '$expected')"
  echo "ok: a master URI of '${bad#*:}' refused: $expected"
done

# -h lists every parameter of the launch file's YAML with the value it gives there (the node's
# defaults), and needs no master.
help=$(ROS_MASTER_URI=$no_master timeout 10 "$build/bin/msf_ros_node" -h) || fail "msf_ros_node -h failed"
python3 - "$(dirname "$0")/../../modules/ros/config/kitti_bag.yaml" "$help" <<'PY' || fail "msf_ros_node -h and kitti_bag.yaml differ"
import re, sys, yaml
params = yaml.safe_load(open(sys.argv[1]))
shown = dict(re.findall(r"^  (\w+) = (.*)$", sys.argv[2], re.M))
assert set(shown) == set(params), (sorted(shown), sorted(params))
for name, value in params.items():
    if name == "sweeping_scans":  # unset in the node: the rig's, else true, as the file sets it
        assert shown[name] == "the rig's, else true", shown[name]
    elif isinstance(value, str):
        assert shown[name] == '"%s"' % value, (name, shown[name], value)
    else:
        assert yaml.safe_load(shown[name]) == value, (name, shown[name], value)
PY
echo "ok: msf_ros_node -h lists kitti_bag.yaml's parameters with its values, without a master"

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
refuse bad_path "parameter /bad_path/mesh_path: '$work/mine.ply' exists; set /bad_path/overwrite true to replace it" \
  _mesh_path:="$work/mine.ply"
[ ! -s "$work/mine.ply" ] || fail "the node wrote over '$work/mine.ply'"
refuse bad_name "unknown parameter /bad_name/queue_sise" _queue_sise:=2
refuse bad_type "parameter /bad_type/queue_size must be an integer" _queue_size:=two
refuse bad_range "parameter /bad_range/queue_size must be 1..8 frames, not 20" _queue_size:=20
refuse bad_poses "parameter /bad_poses/poses must be auto, tf, odometry or refine, not 'gps'" _poses:=gps
refuse bad_config "parameter /bad_config/config: config '$work/none.yaml' does not exist" _config:="$work/none.yaml"
refuse bad_sweep "parameter /bad_sweep/sweeping_scans must be true or false" _sweeping_scans:=maybe
refuse bad_overwrite "parameter /bad_overwrite/overwrite must be true or false" _overwrite:=sometimes
refuse bad_ext "parameter /bad_ext/mesh_path: cannot write mesh '$work/m.txt': use .ply, .obj or .vtk" \
  _mesh_path:="$work/m.txt"
refuse bad_rig "parameter /bad_rig/rig: calibration '$work/none.yaml' does not exist" _rig:="$work/none.yaml"
refuse bad_folder \
  "parameter /bad_folder/mesh_path: cannot write '$work/none/m.ply': output folder '$work/none' does not exist" \
  _mesh_path:="$work/none/m.ply"

# Plays the bag to the node started by launch/kitti_bag.launch with ARGS...; returns when it has
# published a depth image per frame (rostopic echo -n exits then) and has been stopped.
# $frames_made: the frames it makes, else every scan's.
play_to_node() { # NAME ARGS... (the bag: $bag, else 04.bag; $during: a command run while the node runs)
  local name=$1 counter launcher seen frames=${frames_made:-$frames}
  local log="$work/${name}_depth_seen.log"
  shift
  background "${name}_depth_seen" rostopic echo -n "$frames" /msf_ros_node/depth/header/seq
  counter=$started
  background "$name" roslaunch --wait msfusion kitti_bag.launch bag:="${bag:-$work/04.bag}" rate:=0.5 \
    queue_size:=$frames "$@"
  launcher=$started
  if [ -n "${during:-}" ]; then # once the engine has started
    for ((k = 0; k < 300; ++k)); do
      grep -aq "reconstructing" "$work/$name.log" && break
      sleep 0.1
    done
    eval "$during"
  fi
  for ((k = 0; ; ++k)); do
    kill -0 "$counter" 2>/dev/null || break
    ((k < 600)) || fail "the node published $(grep -c '^---' "$log") depth images of $frames in 60 s"
    sleep 0.1
  done
  seen=$(grep -c '^---' "$log" || true)
  ((seen >= frames)) || fail "rostopic counted $seen of $frames depth images: $(tr '\n' ' ' <"$log")"
  stop_group "$launcher" 30 # the node publishes the last mesh marker, saves the mesh, gives its account
}

# The recorder first, so that it hears the first frame; then the node, and the player, which
# waits for the node's subscriptions. queue_size: every frame, however slow the machine.
background record rosbag record -q -O "$work/published.bag" /msf_ros_node/depth /msf_ros_node/weight \
  /msf_ros_node/points /msf_ros_node/mesh
recorder=$started
play_to_node launch mesh_path:="$work/node_mesh.ply"
stop_group "$recorder" 10
node_lines "$work/launch.log"

account=$(node_lines "$work/launch.log" | grep -a "scans received")
[[ "$account" == *"$frames scans received, $frames frames, $frames reconstructed, 0 dropped"* ]] ||
  fail "the node's account at shutdown is not every frame reconstructed: '$account'"
[ -f "$work/node_mesh.ply" ] || fail "the node saved no mesh"

"$build/tests/check_node_output" "$work/04.bag" "$work/published.bag" ||
  fail "what the node published is not the engine's"

"$build/bin/msf_reconstruct" "$work/04.bag" -panels 0 -o "$work/reconstruct" >"$work/reconstruct.log" 2>&1 ||
  fail "msf_reconstruct: $(tail -5 "$work/reconstruct.log")"
cmp "$work/node_mesh.ply" "$work/reconstruct/mesh.ply" ||
  fail "the node's mesh differs from msf_reconstruct's of the same bag"
echo "ok: the node's mesh is msf_reconstruct's, byte for byte ($(stat -c %s "$work/node_mesh.ply") bytes)"

# ~sweeping_scans sets the rig's lidar.sweeping: scans of one instant keep no margin for a sweep's
# skew when they carve, and make another map of the same bag.
node_params=$(rospack find msfusion)/config/kitti_bag.yaml
sed 's/^sweeping_scans: true /sweeping_scans: false/' "$node_params" >"$work/snapshots.yaml"
grep -q "^sweeping_scans: false" "$work/snapshots.yaml" || fail "kitti_bag.yaml has no 'sweeping_scans: true' line"
# Into the file the node refused above, now with ~overwrite: replaced whole at shutdown.
play_to_node snapshots params:="$work/snapshots.yaml" mesh_path:="$work/mine.ply" overwrite:=true
[ -s "$work/mine.ply" ] || fail "the node with overwrite true did not replace '$work/mine.ply'"
! cmp -s "$work/node_mesh.ply" "$work/mine.ply" ||
  fail "sweeping_scans false made the same mesh as the sweeping rig: the parameter did not reach the engine"
echo "ok: sweeping_scans false makes another map, written over mine.ply with overwrite true"

# A rig of another image size than the bag's: every frame refused, the error logged once.
printf '%s\n' "image_width: 640" "image_height: 480" "left:" "  P: [500, 0, 320, 0, 0, 500, 240, 0, 0, 0, 1, 0]" \
  "right:" "  P: [500, 0, 320, -250, 0, 500, 240, 0, 0, 0, 1, 0]" >"$work/small_rig.yaml"
sed "s|^rig: \"\" |rig: \"$work/small_rig.yaml\"|" "$node_params" >"$work/refused.yaml"
grep -q "^rig: \"$work/small_rig.yaml\"" "$work/refused.yaml" || fail "kitti_bag.yaml has no 'rig: \"\" ' line"
background refused roslaunch --wait msfusion kitti_bag.launch bag:="$work/04.bag" rate:=0.5 params:="$work/refused.yaml"
refused=$started
for ((k = 0; k < 600; ++k)); do
  grep -aq "player-2.*finished" "$work/refused.log" && break
  sleep 0.1
done
sleep 2 # the frames still queued
stop_group "$refused" 30
account=$(node_lines "$work/refused.log" | grep -a "scans received")
[[ "$account" == *"$frames scans received, $frames frames, 0 reconstructed, $frames dropped"* ]] ||
  fail "the node with a rig of another size: '$account'"
errors=$(node_lines "$work/refused.log" | grep -ac "each error is logged once" || true)
[ "$errors" = 1 ] || fail "the node logged the refusal $errors times: $(node_lines "$work/refused.log" | tr '\n' ' ')"
echo "ok: a rig of another image size: every frame refused, the error logged once"

# A file put at ~mesh_path while the node runs is the user's: left as it is, the mesh beside it.
during="echo mine >'$work/late.ply'" play_to_node late mesh_path:="$work/late.ply"
[ "$(cat "$work/late.ply")" = mine ] || fail "the node wrote over late.ply, which appeared while it ran"
cmp "$work/late_1.ply" "$work/node_mesh.ply" || fail "the node did not save its mesh as late_1.ply"
node_lines "$work/late.log" | grep -aq "'$work/late.ply' appeared while the node ran and is left as it is" ||
  fail "the node did not say it left late.ply: $(node_lines "$work/late.log" | tr '\n' ' ')"
echo "ok: a file that appeared at ~mesh_path while the node ran is left as it is; the mesh is late_1.ply"

# The bag played twice to one node: time goes back at the second play. Its scans make no frame
# (the map takes frames in time order), the node says why, and the map is the first play's.
background replay roslaunch --wait msfusion kitti_bag.launch bag:="$work/04.bag" play:=false queue_size:=$frames \
  mesh_path:="$work/replay_mesh.ply"
replay=$started
background replay_depth_seen rostopic echo -n "$frames" /msf_ros_node/depth/header/seq
counter=$started
rosbag play -q --wait-for-subscribers --rate 0.5 "$work/04.bag" >"$work/replay_play1.log" 2>&1 ||
  fail "rosbag play: $(tail -3 "$work/replay_play1.log")"
for ((k = 0; k < 600; ++k)); do
  kill -0 "$counter" 2>/dev/null || break
  sleep 0.1
done
rosbag play -q --wait-for-subscribers --rate 0.5 "$work/04.bag" >"$work/replay_play2.log" 2>&1 ||
  fail "rosbag play again: $(tail -3 "$work/replay_play2.log")"
sleep 2 # the last messages reach the node
stop_group "$replay" 30
account=$(node_lines "$work/replay.log" | grep -a -A3 "scans received")
[[ "$account" == *"$((2 * frames)) scans received, $frames frames, $frames reconstructed, 0 dropped"* &&
  "$account" == *"$frames scans made no frame: time went back, by up to "*" (a bag played again, or a clock reset)"* &&
  "$account" != *"no stereo pair"* ]] || fail "the node's account of a bag played twice: '$account'"
node_lines "$work/replay.log" | grep -aq "time went back on '/kitti/velo/pointcloud'.*restart the node for a new map" ||
  fail "the node did not warn that time went back: $(node_lines "$work/replay.log" | tr '\n' ' ')"
cmp "$work/replay_mesh.ply" "$work/node_mesh.ply" || fail "the map of a bag played twice is not the first play's"
echo "ok: a bag played twice: the second play's $frames scans make no frame, the node says time went back"

# A rig that records its images compressed (CompressedImage on image_raw/compressed; PNG keeps
# every grey level): the node, told the compressed topics, decodes them and makes the raw bag's map.
"$build/bin/msf_kitti2bag" "$sequence" -frames "0:$last" -images png -o "$work/png.bag" >/dev/null
sed -E 's|^((left\|right\|color)_topic: +/kitti/[a-z_]+/image_raw)|\1/compressed|' "$node_params" >"$work/png.yaml"
[ "$(grep -cE "^(left|right|color)_topic: +\S+/image_raw/compressed" "$work/png.yaml")" = 3 ] ||
  fail "kitti_bag.yaml has not three image topics"
bag=$work/png.bag play_to_node compressed params:="$work/png.yaml" mesh_path:="$work/png_mesh.ply"
account=$(node_lines "$work/compressed.log" | grep -a "scans received")
[[ "$account" == *"$frames scans received, $frames frames, $frames reconstructed, 0 dropped"* ]] ||
  fail "the node on compressed images: '$account'"
cmp "$work/png_mesh.ply" "$work/node_mesh.ply" || fail "the node's map of PNG-compressed images is not the raw bag's"
echo "ok: images compressed as PNG on image_raw/compressed: every frame, the raw bag's mesh byte for byte"

# The same rig with the node told the raw topics: while its scans wait, it names the compressed
# topics that are published instead, and the parameter to set.
"$build/bin/msf_kitti2bag" "$sequence" -frames 0:9 -images png -o "$work/png10.bag" >/dev/null
# The player cannot wait for subscribers to every topic (the node subscribes to none of the
# images): it waits 2 s after advertising for the node to connect, and sends 10 scans.
background hint roslaunch --wait msfusion kitti_bag.launch bag:="$work/png10.bag" play:=false
hint=$started
for ((k = 0; k < 300; ++k)); do
  rostopic info /kitti/velo/pointcloud 2>/dev/null | grep -q "/msf_ros_node" && break
  sleep 0.1
done
rosbag play -q -d 2 --rate 0.5 "$work/png10.bag" >"$work/hint_play.log" 2>&1 ||
  fail "rosbag play: $(tail -3 "$work/hint_play.log")"
stop_group "$hint" 30
expected="nothing yet on '/kitti/camera_gray_left/image_raw', '/kitti/camera_gray_right/image_raw'; "
expected+="'/kitti/camera_gray_left/image_raw/compressed' is published (sensor_msgs/CompressedImage): name it in "
expected+="~left_topic; '/kitti/camera_gray_right/image_raw/compressed' is published"
node_lines "$work/hint.log" | grep -aqF "$expected" ||
  fail "the node did not name the compressed topics: $(node_lines "$work/hint.log" | tr '\n' ' ')"
echo "ok: told the raw topics of a compressed rig, the node names the compressed ones and their parameters"

# A rig's own bag: no colour camera though ~color_topic names one (a grey mesh, every frame), and
# tf's world not kitti2bag's camera_init (the root of the left camera's tree, which a moving
# transform leads to: msf_kitti2bag's 'world' above it): the poses from tf, the mesh
# msf_reconstruct's of the same bag.
/usr/bin/python3 - "$work/04.bag" "$work/own.bag" <<'PY' || fail "could not write own.bag"
import rosbag, sys
# Raw messages: "camera_init" renamed in the serialized bytes to a name of the same length.
with rosbag.Bag(sys.argv[1]) as bag_in, rosbag.Bag(sys.argv[2], "w") as bag_out:
    for topic, raw, t in bag_in.read_messages(raw=True):
        if "camera_color_left" in topic:
            continue
        if topic in ("/tf", "/tf_static"):
            raw = (raw[0], raw[1].replace(b"camera_init", b"vehicle_map")) + tuple(raw[2:])
        bag_out.write(topic, raw, t, raw=True)
PY
bag=$work/own.bag play_to_node own mesh_path:="$work/own_mesh.ply"
account=$(node_lines "$work/own.log" | grep -a "scans received")
[[ "$account" == *"$frames scans received, $frames frames, $frames reconstructed, 0 dropped"* ]] ||
  fail "the node on a bag without colour: '$account'"
node_lines "$work/own.log" | grep -aq "world frame 'world' (the root of the left camera's tf tree)" ||
  fail "the node did not take the root of the tf tree as its world: $(node_lines "$work/own.log" | tr '\n' ' ')"
"$build/bin/msf_reconstruct" "$work/own.bag" -panels 0 -o "$work/own_reconstruct" >"$work/own_reconstruct.log" 2>&1 ||
  fail "msf_reconstruct of own.bag: $(tail -5 "$work/own_reconstruct.log")"
cmp "$work/own_mesh.ply" "$work/own_reconstruct/mesh.ply" ||
  fail "the node's mesh of a bag without colour and camera_init differs from msf_reconstruct's"
echo "ok: a bag without the colour camera nor camera_init: every frame, poses from tf's root, msf_reconstruct's mesh"

# The same rig tracked by the odometry (~poses odometry), its right camera 30 ms late: the node
# says the pair lies apart (the last scan makes no frame: the approximate-time sync holds a pair
# not stamped as its scan until a later message shows it is the nearest), and puts its poses in tf as camera_init above the root of the left
# camera's tree, so that the mesh marker's frame meets the rig's; composed with the bag's tf,
# each is the left camera's motion since the first frame.
/usr/bin/python3 - "$work/own.bag" "$work/late_right.bag" <<'PY' || fail "could not write late_right.bag"
import rosbag, rospy, sys
with rosbag.Bag(sys.argv[1]) as bag_in, rosbag.Bag(sys.argv[2], "w") as bag_out:
    for topic, msg, t in bag_in.read_messages():
        if topic.startswith("/kitti/camera_gray_right/"):
            msg.header.stamp += rospy.Duration(0.030)
            t += rospy.Duration(0.030)
        bag_out.write(topic, msg, t)
PY
sed 's/^poses: auto$/poses: odometry/' "$node_params" >"$work/odometry.yaml"
grep -q "^poses: odometry" "$work/odometry.yaml" || fail "kitti_bag.yaml has no 'poses: auto' line"
background record_tf rosbag record -q -O "$work/odometry_tf.bag" /tf
recorder=$started
frames_made=$last bag=$work/late_right.bag play_to_node odometry params:="$work/odometry.yaml"
stop_group "$recorder" 10
node_lines "$work/odometry.log" | grep -aq "the stereo pair's images lie a median of 30 ms apart" ||
  fail "the node did not say the pair lies 30 ms apart: $(node_lines "$work/odometry.log" | tr '\n' ' ')"
node_lines "$work/odometry.log" | grep -aq "the odometry's poses go to tf as 'camera_init' -> 'world'" ||
  fail "the node did not say where its poses go in tf: $(node_lines "$work/odometry.log" | tr '\n' ' ')"
/usr/bin/python3 - "$work/own.bag" "$work/odometry_tf.bag" "$last" <<'PY' || fail "the odometry's tf is not the rig's motion"
import numpy as np, rosbag, sys

def matrix(transform):
    q, p = transform.rotation, transform.translation
    x, y, z, w = q.x, q.y, q.z, q.w
    T = np.eye(4)
    T[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    T[:3, 3] = [p.x, p.y, p.z]
    return T

def transforms(path):  # (parent, child, stamp in ns) -> 4x4
    found = {}
    with rosbag.Bag(path) as bag:
        for _, msg, _ in bag.read_messages(topics=["/tf", "/tf_static"]):
            for t in msg.transforms:
                found[(t.header.frame_id, t.child_frame_id, t.header.stamp.to_nsec())] = matrix(t.transform)
    return found

rig = transforms(sys.argv[1])
static = next(T for (p, c, _), T in rig.items() if (p, c) == ("world", "vehicle_map"))
world_cam = {s: static @ T for (p, c, s), T in rig.items() if (p, c) == ("vehicle_map", "camera_gray_left")}
odometry = {s: T for (p, c, s), T in transforms(sys.argv[2]).items() if (p, c) == ("camera_init", "world")}
assert len(odometry) == int(sys.argv[3]), f"{len(odometry)} odometry transforms for {sys.argv[3]} frames"
first = min(odometry)
for stamp, T_init_world in sorted(odometry.items()):
    tracked = T_init_world @ world_cam[stamp]
    truth = np.linalg.inv(world_cam[first]) @ world_cam[stamp]
    error = np.linalg.inv(truth) @ tracked
    metres = np.linalg.norm(error[:3, 3])
    degrees = np.degrees(np.arccos(np.clip((np.trace(error[:3, :3]) - 1) / 2, -1, 1)))
    assert metres < 0.1 and degrees < 1, f"at {stamp}: {metres:.3f} m, {degrees:.2f} degrees off the rig's motion"
    print(f"  frame at {stamp * 1e-9:.3f} s: {np.linalg.norm(truth[:3, 3]):.2f} m from the first, "
          f"the odometry {metres:.3f} m and {degrees:.2f} degrees off")
PY
echo "ok: the odometry's poses in tf as camera_init above the rig's tree; a right camera 30 ms late is said"

ros_session_stop
echo "ok: roscore, the node, the player and the recorder stopped; no process left"
