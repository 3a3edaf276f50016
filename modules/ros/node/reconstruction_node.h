// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The reconstruction engine (msf::Reconstructor) as a ROS 1 node: messages in, the engine's
// depth, points and mesh out. All the method lives in the library; this converts and schedules.
#include "image_input.h"

#include <msf/pipeline/bounded_queue.h>
#include <msf/pipeline/pipeline_config.h>
#include <msf/pipeline/reconstructor.h>

#include <message_filters/subscriber.h>
#include <message_filters/sync_policies/approximate_time.h>
#include <message_filters/synchronizer.h>
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include <atomic>
#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <set>
#include <string>
#include <thread>
#include <vector>

namespace msf {

/// The node's private parameters, read once at start (config/kitti_bag.yaml lists them all).
/// The topics default to the layout kitti2bag and msf_kitti2bag write.
struct NodeParameters {
  std::string lidar_topic;   ///< sensor_msgs/PointCloud2
  std::string left_topic;    ///< rectified grey or colour Image; its CameraInfo is the sibling camera_info
  std::string right_topic;
  std::string color_topic;   ///< "" = no colour camera
  /// tf frame of the poses and of the mesh; "" = camera_init (kitti2bag's) when tf has it, else
  /// the root of the left camera's tf tree when a moving transform leads there.
  std::string world_frame;
  std::string poses = "auto";              ///< auto | tf | odometry | refine (Reconstructor::PoseMode)
  std::string config;        ///< the engine's YAML configuration ("" = its defaults)
  std::string rig;           ///< a calibration file instead of CameraInfo and the tf extrinsic
  int threads = 0;           ///< the engine's threads (0 = all cores)
  /// How the LiDAR takes its scans, when given: swept over their period (deskewed, carving allows
  /// for the skew) or at one instant; else the rig file's lidar.sweeping, or swept.
  std::optional<bool> sweeping_scans;
  int queue_size = 1;        ///< frames waiting for the engine; when full the oldest is dropped
  double sync_slop_s = 0.05; ///< the largest spread of stamps within one frame's messages
  double tf_timeout_s = 0.2; ///< how long a frame waits for its pose and the first for the extrinsic
  double mesh_rate_hz = 1.0; ///< mesh marker refresh (0 = none)
  std::string mesh_path;     ///< the mesh saved at shutdown (.ply/.obj/.vtk), "" = none
  bool overwrite = false;    ///< replace a mesh_path that exists (else refused at start)

  NodeParameters();
  /// Reads the private parameters; throws ConfigError naming the parameter for an unknown
  /// name, a wrong type or a value out of range, for a rig file that does not load, for a
  /// mesh_path that exists unless overwrite, is not .ply/.obj/.vtk or whose folder is missing
  /// or not writable.
  static NodeParameters read(const ros::NodeHandle& private_nh);
  /// The node's usage: its topics and every parameter with its meaning and default (-h).
  static std::string help();
};

class ReconstructionNode {
public:
  ReconstructionNode(ros::NodeHandle& nh, ros::NodeHandle& private_nh);
  /// Finishes the frames waiting, saves the mesh (mesh_path) and logs what was dropped and why.
  ~ReconstructionNode();

private:
  using Cloud = sensor_msgs::PointCloud2;
  using Image = sensor_msgs::Image;
  using Info = sensor_msgs::CameraInfo;
  using Clock = std::chrono::steady_clock;
  /// One frame's messages as the sync gave them; converted on the worker thread.
  struct Pending {
    Cloud::ConstPtr cloud;
    Image::ConstPtr left, right, color;
    Info::ConstPtr left_info, right_info, color_info;
  };
  using StereoPolicy = message_filters::sync_policies::ApproximateTime<Cloud, Image, Info, Image, Info>;
  using ColorPolicy = message_filters::sync_policies::ApproximateTime<Cloud, Image, Info, Image, Info, Image, Info>;

