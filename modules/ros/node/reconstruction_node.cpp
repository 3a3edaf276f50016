#include "reconstruction_node.h"

#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/pipeline/fused_cloud.h>
#include <msf/ros/message_conversions.h>

#include <pcl_conversions/pcl_conversions.h>
#include <visualization_msgs/Marker.h>

#include <filesystem>

namespace msf {

namespace {

std::string cameraInfoTopic(const std::string& image_topic) {
  const std::size_t slash = image_topic.rfind('/');
  return (slash == std::string::npos ? std::string() : image_topic.substr(0, slash + 1)) + "camera_info";
}

Reconstructor::PoseMode poseMode(const std::string& name) {
  if (name == "auto")
    return Reconstructor::PoseMode::Auto;
  if (name == "tf")
    return Reconstructor::PoseMode::Given;
  if (name == "odometry")
    return Reconstructor::PoseMode::Odometry;
  throw ConfigError("parameter ~poses must be auto, tf or odometry, not '" + name + "'");
}

} // namespace

NodeParameters NodeParameters::read(const ros::NodeHandle& nh) {
  NodeParameters p;
  nh.param("lidar_topic", p.lidar_topic, p.lidar_topic);
  nh.param("left_topic", p.left_topic, p.left_topic);
  nh.param("right_topic", p.right_topic, p.right_topic);
  nh.param("color_topic", p.color_topic, p.color_topic);
  nh.param("world_frame", p.world_frame, p.world_frame);
  nh.param("poses", p.poses, p.poses);
  nh.param("config", p.config, p.config);
  nh.param("rig", p.rig, p.rig);
  nh.param("threads", p.threads, p.threads);
  nh.param("queue_size", p.queue_size, p.queue_size);
  nh.param("sync_slop_s", p.sync_slop_s, p.sync_slop_s);
  nh.param("tf_timeout_s", p.tf_timeout_s, p.tf_timeout_s);
  nh.param("mesh_rate_hz", p.mesh_rate_hz, p.mesh_rate_hz);
  nh.param("mesh_path", p.mesh_path, p.mesh_path);
  poseMode(p.poses);
  const auto check = [](bool ok, const std::string& name, const std::string& range, double value) {
    if (!ok)
      throw ConfigError("parameter ~" + name + " must be " + range + ", not " + std::to_string(value));
  };
  check(p.threads >= 0, "threads", ">= 0", p.threads);
  check(p.queue_size >= 1 && p.queue_size <= 8, "queue_size", "1..8 frames", p.queue_size);
  check(p.sync_slop_s > 0, "sync_slop_s", "> 0", p.sync_slop_s);
  check(p.tf_timeout_s >= 0, "tf_timeout_s", ">= 0", p.tf_timeout_s);
  check(p.mesh_rate_hz >= 0, "mesh_rate_hz", ">= 0", p.mesh_rate_hz);
  std::error_code ec;
  if (!p.mesh_path.empty() && std::filesystem::exists(p.mesh_path, ec))
    throw ConfigError("parameter ~mesh_path: '" + p.mesh_path + "' exists, and a mesh is never written over a file");
  return p;
}

ReconstructionNode::ReconstructionNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh)
    : params_(NodeParameters::read(private_nh)), tf_listener_(tf_buffer_) {
  if (!params_.config.empty())
    config_ = PipelineConfig::load(params_.config);
  config_.validate();
  subscribe(nh);
  depth_pub_ = private_nh.advertise<Image>("depth", 2);
  weight_pub_ = private_nh.advertise<Image>("weight", 2);
  points_pub_ = private_nh.advertise<Cloud>("points", 2);
  mesh_pub_ = private_nh.advertise<visualization_msgs::Marker>("mesh", 1, true);
  last_mesh_ = ros::WallTime::now();
  worker_ = std::thread(&ReconstructionNode::work, this);
  ROS_INFO("msf_ros_node: %s + %s + %s%s%s, poses: %s (world frame '%s'), queue of %d frames", params_.lidar_topic.c_str(),
           params_.left_topic.c_str(), params_.right_topic.c_str(), params_.color_topic.empty() ? "" : " + ",
           params_.color_topic.c_str(), params_.poses.c_str(), params_.world_frame.c_str(), params_.queue_size);
}

