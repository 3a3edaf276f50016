#pragma once
// The reconstruction engine (msf::Reconstructor) as a ROS 1 node: messages in, the engine's
// depth, points and mesh out. All the method lives in the library; this converts and schedules.
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
#include <tf2_ros/transform_listener.h>

#include <condition_variable>
#include <deque>
#include <map>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

namespace msf {

/// The node's parameters (private, read once at start; config/ros_node.yaml has them all).
struct NodeParameters {
  std::string lidar_topic = "/kitti/velo/pointcloud";
  std::string left_topic = "/kitti/camera_gray_left/image_raw"; ///< camera_info: its sibling
  std::string right_topic = "/kitti/camera_gray_right/image_raw";
  std::string color_topic;          ///< "" = no colour camera
  std::string world_frame = "camera_init"; ///< tf frame of the poses and of the mesh
  std::string poses = "auto";       ///< auto | tf | odometry (Reconstructor::PoseMode)
  std::string config;               ///< the engine's YAML configuration ("" = defaults)
  std::string rig;                  ///< a calibration file replacing CameraInfo and the tf extrinsic
  int threads = 0;                  ///< the engine's threads (0 = all cores)
  int queue_size = 2;               ///< frames waiting for the engine (1-2): more are dropped
  double sync_slop_s = 0.05;        ///< the approximate sync's largest spread of stamps in a frame
  double tf_timeout_s = 0.5;        ///< how long a frame waits for its pose and the extrinsic
  double mesh_rate_hz = 1.0;        ///< mesh marker refresh (0 = only at shutdown)
  std::string mesh_path;            ///< the mesh saved at shutdown (.ply/.obj/.vtk), "" = none

  /// Reads the private parameters; throws ConfigError naming the parameter for a bad value.
  static NodeParameters read(const ros::NodeHandle& private_nh);
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
  /// One frame's messages as the sync gave them; converted on the worker thread.
  struct Pending {
    Cloud::ConstPtr cloud;
    Image::ConstPtr left, right, color;
    Info::ConstPtr left_info, right_info, color_info;
  };
  using StereoPolicy = message_filters::sync_policies::ApproximateTime<Cloud, Image, Info, Image, Info>;
  using ColorPolicy = message_filters::sync_policies::ApproximateTime<Cloud, Image, Info, Image, Info, Image, Info>;
  using StereoSync = message_filters::Synchronizer<StereoPolicy>;
  using ColorSync = message_filters::Synchronizer<ColorPolicy>;

  void subscribe(ros::NodeHandle& nh);
  void onStereo(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left, const Info::ConstPtr& left_info,
                const Image::ConstPtr& right, const Info::ConstPtr& right_info);
  void onColor(const Cloud::ConstPtr& cloud, const Image::ConstPtr& left, const Info::ConstPtr& left_info,
               const Image::ConstPtr& right, const Info::ConstPtr& right_info, const Image::ConstPtr& color,
               const Info::ConstPtr& color_info);
  /// The sync's callback: queues the frame, dropping the oldest waiting one when the queue is full.
  void enqueue(Pending pending);
  /// The worker thread: one frame at a time through the engine, then what it gives published.
  void work();
  void process(const Pending& pending);
  /// The engine, made at the first frame: its rig from that frame's CameraInfo and the tf extrinsic.
  bool startEngine(const Pending& pending);
  bool lookUp(const std::string& target, const std::string& source, const ros::Time& stamp,
              Eigen::Isometry3d& T, std::string& error);
  void publish(const FrameResult& result, const std_msgs::Header& camera_header);
  void publishMesh();
  void drop(const std::string& reason);
  void saveMesh();

  NodeParameters params_;
  PipelineConfig config_;
  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  message_filters::Subscriber<Cloud> cloud_sub_;
  message_filters::Subscriber<Image> left_sub_, right_sub_, color_sub_;
  message_filters::Subscriber<Info> left_info_sub_, right_info_sub_, color_info_sub_;
  std::unique_ptr<StereoSync> stereo_sync_;
  std::unique_ptr<ColorSync> color_sync_;
  ros::Publisher depth_pub_, weight_pub_, points_pub_, mesh_pub_;

  std::mutex mutex_; // guards the queue, the counts and running_
  std::condition_variable wake_;
  std::deque<Pending> queue_;
  bool running_ = true;
  std::size_t received_ = 0, reconstructed_ = 0;
  std::map<std::string, std::size_t> dropped_; // reason -> frames

  // The worker thread's own.
  std::unique_ptr<Reconstructor> engine_;
  std::int64_t first_scan_ns_ = 0;
  ros::WallTime last_mesh_;
  std::thread worker_;
};

} // namespace msf
