// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "reconstruction_node.h"

#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/io/bag_options.h>
#include <msf/io/beam_elevations.h>
#include <msf/io/cloud_io.h>
#include <msf/pipeline/fused_cloud.h>
#include <msf/ros/compressed_image.h>
#include <msf/ros/frame_matcher.h>
#include <msf/ros/message_conversions.h>

#include <pcl_conversions/pcl_conversions.h>
#include <visualization_msgs/Marker.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <limits>
#include <map>
#include <set>
#include <sstream>
#include <vector>

namespace msf {

namespace {

/// The odometry's world, the first left camera's pose: kitti2bag's name for it.
constexpr char kOdometryWorld[] = "camera_init";

const std::map<std::string, Reconstructor::PoseMode> kPoseModes{
    {"auto", Reconstructor::PoseMode::Auto}, {"tf", Reconstructor::PoseMode::Given},
    {"odometry", Reconstructor::PoseMode::Odometry}, {"refine", Reconstructor::PoseMode::Refine}};

/// Reads one parameter when it is set; a value of another type is an error, not the default.
template <typename T>
void readParam(const ros::NodeHandle& nh, const std::string& name, T& value, const char* type) {
  if (nh.hasParam(name) && !nh.getParam(name, value))
    throw ConfigError("parameter " + nh.resolveName(name) + " must be " + type);
}

/// Every parameter set under the node's private namespace is one it knows: a typo is an error.
void refuseUnknownParams(const ros::NodeHandle& nh, const std::set<std::string>& known) {
  std::vector<std::string> names;
  ros::param::getParamNames(names);
  const std::string prefix = nh.getNamespace() + "/";
  std::string list;
  for (const std::string& name : known)
    list += (list.empty() ? "" : ", ") + name;
  for (const std::string& name : names) {
    if (name.compare(0, prefix.size(), prefix) != 0)
      continue;
    const std::string key = name.substr(prefix.size(), name.find('/', prefix.size()) - prefix.size());
    if (!known.count(key))
      throw ConfigError("unknown parameter " + prefix + key + " (the node's parameters: " + list + ")");
  }
}

/// A parameter's name, its default as text and what it sets: the node's help, and the names it knows.
struct ParamDoc {
  std::string name, default_value, meaning;
};

std::string quoted(const std::string& text) { return "\"" + text + "\""; }

/// `path`, or the first of path's stem + "_1", "_2", ... beside it that does not exist.
std::string freeNameBeside(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  const fs::path p(path);
  fs::path free = p;
  for (int k = 1; fs::exists(free, ec); ++k)
    free = p.parent_path() / (p.stem().string() + "_" + std::to_string(k) + p.extension().string());
  return free.string();
}

std::string numberText(double value) {
  std::ostringstream text;
  text << value;
  return text.str();
}

std::vector<ParamDoc> paramDocs(const NodeParameters& d) {
  return {
      {"lidar_topic", quoted(d.lidar_topic), "sensor_msgs/PointCloud2: x y z (intensity, ring, time)"},
      {"left_topic", quoted(d.left_topic),
       "rectified Image, or CompressedImage on .../compressed (its CameraInfo: camera_info beside it); the depth's"},
      {"right_topic", quoted(d.right_topic), "rectified Image of the pair's right camera"},
      {"color_topic", quoted(d.color_topic),
       "the mesh's colour, when the topic has a publisher (\"\" or none = a grey mesh)"},
      {"sync_slop_s", numberText(d.sync_slop_s), "the largest spread of stamps within one frame's messages"},
      {"world_frame", quoted(d.world_frame),
       "tf frame of the poses and of the mesh (\"\" = camera_init when tf has it, else the root of the left "
       "camera's tf tree)"},
      {"poses", quoted(d.poses), "auto, tf, odometry or refine (tf's poses refined by the LiDAR)"},
      {"tf_timeout_s", numberText(d.tf_timeout_s), "how long a frame waits for its pose (the first, its extrinsic)"},
      {"sweeping_scans", "the rig's, else true", "a spinning LiDAR's swept scans (false: taken at one instant)"},
      {"config", quoted(d.config), "the engine's YAML configuration (\"\" = its defaults)"},
      {"rig", quoted(d.rig), "a calibration file (KITTI calib.txt or rig YAML) instead of CameraInfo and tf"},
      {"threads", std::to_string(d.threads), "the engine's threads (0 = all cores)"},
      {"queue_size", std::to_string(d.queue_size), "frames waiting for the engine (1..8), the oldest dropped"},
      {"mesh_rate_hz", numberText(d.mesh_rate_hz), "~mesh refresh (0 = none)"},
      {"mesh_path", quoted(d.mesh_path), "the mesh saved at shutdown (.ply/.obj/.vtk; \"\" = none)"},
      {"overwrite", d.overwrite ? "true" : "false", "replace a mesh_path that exists (else refused at start)"}};
}

} // namespace

std::string NodeParameters::help() {
  std::ostringstream text;
  text << "msf_ros_node: the msfusion engine as a ROS 1 node (docs/ros.md).\n"
          "usage: rosrun or roslaunch (launch/kitti_bag.launch), or msf_ros_node [_param:=value] [topic:=remap]\n"
          "  in:  ~lidar_topic, ~left_topic, ~right_topic (and their camera_info), ~color_topic, /tf, /tf_static\n"
          "  out: ~depth, ~weight (Image 32FC1), ~points (PointCloud2), ~mesh (Marker), /tf (the odometry's poses)\n"
          "parameters (private: _name:=value, or a launch file's rosparam), with their defaults:\n";
  for (const ParamDoc& doc : paramDocs(NodeParameters()))
    text << "  " << doc.name << " = " << doc.default_value << "\n      " << doc.meaning << "\n";
  return text.str();
}

NodeParameters::NodeParameters() {
  const BagOptions kitti2bag;
  lidar_topic = kitti2bag.lidar_topic;
  left_topic = kitti2bag.left_topic;
  right_topic = kitti2bag.right_topic;
  color_topic = kitti2bag.color_topic;
}

NodeParameters NodeParameters::read(const ros::NodeHandle& nh) {
  NodeParameters p;
  std::set<std::string> known;
  for (const ParamDoc& doc : paramDocs(p))
    known.insert(doc.name);
  refuseUnknownParams(nh, known);
  for (auto [name, value] : {std::pair{"lidar_topic", &p.lidar_topic}, {"left_topic", &p.left_topic},
                             {"right_topic", &p.right_topic}, {"color_topic", &p.color_topic},
                             {"world_frame", &p.world_frame}, {"poses", &p.poses}, {"config", &p.config},
                             {"rig", &p.rig}, {"mesh_path", &p.mesh_path}})
    readParam(nh, name, *value, "a string");
  readParam(nh, "threads", p.threads, "an integer");
  readParam(nh, "queue_size", p.queue_size, "an integer");
  readParam(nh, "overwrite", p.overwrite, "true or false");
  if (nh.hasParam("sweeping_scans")) {
    bool sweeping = true;
    readParam(nh, "sweeping_scans", sweeping, "true or false");
    p.sweeping_scans = sweeping;
  }
  for (auto [name, value] : {std::pair{"sync_slop_s", &p.sync_slop_s}, {"tf_timeout_s", &p.tf_timeout_s},
                             {"mesh_rate_hz", &p.mesh_rate_hz}})
    readParam(nh, name, *value, "a number");
  const auto check = [&](bool ok, const std::string& name, const std::string& range, auto value) {
    std::ostringstream text;
    text << value;
    if (!ok)
      throw ConfigError("parameter " + nh.resolveName(name) + " must be " + range + ", not " + text.str());
  };
  check(kPoseModes.count(p.poses) > 0, "poses", "auto, tf, odometry or refine", "'" + p.poses + "'");
  check(p.threads >= 0, "threads", ">= 0", p.threads);
  check(p.queue_size >= 1 && p.queue_size <= 8, "queue_size", "1..8 frames", p.queue_size);
  check(p.sync_slop_s > 0, "sync_slop_s", "> 0", p.sync_slop_s);
  check(p.tf_timeout_s >= 0, "tf_timeout_s", ">= 0", p.tf_timeout_s);
  check(p.mesh_rate_hz >= 0, "mesh_rate_hz", ">= 0", p.mesh_rate_hz);
  if (p.lidar_topic.empty() || p.left_topic.empty() || p.right_topic.empty())
    throw ConfigError("parameters " + nh.resolveName("lidar_topic") + ", left_topic and right_topic must be set");
  if (!p.rig.empty()) {
    try { // read at start, not at the first frame
      loadCalibration(p.rig);
    } catch (const Error& e) {
      throw ConfigError("parameter " + nh.resolveName("rig") + ": " + e.what());
    }
  }
  if (!p.mesh_path.empty()) {
    p.mesh_path = std::filesystem::absolute(p.mesh_path).string(); // the node's folder is ROS_HOME
    try {
      requireMeshExtension(p.mesh_path);
    } catch (const IOError& e) {
      throw ConfigError("parameter " + nh.resolveName("mesh_path") + ": " + e.what());
    }
    std::error_code ec;
    if (!p.overwrite && std::filesystem::exists(p.mesh_path, ec))
      throw ConfigError("parameter " + nh.resolveName("mesh_path") + ": '" + p.mesh_path + "' exists; set " +
                        nh.resolveName("overwrite") + " true to replace it");
    try { // its folder at start too, not when the session ends
      requireWritableFolder(p.mesh_path);
    } catch (const IOError& e) {
      throw ConfigError("parameter " + nh.resolveName("mesh_path") + ": " + e.what());
    }
  }
  return p;
}

ReconstructionNode::ReconstructionNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
    : params_(NodeParameters::read(private_nh)), tf_listener_(tf_buffer_),
      queue_(static_cast<std::size_t>(params_.queue_size)) {
  try {
    config_ = PipelineConfig::load(params_.config); // "" = the defaults
    config_.validate();
  } catch (const Error& e) {
    throw ConfigError("parameter " + private_nh.resolveName("config") + ": " + e.what());
  }
  depth_pub_ = private_nh.advertise<Image>("depth", 2);
  weight_pub_ = private_nh.advertise<Image>("weight", 2);
  points_pub_ = private_nh.advertise<Cloud>("points", 2);
  mesh_pub_ = private_nh.advertise<visualization_msgs::Marker>("mesh", 1, true);
  subscribe(nh); // the callbacks run in ros::spin, after this
  last_mesh_ = Clock::now();
  worker_ = std::thread(&ReconstructionNode::work, this);
  const std::string world = params_.world_frame.empty() ? "from tf" : "'" + params_.world_frame + "'";
  ROS_INFO("msf_ros_node: %s + %s + %s%s%s, poses: %s (world frame %s), %d frame%s waiting at most",
           params_.lidar_topic.c_str(), params_.left_topic.c_str(), params_.right_topic.c_str(),
           params_.color_topic.empty() ? "" : " + (when published) ", params_.color_topic.c_str(),
           params_.poses.c_str(), world.c_str(), params_.queue_size, params_.queue_size == 1 ? "" : "s");
}

void ReconstructionNode::subscribe(ros::NodeHandle& nh) {
  // Deep enough for a frame's messages to meet however the transport orders them; the sync's
  // callback only queues, so these never fill.
  constexpr std::uint32_t kQueue = 5, kSyncQueue = 10;
  const auto refused = [](const std::string& why) {
    ROS_ERROR_THROTTLE(5.0, "msf_ros_node: %s: its frame is not made", why.c_str());
  };
  cloud_sub_.subscribe(nh, params_.lidar_topic, kQueue);
  left_sub_.subscribe(nh, params_.left_topic, kQueue, refused);
  left_info_sub_.subscribe(nh, cameraInfoTopic(params_.left_topic), kQueue);
  right_sub_.subscribe(nh, params_.right_topic, kQueue, refused);
  right_info_sub_.subscribe(nh, cameraInfoTopic(params_.right_topic), kQueue);
  const ros::Duration slop(params_.sync_slop_s);
  // Frames without colour, and with it when the colour camera publishes (colorPublished).
  stereo_sync_ = std::make_unique<message_filters::Synchronizer<StereoPolicy>>(
      StereoPolicy(kSyncQueue), cloud_sub_, left_sub_, left_info_sub_, right_sub_, right_info_sub_);
  stereo_sync_->getPolicy()->setMaxIntervalDuration(slop);
  stereo_sync_->registerCallback(&ReconstructionNode::onStereo, this);
  if (!params_.color_topic.empty()) {
    color_sub_.subscribe(nh, params_.color_topic, kQueue, refused);
    color_info_sub_.subscribe(nh, cameraInfoTopic(params_.color_topic), kQueue);
    color_sync_ = std::make_unique<message_filters::Synchronizer<ColorPolicy>>(
        ColorPolicy(kSyncQueue), cloud_sub_, left_sub_, left_info_sub_, right_sub_, right_info_sub_, color_sub_,
        color_info_sub_);
    color_sync_->getPolicy()->setMaxIntervalDuration(slop);
    color_sync_->registerCallback(&ReconstructionNode::onColor, this);
  }
  countMessages();
}

void ReconstructionNode::countMessages() {
  const auto count = [this](const std::string& topic) {
    std::lock_guard<std::mutex> lock(drops_mutex_);
    ++messages_[topic];
  };
  for (const std::string& topic : {params_.left_topic, params_.right_topic, cameraInfoTopic(params_.left_topic),
                                   cameraInfoTopic(params_.right_topic)})
    messages_[topic] = 0;
  if (color_sync_) {
    messages_[params_.color_topic] = 0;
    messages_[cameraInfoTopic(params_.color_topic)] = 0;
    color_sub_.registerCallback([=, topic = params_.color_topic](const Image::ConstPtr&) { count(topic); });
    color_info_sub_.registerCallback(
        [=, topic = cameraInfoTopic(params_.color_topic)](const Info::ConstPtr&) { count(topic); });
  }
  cloud_sub_.registerCallback([this](const Cloud::ConstPtr& cloud) { onScan(cloud->header.stamp); });
  left_sub_.registerCallback([=, topic = params_.left_topic](const Image::ConstPtr&) { count(topic); });
  right_sub_.registerCallback([=, topic = params_.right_topic](const Image::ConstPtr&) { count(topic); });
  left_info_sub_.registerCallback(
      [=, topic = cameraInfoTopic(params_.left_topic)](const Info::ConstPtr&) { count(topic); });
  right_info_sub_.registerCallback(
      [=, topic = cameraInfoTopic(params_.right_topic)](const Info::ConstPtr&) { count(topic); });
}

bool ReconstructionNode::colorPublished() const {
  return color_sync_ && color_sub_.publishers() > 0 &&
         color_info_sub_.getSubscriber().getNumPublishers() > 0;
}

std::string ReconstructionNode::silentInputs() const {
  const bool color = colorPublished(); // else frames do not wait for the colour camera
  std::lock_guard<std::mutex> lock(drops_mutex_);
  std::string silent;
  for (const auto& [topic, n] : messages_)
    if (n == 0 && (color || (topic != params_.color_topic && topic != cameraInfoTopic(params_.color_topic))))
      silent += (silent.empty() ? "'" : ", '") + topic + "'";
  return silent;
}

std::string ReconstructionNode::compressedInstead() const {
  ros::master::V_TopicInfo published;
  if (!ros::master::getTopics(published))
    return "";
  std::string hint;
  const std::pair<const char*, std::string> inputs[] = {
      {"left_topic", params_.left_topic}, {"right_topic", params_.right_topic}, {"color_topic", params_.color_topic}};
  std::lock_guard<std::mutex> lock(drops_mutex_);
  for (const auto& [parameter, topic] : inputs) {
    const auto counted = messages_.find(topic);
    if (topic.empty() || isCompressedTopic(topic) || counted == messages_.end() || counted->second > 0)
      continue;
    for (const ros::master::TopicInfo& info : published)
      if (info.name == topic + "/compressed")
        hint += "; '" + info.name + "' is published (" + info.datatype + "): name it in ~" + parameter;
  }
  return hint;
}

void ReconstructionNode::onScan(const ros::Time& stamp) {
  ++scans_;
  const std::int64_t ns = stampNs(stamp);
  if (scans_ > 1 && ns <= newest_scan_ns_) {
    // The map takes its frames in time order: a frame of this scan would come after newer ones.
    ++scans_back_in_time_;
    {
      std::lock_guard<std::mutex> lock(drops_mutex_);
      largest_step_back_ns_ = std::max(largest_step_back_ns_, newest_scan_ns_ - ns);
    }
    if (!stepping_back_)
      ROS_WARN("msf_ros_node: time went back on '%s' (a scan at %.3f s after one at %.3f s: a bag played again, or a "
               "clock reset): scans up to %.3f s make no frame, since the map takes its frames in time order; "
               "restart the node for a new map",
               params_.lidar_topic.c_str(), stamp.toSec(), newest_scan_ns_ * 1e-9, newest_scan_ns_ * 1e-9);
    stepping_back_ = true;
    return;
  }
  newest_scan_ns_ = ns;
  stepping_back_ = false;
  // A few scans with no frame: say which input they wait for, every few seconds while it waits.
  constexpr std::size_t kScansBeforeWarning = 5;
  constexpr std::chrono::seconds kWarningEvery(5);
  if (++scans_since_frame_ < kScansBeforeWarning || Clock::now() < next_input_warning_)
    return;
  next_input_warning_ = Clock::now() + kWarningEvery;
  const std::string silent = silentInputs();
  const std::string why = silent.empty() ? "their images and CameraInfo are not within sync_slop_s (" +
                                               numberText(params_.sync_slop_s) + " s) of them"
                                         : "nothing yet on " + silent + compressedInstead();
  ROS_WARN("msf_ros_node: %zu scans on '%s' and no frame: %s", scans_since_frame_.load(), params_.lidar_topic.c_str(),
           why.c_str());
}

void ReconstructionNode::onStereo(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left,
                                  const Info::ConstPtr& left_info, const Image::ConstPtr& right,
                                  const Info::ConstPtr& right_info) {
  if (colorPublished())
    return; // the colour sync gives this frame, with its colour
  enqueue({cloud, left, right, nullptr, left_info, right_info, nullptr});
}

void ReconstructionNode::onColor(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left,
                                 const Info::ConstPtr& left_info, const Image::ConstPtr& right,
                                 const Info::ConstPtr& right_info, const Image::ConstPtr& color,
                                 const Info::ConstPtr& color_info) {
  enqueue({cloud, left, right, color, left_info, right_info, color_info});
}

void ReconstructionNode::enqueue(Pending pending) {
  // A colour camera that starts publishing later: both syncs may give its first frames, queued once.
  // A scan from before the last frame's (time went back) is counted by onScan.
  const std::int64_t scan_ns = stampNs(pending.cloud->header.stamp);
  if (frames_ > 0 && scan_ns <= newest_queued_scan_ns_)
    return;
  newest_queued_scan_ns_ = scan_ns;
  scans_since_frame_ = 0;
  judgePairStamps(pending);
  if (frames_++ == 0)
    first_arrival_ = Clock::now();
  last_arrival_ = Clock::now();
  if (queue_.pushNewest(std::move(pending)))
    drop("the engine was busy: the oldest of " + std::to_string(params_.queue_size) +
         " waiting frames made room for the newest");
}

void ReconstructionNode::judgePairStamps(const Pending& pending) {
  constexpr std::size_t kPairsJudged = 10;
  std::lock_guard<std::mutex> lock(drops_mutex_);
  if (pair_apart_ns_.size() == kPairsJudged)
    return;
  pair_apart_ns_.push_back(std::llabs(stampNs(pending.left->header.stamp) - stampNs(pending.right->header.stamp)));
  if (pair_apart_ns_.size() == kPairsJudged)
    if (const std::string note = stereoPairApartNote(pair_apart_ns_); !note.empty())
      ROS_WARN("msf_ros_node: on '%s' and '%s', %s", params_.left_topic.c_str(), params_.right_topic.c_str(),
               note.c_str());
}

void ReconstructionNode::work() {
  while (!queue_.drained()) {
    if (std::optional<Pending> pending = queue_.popFor(untilMeshDue())) {
      try {
        process(*pending);
      } catch (const std::exception& e) {
        // Each error once: a rig that does not fit would repeat it at every frame.
        if (refusals_logged_.insert(e.what()).second)
          ROS_ERROR("msf_ros_node: the frame of the scan at %.3f s: %s (each error is logged once)",
                    pending->cloud->header.stamp.toSec(), e.what());
        drop("the engine refused it (the error is logged)");
      }
    }
    if (untilMeshDue() == Clock::duration::zero())
      publishMesh();
  }
  if (meshed_frames_ != reconstructed_ && params_.mesh_rate_hz > 0)
    publishMesh(); // the whole map, however recently the last one went
}

void ReconstructionNode::process(const Pending& pending) {
  if (!engine_ && !startEngine(pending))
    return;
  Frame frame = frameFromMessages(pending);
  if (!placeFrame(frame, pending.left->header))
    return;
  const Clock::time_point start = Clock::now();
  const FrameResult result = engine_->addFrame(frame);
  const double ms = std::chrono::duration<double, std::milli>(Clock::now() - start).count();
  (reconstructed_ == 0 ? first_frame_ms_ : later_frames_ms_) += ms;
  if (reconstructed_++ == 0)
    tracking_ = !frame.has_pose; // PoseMode::Auto: the odometry tracks a run whose first frame has no pose
  ROS_DEBUG("msf_ros_node: frame %zu (scan at %.3f s) in %.0f ms", frame.index, pending.cloud->header.stamp.toSec(), ms);
  last_header_ = pending.left->header;
  publish(result, pending.left->header);
  if (tracking_)
    publishOdometryTf(result, pending.left->header);
}

bool ReconstructionNode::startEngine(const Pending& pending) {
  const cv::Size size(static_cast<int>(pending.left->width), static_cast<int>(pending.left->height));
  Calibration rig;
  if (!params_.rig.empty()) {
    rig = loadCalibration(params_.rig, size);
  } else {
    const std::string &lidar = pending.cloud->header.frame_id, &camera = pending.left->header.frame_id;
    Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity();
    std::string error;
    if (lidar != camera && !lookUp(camera, lidar, ros::Time(0), T_cam0_velo, error)) {
      ROS_ERROR_THROTTLE(5.0, "msf_ros_node: no tf from the LiDAR's frame '%s' to the left camera's '%s' (%s): publish "
                              "it (/tf_static) or give the rig's calibration in ~rig",
                         lidar.c_str(), camera.c_str(), error.c_str());
      drop("no LiDAR extrinsic yet (tf from the scan's frame to the left camera's)");
      return false;
    }
    rig = rigFromCameraInfo(*pending.left_info, *pending.right_info, pending.color_info.get(), T_cam0_velo, size,
                            "the CameraInfo on " + cameraInfoTopic(params_.left_topic));
  }
  if (params_.sweeping_scans)
    rig.lidar.sweeping = *params_.sweeping_scans;
  Frame first;
  scanFromMessage(*pending.cloud, first, "the scan on '" + params_.lidar_topic + "'");
  if (rig.lidar.sweeping && !params_.sweeping_scans && scanTimesAreOneInstant(first))
    ROS_WARN("msf_ros_node: the first scan's points all have the same time: if the LiDAR takes each scan at one "
             "instant, set ~sweeping_scans false (else its scans are taken as swept over their period)");
  if (rig.lidar.beam_elevations_deg.empty()) { // the beams, from the first scan's rings when it has them
    const std::vector<double> beams = beamElevationsFromRings(*first.scan, first.point_ring);
    if (!beams.empty()) {
      rig.lidar.beam_elevations_deg = beams;
      rig.lidar.rings = static_cast<int>(beams.size());
      ROS_INFO("msf_ros_node: %s", beamsFromRingsNote(beams).c_str());
    }
  }
  Reconstructor::Options options;
  options.poses = kPoseModes.at(params_.poses);
  options.threads = params_.threads;
  engine_ = std::make_unique<Reconstructor>(rig, config_, options);
  tracking_ = params_.poses == "odometry";
  first_scan_ns_ = stampNs(pending.cloud->header.stamp);
  ROS_INFO("msf_ros_node: rig %dx%d, fx %.1f px, baseline %.3f m; reconstructing", size.width, size.height, rig.fx(0),
           rig.baselineGrey());
  return true;
}

Frame ReconstructionNode::frameFromMessages(const Pending& pending) const {
  Frame frame;
  scanFromMessage(*pending.cloud, frame, "the scan on '" + params_.lidar_topic + "'");
  stampFrame(frame, reconstructed_, stampNs(pending.cloud->header.stamp), first_scan_ns_,
             pending.cloud->header.frame_id);
  greyPairFromMessages(*pending.left, *pending.right, frame.left, frame.right,
                       "the image on '" + params_.left_topic + "'", "the image on '" + params_.right_topic + "'");
  if (pending.color)
    frame.color = colorFromMessage(*pending.color, "the image on '" + params_.color_topic + "'");
  return frame;
}

bool ReconstructionNode::placeFrame(Frame& frame, const std_msgs::Header& camera_header) {
  if (tracking_)
    return true;
  const std::string world = worldFrame(camera_header.frame_id);
  std::string error = "no frame above it in tf reached through a moving transform: set ~world_frame";
  frame.has_pose = !world.empty() &&
                   lookUp(world, camera_header.frame_id, camera_header.stamp, frame.T_world_cam0, error);
  if (frame.has_pose)
    return true;
  // Without a pose, only the first frame of PoseMode::Auto goes on: the odometry tracks from it.
  if (params_.poses == "auto" && reconstructed_ == 0) {
    ROS_WARN("msf_ros_node: the first frame has no pose from tf (%s): the LiDAR odometry gives the poses, the mesh "
             "in the first left camera's frame; set ~world_frame to the tf frame of your poses, or ~poses tf",
             error.c_str());
    return true;
  }
  ROS_WARN_THROTTLE(5.0, "msf_ros_node: no tf from '%s' to '%s' at %.3f s: %s", world.c_str(),
                    camera_header.frame_id.c_str(), camera_header.stamp.toSec(), error.c_str());
  drop("no pose (tf from the world frame to the left camera at the frame's stamp)");
  return false;
}

std::string ReconstructionNode::worldFrame(const std::string& camera_frame) {
  if (!world_frame_.empty())
    return world_frame_;
  if (!params_.world_frame.empty())
    return world_frame_ = params_.world_frame;
  // tf's moving transform may come after the frame's messages: looked for up to tf_timeout_s.
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(params_.tf_timeout_s));
  do {
    if (tf_buffer_.canTransform(kOdometryWorld, camera_frame, ros::Time(0)))
      return world_frame_ = kOdometryWorld;
    const std::string root = treeRoot(camera_frame);
    // Only static transforms up to the root (the rig's own frames) give no pose.
    try {
      if (root != camera_frame && !tf_buffer_.lookupTransform(root, camera_frame, ros::Time(0)).header.stamp.isZero()) {
        ROS_INFO("msf_ros_node: world frame '%s' (the root of the left camera's tf tree)", root.c_str());
        return world_frame_ = root;
      }
    } catch (const tf2::TransformException&) {
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  } while (Clock::now() < deadline);
  return "";
}

std::string ReconstructionNode::treeRoot(const std::string& frame) const {
  std::string root = frame, parent;
  while (tf_buffer_._getParent(root, ros::Time(0), parent) && parent != root)
    root = parent;
  return root;
}

void ReconstructionNode::publishOdometryTf(const FrameResult& result, const std_msgs::Header& camera_header) {
  const std::string& camera = camera_header.frame_id;
  if (!odometry_tf_child_) { // decided at the first frame, before tf holds this node's own transforms
    const ros::Duration wait(params_.tf_timeout_s);
    const bool known = tf_buffer_.canTransform(kOdometryWorld, camera, ros::Time(0), wait);
    odometry_tf_child_ = known ? "" : treeRoot(camera);
    if (!known)
      ROS_INFO("msf_ros_node: the odometry's poses go to tf as '%s' -> '%s', the root of the left camera's tree",
               kOdometryWorld, odometry_tf_child_->c_str());
  }
  if (odometry_tf_child_->empty())
    return;
  Eigen::Isometry3d T_camera_child = Eigen::Isometry3d::Identity();
  std::string error;
  const std::string& child = *odometry_tf_child_;
  if (child != camera && !lookUp(camera, child, camera_header.stamp, T_camera_child, error)) {
    ROS_WARN_THROTTLE(5.0, "msf_ros_node: the odometry's pose at %.3f s is not in tf: no tf from '%s' to '%s' (%s)",
                      camera_header.stamp.toSec(), child.c_str(), camera.c_str(), error.c_str());
    return;
  }
  geometry_msgs::TransformStamped message;
  message.header.stamp = camera_header.stamp;
  message.header.frame_id = kOdometryWorld;
  message.child_frame_id = child;
  message.transform = transformFromIsometry(result.T_world_cam0 * T_camera_child);
  tf_broadcaster_.sendTransform(message);
}

bool ReconstructionNode::lookUp(const std::string& target, const std::string& source, const ros::Time& stamp,
                                Eigen::Isometry3d& T, std::string& error) const {
  try {
    T = isometryFromTransform(
        tf_buffer_.lookupTransform(target, source, stamp, ros::Duration(params_.tf_timeout_s)).transform);
    return true;
  } catch (const tf2::TransformException& e) {
    error = e.what();
    return false;
  }
}

void ReconstructionNode::publish(const FrameResult& result, const std_msgs::Header& camera_header) {
  if (depth_pub_.getNumSubscribers() > 0) { // REP 118: NaN where there is no depth
    cv::Mat depth = result.fused.depth.clone();
    depth.setTo(std::numeric_limits<float>::quiet_NaN(), depth <= 0);
    depth_pub_.publish(imageToMessage(depth, camera_header));
  }
  if (weight_pub_.getNumSubscribers() > 0)
    weight_pub_.publish(imageToMessage(result.fused.weight, camera_header));
  if (points_pub_.getNumSubscribers() > 0) {
    Cloud points;
    pcl::toROSMsg(fusedCloud(result, engine_->calibration()), points);
    points.header = camera_header;
    points_pub_.publish(points);
  }
}

ReconstructionNode::Clock::duration ReconstructionNode::untilMeshDue() const {
  if (params_.mesh_rate_hz <= 0 || reconstructed_ == meshed_frames_)
    return std::chrono::hours(1); // nothing new to mesh: wait for a frame
  const auto due = last_mesh_ + std::chrono::duration_cast<Clock::duration>(
                                    std::chrono::duration<double>(1.0 / params_.mesh_rate_hz));
  return std::max(Clock::duration::zero(), due - Clock::now());
}

void ReconstructionNode::publishMesh() {
  last_mesh_ = Clock::now();
  if (mesh_pub_.getNumSubscribers() == 0)
    return; // meshing costs: only for a listener (the file at shutdown meshes anyway)
  meshed_frames_ = reconstructed_;
  std_msgs::Header header = last_header_;
  header.frame_id = tracking_ || world_frame_.empty() ? kOdometryWorld : world_frame_;
  mesh_pub_.publish(meshToMarker(engine_->mesh(), header));
}

void ReconstructionNode::drop(const std::string& reason) {
  std::lock_guard<std::mutex> lock(drops_mutex_);
  ++dropped_[reason];
  ROS_WARN_THROTTLE(5.0, "msf_ros_node: frame dropped: %s (%zu dropped for this reason so far)", reason.c_str(),
                    dropped_[reason]);
}

void ReconstructionNode::saveMesh() {
  if (params_.mesh_path.empty())
    return;
  if (!engine_ || engine_->mesh().triangles.empty()) {
    ROS_WARN("msf_ros_node: no surface was reconstructed: '%s' is not written", params_.mesh_path.c_str());
    return;
  }
  const TriangleMesh& mesh = engine_->mesh();
  pcl::PolygonMesh polygons;
  mesh.toPolygonMesh(polygons);
  const std::string path = params_.overwrite ? params_.mesh_path : freeNameBeside(params_.mesh_path);
  if (path != params_.mesh_path)
    ROS_WARN("msf_ros_node: '%s' appeared while the node ran and is left as it is", params_.mesh_path.c_str());
  msf::saveMesh(path, polygons);
  ROS_INFO("msf_ros_node: mesh of %zu triangles saved to '%s'", mesh.triangles.size(), path.c_str());
}

std::string ReconstructionNode::summary() const {
  const std::string silent = silentInputs();
  std::lock_guard<std::mutex> lock(drops_mutex_);
  std::size_t dropped = 0;
  std::string reasons;
  for (const auto& [reason, n] : dropped_) {
    dropped += n;
    reasons += "\n  " + std::to_string(n) + ": " + reason;
  }
  if (const std::string apart = stereoPairApartNote(pair_apart_ns_); !apart.empty())
    reasons += "\n  " + apart;
  if (scans_back_in_time_ > 0) {
    char back[64];
    std::snprintf(back, sizeof back, "%.3f s", static_cast<double>(largest_step_back_ns_) * 1e-9);
    reasons += "\n  " + std::to_string(scans_back_in_time_) + " scans made no frame: time went back, by up to " +
               back + " (a bag played again, or a clock reset), and the map takes its frames in time order";
  }
  const std::size_t unmatched = scans_ - frames_ - scans_back_in_time_;
  if (unmatched > 0)
    reasons += "\n  " + std::to_string(unmatched) + " scans made no frame: no stereo pair (and CameraInfo) within " +
               numberText(params_.sync_slop_s) + " s of their stamp, or, the last ones, no messages after them " +
               "to show which pair is nearest" + (silent.empty() ? "" : " (nothing came on " + silent + ")");
  char times[160] = "";
  if (reconstructed_ > 1 && frames_ > 1)
    std::snprintf(times, sizeof times, "\n  the engine: %.0f ms a frame (the first %.0f ms); the frames came every %.0f ms",
                  later_frames_ms_ / static_cast<double>(reconstructed_ - 1), first_frame_ms_,
                  std::chrono::duration<double, std::milli>(last_arrival_ - first_arrival_).count() /
                      static_cast<double>(frames_ - 1));
  return std::to_string(scans_) + " scans received, " + std::to_string(frames_) + " frames, " +
         std::to_string(reconstructed_) + " reconstructed, " + std::to_string(dropped) + " dropped" + reasons + times;
}

ReconstructionNode::~ReconstructionNode() {
  queue_.close();
  worker_.join(); // after the frames still waiting
  try {
    saveMesh();
  } catch (const std::exception& e) {
    ROS_ERROR("msf_ros_node: the mesh is not saved: %s", e.what());
  }
  ROS_INFO("msf_ros_node: %s", summary().c_str());
}

} // namespace msf