void ReconstructionNode::subscribe(ros::NodeHandle& nh) {
  constexpr std::uint32_t kQueue = 5, kSyncQueue = 10;
  cloud_sub_.subscribe(nh, params_.lidar_topic, kQueue);
  left_sub_.subscribe(nh, params_.left_topic, kQueue);
  left_info_sub_.subscribe(nh, cameraInfoTopic(params_.left_topic), kQueue);
  right_sub_.subscribe(nh, params_.right_topic, kQueue);
  right_info_sub_.subscribe(nh, cameraInfoTopic(params_.right_topic), kQueue);
  const ros::Duration slop(params_.sync_slop_s);
  if (params_.color_topic.empty()) {
    stereo_sync_ = std::make_unique<StereoSync>(StereoPolicy(kSyncQueue), cloud_sub_, left_sub_, left_info_sub_,
                                                right_sub_, right_info_sub_);
    stereo_sync_->getPolicy()->setMaxIntervalDuration(slop);
    stereo_sync_->registerCallback(&ReconstructionNode::onStereo, this);
    return;
  }
  color_sub_.subscribe(nh, params_.color_topic, kQueue);
  color_info_sub_.subscribe(nh, cameraInfoTopic(params_.color_topic), kQueue);
  color_sync_ = std::make_unique<ColorSync>(ColorPolicy(kSyncQueue), cloud_sub_, left_sub_, left_info_sub_, right_sub_,
                                            right_info_sub_, color_sub_, color_info_sub_);
  color_sync_->getPolicy()->setMaxIntervalDuration(slop);
  color_sync_->registerCallback(&ReconstructionNode::onColor, this);
}

void ReconstructionNode::onStereo(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left,
                                  const Info::ConstPtr& left_info, const Image::ConstPtr& right,
                                  const Info::ConstPtr& right_info) {
  enqueue({cloud, left, right, nullptr, left_info, right_info, nullptr});
}

void ReconstructionNode::onColor(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left,
                                 const Info::ConstPtr& left_info, const Image::ConstPtr& right,
                                 const Info::ConstPtr& right_info, const Image::ConstPtr& color,
                                 const Info::ConstPtr& color_info) {
  enqueue({cloud, left, right, color, left_info, right_info, color_info});
}

void ReconstructionNode::enqueue(Pending pending) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++received_;
  if (queue_.size() >= static_cast<std::size_t>(params_.queue_size)) {
    queue_.pop_front(); // the oldest: a live map wants the newest frame
    ++dropped_["the engine was busy (its queue of " + std::to_string(params_.queue_size) + " frames was full)"];
    ROS_WARN_THROTTLE(5.0, "msf_ros_node: the engine is slower than the frames come: dropping the oldest waiting");
  }
  queue_.push_back(std::move(pending));
  wake_.notify_one();
}

void ReconstructionNode::work() {
  for (;;) {
    Pending pending;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return !queue_.empty() || !running_; });
      if (queue_.empty())
        return;
      pending = std::move(queue_.front());
      queue_.pop_front();
    }
    try {
      process(pending);
    } catch (const std::exception& e) {
      ROS_ERROR("msf_ros_node: frame at %.3f s: %s", pending.cloud->header.stamp.toSec(), e.what());
      drop("the engine refused it (logged)");
    }
  }
}

