// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/ros/bag_writer.h>
#include <msf/ros/compressed_image.h>
#include <msf/ros/message_conversions.h>

#include <rosbag/bag.h>
#include <tf2_msgs/TFMessage.h>

#include <cerrno>
#include <cmath>
#include <filesystem>

namespace msf {

namespace {

/// kitti2bag's names.
constexpr const char* kVeloTopic = "/kitti/velo/pointcloud";
constexpr const char* kVeloFrame = "velo_link";
constexpr const char* kWorldFrame = "world";
constexpr const char* kOdometryWorldFrame = "camera_init";
const struct {
  const char* namespace_;
  const char* frame;
} kCameras[] = {{"/kitti/camera_gray_left/", "camera_gray_left"},
                {"/kitti/camera_gray_right/", "camera_gray_right"},
                {"/kitti/camera_color_left/", "camera_color_left"}};

rosbag::compression::CompressionType compressionOf(const std::string& name) {
  if (name == "none")
    return rosbag::compression::Uncompressed;
  if (name == "lz4")
    return rosbag::compression::LZ4;
  if (name == "bz2")
    return rosbag::compression::BZ2;
  throw InvalidInputError("bag compression must be none, lz4 or bz2, not '" + name + "'");
}

std_msgs::Header header(const ros::Time& stamp, const std::string& frame, std::size_t seq) {
  std_msgs::Header h;
  h.stamp = stamp;
  h.frame_id = frame;
  h.seq = static_cast<std::uint32_t>(seq);
  return h;
}

geometry_msgs::TransformStamped stamped(const ros::Time& stamp, const std::string& parent, const std::string& child,
                                        const Eigen::Isometry3d& T_parent_child) {
  geometry_msgs::TransformStamped t;
  t.header = header(stamp, parent, 0);
  t.child_frame_id = child;
  t.transform = transformFromIsometry(T_parent_child);
  return t;
}

/// The rig's fixed transforms, as kitti2bag writes them for an odometry sequence.
tf2_msgs::TFMessage staticTransforms(const Calibration& calibration, bool with_color, const ros::Time& stamp) {
  tf2_msgs::TFMessage message;
  message.transforms.push_back(stamped(stamp, kWorldFrame, kOdometryWorldFrame, calibration.T_cam0_velo.inverse()));
  message.transforms.push_back(stamped(stamp, kCameras[0].frame, kVeloFrame, calibration.T_cam0_velo));
  for (int camera = 1; camera < (with_color ? 3 : 2); ++camera) {
    Eigen::Isometry3d T_cam0_cam = Eigen::Isometry3d::Identity();
    T_cam0_cam.translation() = calibration.cameraCenter(camera);
    message.transforms.push_back(stamped(stamp, kCameras[0].frame, kCameras[camera].frame, T_cam0_cam));
  }
  return message;
}

/// A connection header that rosbag play publishes latched, as a tf_static broadcaster does.
template <typename Message> boost::shared_ptr<ros::M_string> latched(const Message& message) {
  auto h = boost::make_shared<ros::M_string>();
  (*h)["type"] = ros::message_traits::datatype(message);
  (*h)["md5sum"] = ros::message_traits::md5sum(message);
  (*h)["message_definition"] = ros::message_traits::definition(message);
  (*h)["callerid"] = "/msf_kitti2bag";
  (*h)["latching"] = "1";
  return h;
}

void writeFrame(rosbag::Bag& bag, const Frame& frame, const FrameSource& source, const std::string& codec,
                std::size_t seq, const ros::Time& stamp) {
  const Calibration& calibration = source.calibration();
  const tf2_msgs::TFMessage fixed = staticTransforms(calibration, source.hasColor(), stamp);
  bag.write("/tf_static", stamp, fixed, latched(fixed));
  if (frame.has_pose) {
    tf2_msgs::TFMessage pose;
    pose.transforms.push_back(stamped(stamp, kOdometryWorldFrame, kCameras[0].frame, frame.T_world_cam0));
    bag.write("/tf", stamp, pose);
  }
  const cv::Mat* images[] = {&frame.left, &frame.right, &frame.color};
  for (int camera = 0; camera < 3; ++camera) {
    if (images[camera]->empty())
      continue;
    const std_msgs::Header h = header(stamp, kCameras[camera].frame, seq);
    const std::string topic = std::string(kCameras[camera].namespace_) + "image_raw";
    if (codec == "raw")
      bag.write(topic, stamp, imageToMessage(*images[camera], h));
    else
      bag.write(topic + "/compressed", stamp, compressImage(*images[camera], h, codec));
    bag.write(std::string(kCameras[camera].namespace_) + "camera_info", stamp,
              cameraInfoFromCalibration(calibration, camera, h));
  }
  bag.write(kVeloTopic, stamp, scanToMessage(frame, header(stamp, kVeloFrame, seq)));
}

} // namespace

void requireKittiBagOptions(const KittiBagOptions& options) {
  compressionOf(options.compression);
  if (options.images != "raw" && options.images != "png" && options.images != "jpeg")
    throw InvalidInputError("the bag's images must be raw, png or jpeg, not '" + options.images + "'");
  if (!(options.start_time_s > 0.0) || !(options.start_time_s < 4.0e9))
    throw InvalidInputError("the bag's start time must be in (0, 4e9) s since the epoch, not " +
                            std::to_string(options.start_time_s));
}

void writeKittiBag(const FrameSource& source, const std::vector<std::size_t>& frames, const std::string& path,
                   const KittiBagOptions& options) {
  std::error_code ec;
  if (!options.overwrite && std::filesystem::exists(path, ec))
    throw IOError("'" + path + "' exists: a bag is not written over a file unless told to (overwrite)", path, EEXIST);
  source.calibration().requireVelodyne();
  requireKittiBagOptions(options);
  const rosbag::compression::CompressionType compression = compressionOf(options.compression);
  const std::int64_t start_ns = std::llround(options.start_time_s * 1e9);
  writeAtomically(path, [&](const std::string& tmp) {
    try {
      rosbag::Bag bag(tmp, rosbag::bagmode::Write);
      bag.setCompression(compression);
      for (std::size_t k = 0; k < frames.size(); ++k) {
        const Frame frame = source.load(frames[k], true);
        const ros::Time stamp = stampFromNs(start_ns + std::llround(frame.timestamp * 1e9));
        writeFrame(bag, frame, source, options.images, frames[k], stamp);
        if (options.progress)
          options.progress(k + 1, frames.size());
      }
      bag.close();
    } catch (const rosbag::BagException& e) {
      throw IOError("cannot write ROS bag '" + path + "': " + e.what());
    }
  });
}

} // namespace msf