  void subscribe(ros::NodeHandle& nh);
  /// Counts each input's messages, for saying which one a scan waits for.
  void countMessages();
  /// Whether the colour camera is there (its image and CameraInfo topics have publishers):
  /// frames then wait for it.
  bool colorPublished() const;
  /// The inputs that have sent nothing yet, as "'topic', 'topic'" ("" = none).
  std::string silentInputs() const;
  /// For each image topic that has sent nothing while its "<topic>/compressed" is published (the
  /// master says), "; '<topic>/compressed' is published (<type>): name it in ~<parameter>".
  std::string compressedInstead() const;
  /// Counts the scan, and its going back in time (a bag played again): such scans make no frame.
  void onScan(const ros::Time& stamp);
  void onStereo(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left, const Info::ConstPtr& left_info,
                const Image::ConstPtr& right, const Info::ConstPtr& right_info);
  void onColor(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left, const Info::ConstPtr& left_info,
               const Image::ConstPtr& right, const Info::ConstPtr& right_info, const Image::ConstPtr& color,
               const Info::ConstPtr& color_info);
  /// The sync's callback: queues the frame, unless its scan is not newer than the last queued
  /// (both syncs gave it, or time went back); when the queue is full its oldest frame is dropped.
  void enqueue(Pending pending);
  /// The worker thread: one frame at a time through the engine, the mesh marker when due.
  void work();
  void process(const Pending& pending);
  /// The engine, made at the first frame: its rig from that frame's CameraInfo and the tf
  /// extrinsic (or the rig file). False when the extrinsic is not there yet.
  bool startEngine(const Pending& pending);
  Frame frameFromMessages(const Pending& pending) const;
  /// The frame's pose from tf, unless the engine tracks it; false when it needs one and tf has none.
  bool placeFrame(Frame& frame, const std_msgs::Header& camera_header);
  /// The world frame of the poses (NodeParameters::world_frame), "" while tf shows none.
  std::string worldFrame(const std::string& camera_frame);
  /// The root of the tf tree that holds `frame` (the frame itself when tf has no parent for it).
  std::string treeRoot(const std::string& frame) const;
  /// The odometry's pose of the frame to tf, as camera_init (the odometry's world) above the root
  /// of the left camera's tree, so that the mesh and the rig's frames meet in one tree; nothing
  /// when tf has camera_init already (kitti2bag's bags).
  void publishOdometryTf(const FrameResult& result, const std_msgs::Header& camera_header);
  /// Keeps the first frames' gap between the left and right images' stamps, and says once when
  /// their median is too large (stereoPairApartNote).
  void judgePairStamps(const Pending& pending);
  bool lookUp(const std::string& target, const std::string& source, const ros::Time& stamp,
              Eigen::Isometry3d& T, std::string& error) const;
  void publish(const FrameResult& result, const std_msgs::Header& camera_header);
  Clock::duration untilMeshDue() const;
  void publishMesh();
  void drop(const std::string& reason);
  void saveMesh();
  std::string summary() const;

  NodeParameters params_;
  PipelineConfig config_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  message_filters::Subscriber<Cloud> cloud_sub_;
  ImageInput left_sub_, right_sub_, color_sub_;
  message_filters::Subscriber<Info> left_info_sub_, right_info_sub_, color_info_sub_;
  std::unique_ptr<message_filters::Synchronizer<StereoPolicy>> stereo_sync_;
  std::unique_ptr<message_filters::Synchronizer<ColorPolicy>> color_sync_;
  ros::Publisher depth_pub_, weight_pub_, points_pub_, mesh_pub_;
  tf2_ros::TransformBroadcaster tf_broadcaster_;

  BoundedQueue<Pending> queue_;
  std::atomic<std::size_t> scans_ = 0, frames_ = 0, reconstructed_ = 0;
  std::atomic<std::size_t> scans_since_frame_ = 0;
  std::map<std::string, std::size_t> messages_; // per input topic (the spin thread's)
  std::int64_t newest_queued_scan_ns_ = 0;      // the frames go to the engine in time order
  // Scans not newer than one before them (the spin thread's): time went back, by up to the largest.
  std::int64_t newest_scan_ns_ = 0, largest_step_back_ns_ = 0;
  bool stepping_back_ = false; // the last scan was such a scan
  Clock::time_point next_input_warning_; // when scans without a frame may be warned of again
  std::atomic<std::size_t> scans_back_in_time_ = 0;
  Clock::time_point first_arrival_, last_arrival_; // of the frames (the spin thread's)
  mutable std::mutex drops_mutex_;
  std::map<std::string, std::size_t> dropped_; // reason -> frames
  std::vector<std::int64_t> pair_apart_ns_;    // the first frames' |left - right| stamps

  // The worker thread's own.
  std::unique_ptr<Reconstructor> engine_;
  bool tracking_ = false; // the engine's odometry gives the poses
  std::int64_t first_scan_ns_ = 0;
  std::string world_frame_; // resolved (worldFrame)
  std::optional<std::string> odometry_tf_child_; // under camera_init (publishOdometryTf); "" = none
  std::set<std::string> refusals_logged_; // the engine's errors, each logged once
  std_msgs::Header last_header_;
  Clock::time_point last_mesh_;
  std::size_t meshed_frames_ = 0;
  double first_frame_ms_ = 0, later_frames_ms_ = 0; // the engine's time
  std::thread worker_;
};

} // namespace msf