void ReconstructionNode::process(const Pending& pending) {
  if (!engine_ && !startEngine(pending))
    return;
  Frame frame;
  scanFromMessage(*pending.cloud, frame, "the scan on '" + params_.lidar_topic + "'");
  if (frame.scan->empty())
    return drop("a scan without a finite point");
  std::size_t index = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    index = reconstructed_;
  }
  stampFrame(frame, index, stampNs(pending.cloud->header.stamp), first_scan_ns_, pending.cloud->header.frame_id);
  frame.left = greyFromMessage(*pending.left, "the image on '" + params_.left_topic + "'");
  frame.right = greyFromMessage(*pending.right, "the image on '" + params_.right_topic + "'");
  if (pending.color)
    frame.color = colorFromMessage(*pending.color, "the image on '" + params_.color_topic + "'");
  // The pose from tf unless the engine tracks: its odometry by request, or (auto) when the
  // first frame had none.
  const bool tracking = params_.poses == "odometry" || (index > 0 && !engine_->odometryMs().empty());
  std::string error;
  if (!tracking)
    frame.has_pose =
        lookUp(params_.world_frame, pending.left->header.frame_id, pending.left->header.stamp, frame.T_world_cam0, error);
  if (!tracking && !frame.has_pose && (params_.poses == "tf" || index > 0))
    return drop("no pose from tf (" + params_.world_frame + " to the left camera at the frame's stamp)");
  const FrameResult result = engine_->addFrame(frame);
  {
    std::lock_guard<std::mutex> lock(mutex_);
    ++reconstructed_;
  }
  publish(result, pending.left->header);
  if (params_.mesh_rate_hz > 0 && (ros::WallTime::now() - last_mesh_).toSec() >= 1.0 / params_.mesh_rate_hz)
    publishMesh();
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
      ROS_ERROR("msf_ros_node: no tf from the LiDAR's frame '%s' to the left camera's '%s' (%s): publish it on "
                "/tf_static or give the rig's calibration in ~rig",
                lidar.c_str(), camera.c_str(), error.c_str());
      drop("no LiDAR extrinsic yet (tf from the scan's frame to the left camera's)");
      return false;
    }
    rig = rigFromCameraInfo(*pending.left_info, *pending.right_info, pending.color_info.get(), T_cam0_velo, size,
                            "the CameraInfo on " + cameraInfoTopic(params_.left_topic));
  }
  Reconstructor::Options options;
  options.poses = poseMode(params_.poses);
  options.threads = params_.threads;
  engine_ = std::make_unique<Reconstructor>(rig, config_, options);
  first_scan_ns_ = stampNs(pending.cloud->header.stamp);
  ROS_INFO("msf_ros_node: rig %dx%d, fx %.1f px, baseline %.3f m; reconstructing", size.width, size.height, rig.fx(0),
           rig.baselineGrey());
  return true;
}

bool ReconstructionNode::lookUp(const std::string& target, const std::string& source, const ros::Time& stamp,
                                Eigen::Isometry3d& T, std::string& error) {
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
  if (depth_pub_.getNumSubscribers() > 0)
    depth_pub_.publish(imageToMessage(result.fused.depth, camera_header));
  if (weight_pub_.getNumSubscribers() > 0)
    weight_pub_.publish(imageToMessage(result.fused.weight, camera_header));
  if (points_pub_.getNumSubscribers() > 0) {
    Cloud points;
    pcl::toROSMsg(fusedCloud(result.fused, engine_->calibration()), points);
    points.header = camera_header;
    points_pub_.publish(points);
  }
}

void ReconstructionNode::publishMesh() {
  last_mesh_ = ros::WallTime::now();
  if (mesh_pub_.getNumSubscribers() == 0)
    return; // meshing costs: only for a listener (the file at shutdown meshes anyway)
  std_msgs::Header header;
  header.stamp = ros::Time::now();
  header.frame_id = params_.world_frame;
  mesh_pub_.publish(meshToMarker(engine_->mesh(), header));
}

void ReconstructionNode::drop(const std::string& reason) {
  std::lock_guard<std::mutex> lock(mutex_);
  ++dropped_[reason];
  ROS_WARN_THROTTLE(5.0, "msf_ros_node: frame dropped: %s", reason.c_str());
}

void ReconstructionNode::saveMesh() {
  if (params_.mesh_path.empty() || !engine_)
    return;
  const TriangleMesh& mesh = engine_->mesh();
  if (mesh.triangles.empty()) {
    ROS_WARN("msf_ros_node: no surface was reconstructed: '%s' is not written", params_.mesh_path.c_str());
    return;
  }
  pcl::PolygonMesh polygons;
  mesh.toPolygonMesh(polygons);
  msf::saveMesh(params_.mesh_path, polygons);
  ROS_INFO("msf_ros_node: mesh of %zu triangles saved to '%s'", mesh.triangles.size(), params_.mesh_path.c_str());
}

ReconstructionNode::~ReconstructionNode() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    running_ = false;
  }
  wake_.notify_all();
  worker_.join(); // after the frames still waiting
  try {
    saveMesh();
  } catch (const std::exception& e) {
    ROS_ERROR("msf_ros_node: the mesh is not saved: %s", e.what());
  }
  std::size_t dropped = 0;
  std::string reasons;
  for (const auto& [reason, n] : dropped_) {
    dropped += n;
    reasons += "\n  " + std::to_string(n) + ": " + reason;
  }
  ROS_INFO("msf_ros_node: %zu frames received, %zu reconstructed, %zu dropped%s", received_, reconstructed_, dropped,
           reasons.c_str());
}

} // namespace msf
