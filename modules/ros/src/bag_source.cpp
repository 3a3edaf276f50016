// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/beam_elevations.h>
#include <msf/ros/bag_source.h>
#include <msf/ros/compressed_image.h>
#include <msf/ros/frame_matcher.h>
#include <msf/ros/message_conversions.h>

#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <std_msgs/Header.h>
#include <tf2/buffer_core.h>
#include <tf2/exceptions.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <mutex>
#include <numeric>

namespace msf::bag_detail {
/// The std_msgs/Header that every stamped message starts with, read alone: the bag is indexed
/// by the stamps its sensors gave, without decoding a scan's megabytes.
struct HeaderPrefix {
  std_msgs::Header header;
};
} // namespace msf::bag_detail

namespace ros {
namespace message_traits {
template <> struct MD5Sum<msf::bag_detail::HeaderPrefix> {
  static const char* value() { return "*"; }
  static const char* value(const msf::bag_detail::HeaderPrefix&) { return value(); }
};
template <> struct DataType<msf::bag_detail::HeaderPrefix> {
  static const char* value() { return "*"; }
  static const char* value(const msf::bag_detail::HeaderPrefix&) { return value(); }
};
template <> struct Definition<msf::bag_detail::HeaderPrefix> {
  static const char* value() { return ""; }
  static const char* value(const msf::bag_detail::HeaderPrefix&) { return value(); }
};
} // namespace message_traits
namespace serialization {
template <> struct Serializer<msf::bag_detail::HeaderPrefix> {
  template <typename Stream> static void read(Stream& stream, msf::bag_detail::HeaderPrefix& m) {
    stream.next(m.header);
  }
};
} // namespace serialization
} // namespace ros

namespace msf {

namespace {

constexpr const char* kPointCloud2 = "sensor_msgs/PointCloud2";
constexpr const char* kImage = "sensor_msgs/Image";
constexpr const char* kCompressedImage = "sensor_msgs/CompressedImage";
constexpr const char* kCameraInfo = "sensor_msgs/CameraInfo";
constexpr const char* kKittiOdometryWorld = "camera_init";

/// The sibling topic `name` of `topic` (image_transport's camera_info beside an image).
std::string sibling(const std::string& topic, const std::string& name) {
  const std::size_t slash = topic.rfind('/');
  return (slash == std::string::npos ? std::string() : topic.substr(0, slash + 1)) + name;
}

std::string secondsText(double s) {
  char text[32];
  std::snprintf(text, sizeof text, "%.3f s", s);
  return text;
}

} // namespace

/// The bag, its topics' messages sorted by their header stamps, and its transforms.
struct BagSource::Bag {
  struct Topic {
    std::string name;
    std::vector<rosbag::MessageInstance> messages; // in the bag's order
    std::vector<std::size_t> order;                // messages by stamp
    std::vector<std::int64_t> stamps;              // sorted
    std::string frame_id;                          // of the first message
    const rosbag::MessageInstance& at(std::size_t k) const { return messages[order[k]]; }
  };

  rosbag::Bag bag;
  mutable std::mutex mutex; // rosbag::Bag's reads share its buffers
  std::map<std::string, std::string> types; // topic -> message type
  Topic scans, left, right, color;
  std::unique_ptr<tf2::BufferCore> tf;
  bool has_dynamic_tf = false;

  std::string topicList() const {
    std::string list;
    for (const auto& [topic, type] : types)
      list += (list.empty() ? "" : ", ") + topic + " (" + type + ")";
    return list.empty() ? "none" : list;
  }

  void index(Topic& topic) {
    rosbag::View view(bag, rosbag::TopicQuery(topic.name));
    std::vector<std::pair<std::int64_t, std::size_t>> by_stamp;
    for (const rosbag::MessageInstance& m : view) {
      const auto header = m.instantiate<bag_detail::HeaderPrefix>();
      if (topic.messages.empty())
        topic.frame_id = header->header.frame_id;
      by_stamp.emplace_back(stampNs(header->header.stamp), topic.messages.size());
      topic.messages.push_back(m);
    }
    std::stable_sort(by_stamp.begin(), by_stamp.end());
    for (const auto& [ns, k] : by_stamp) {
      topic.stamps.push_back(ns);
      topic.order.push_back(k);
    }
  }

  void readTransforms() {
    rosbag::View all(bag);
    const double span_s = (all.getEndTime() - all.getBeginTime()).toSec();
    tf = std::make_unique<tf2::BufferCore>(ros::Duration(span_s + 60.0));
    rosbag::View view(bag, rosbag::TopicQuery(std::vector<std::string>{"/tf", "/tf_static"}));
    for (const rosbag::MessageInstance& m : view) {
      const auto message = m.instantiate<tf2_msgs::TFMessage>();
      if (!message)
        continue;
      const bool is_static = m.getTopic() == "/tf_static";
      has_dynamic_tf = has_dynamic_tf || !is_static;
      for (const auto& transform : message->transforms)
        tf->setTransform(transform, "bag", is_static);
    }
  }

  template <typename Message> boost::shared_ptr<Message> read(const Topic& topic, std::size_t k) const {
    std::lock_guard<std::mutex> lock(mutex);
    auto message = topic.at(k).instantiate<Message>();
    if (!message)
      throw InvalidInputError("topic '" + topic.name + "' holds " + topic.at(k).getDataType() + ", not the " +
                              ros::message_traits::DataType<Message>::value() + " expected");
    return message;
  }

  /// Message k of an image topic, decoded when the topic holds CompressedImage.
  sensor_msgs::ImageConstPtr readImage(const Topic& topic, std::size_t k, const std::string& what) const {
    if (types.at(topic.name) != kCompressedImage)
      return read<sensor_msgs::Image>(topic, k);
    return decodeCompressedImage(*read<sensor_msgs::CompressedImage>(topic, k), what);
  }
};

BagSource::BagSource(const std::string& path, const BagOptions& options, const std::string& rig)
    : path_(path), options_(options), bag_(std::make_unique<Bag>()) {
  if (!(options_.max_offset_s > 0.0) || !std::isfinite(options_.max_offset_s))
    throw InvalidInputError("the largest offset between a scan and its images must be > 0 s, not " +
                            std::to_string(options_.max_offset_s));
  try {
    bag_->bag.open(path, rosbag::bagmode::Read);
  } catch (const rosbag::BagException& e) {
    throw IOError("cannot read ROS bag '" + path + "': " + e.what());
  }
  try {
    resolveTopics();
    for (Bag::Topic* topic : {&bag_->scans, &bag_->left, &bag_->right, &bag_->color})
      if (!topic->name.empty())
        bag_->index(*topic);
    for (const Bag::Topic* topic : {&bag_->scans, &bag_->left, &bag_->right})
      if (topic->stamps.empty())
        throw InvalidInputError("ROS bag '" + path_ + "': topic '" + topic->name + "' has no message");
    bag_->readTransforms();
    readCalibration(rig);
    matchAndPose();
  } catch (const rosbag::BagException& e) {
    throw IOError("ROS bag '" + path + "' cannot be read: " + e.what());
  }
}

BagSource::~BagSource() = default;

void BagSource::resolveTopics() {
  rosbag::View all(bag_->bag);
  for (const rosbag::ConnectionInfo* c : all.getConnections())
    bag_->types[c->topic] = c->datatype;
  // The topic, or for an image kitti2bag's other name for it (image_raw or image, as its
  // version goes), each also compressed ("<image>/compressed"); "" when the bag has none.
  const auto find = [&](const std::string& topic, const char* type) -> std::string {
    const bool image = type == std::string(kImage);
    const auto has = [&](const std::string& name) {
      const auto it = bag_->types.find(name);
      return it != bag_->types.end() && (it->second == type || (image && it->second == kCompressedImage));
    };
    std::vector<std::string> names{topic};
    if (image)
      for (const char* name : {"image_raw", "image"})
        names.push_back(sibling(topic, name));
    for (const std::string& name : names) {
      if (has(name))
        return name;
      if (image && !isCompressedTopic(name) && has(name + "/compressed"))
        return name + "/compressed";
    }
    return {};
  };
  const auto resolve = [&](std::string& topic, const char* type, const std::string& role, const char* option) {
    const std::string found = find(topic, type);
    if (found.empty()) {
      const auto it = bag_->types.find(topic);
      throw InvalidInputError("ROS bag '" + path_ + "' has " +
                              (it == bag_->types.end() ? "no topic '" + topic + "'"
                                                       : "topic '" + topic + "' of type " + it->second) +
                              " where " + role + " (" + type + ") should be: name it with " + option +
                              "; the bag's topics: " + bag_->topicList());
    }
    if (found != topic)
      notes_.push_back("topic '" + topic + "' is absent: " + role + " read from '" + found + "'");
    topic = found;
  };
  resolve(options_.lidar_topic, kPointCloud2, "the LiDAR's scans", "-lidar_topic");
  resolve(options_.left_topic, kImage, "the left rectified image", "-left_topic");
  resolve(options_.right_topic, kImage, "the right rectified image", "-right_topic");
  // The default colour topic is optional; one named is not.
  const bool color_named = options_.color_topic != BagOptions().color_topic;
  if (!options_.color_topic.empty() && (color_named || !find(options_.color_topic, kImage).empty()))
    resolve(options_.color_topic, kImage, "the colour image", "-color_topic");
  else
    options_.color_topic.clear();
  has_color_ = !options_.color_topic.empty();
  bag_->scans.name = options_.lidar_topic;
  bag_->left.name = options_.left_topic;
  bag_->right.name = options_.right_topic;
  bag_->color.name = options_.color_topic;
}

void BagSource::readCalibration(const std::string& rig) {
  const auto info = [&](const std::string& image_topic) -> boost::shared_ptr<sensor_msgs::CameraInfo> {
    const std::string topic = cameraInfoTopic(image_topic);
    rosbag::View view(bag_->bag, rosbag::TopicQuery(topic));
    for (const rosbag::MessageInstance& m : view)
      if (auto message = m.instantiate<sensor_msgs::CameraInfo>())
        return message;
    return nullptr;
  };
  const auto left = info(options_.left_topic);
  const auto first_left = bag_->readImage(bag_->left, 0, "the first image of '" + path_ + "', topic '" +
                                                               options_.left_topic + "'");
  const cv::Size size(static_cast<int>(first_left->width), static_cast<int>(first_left->height));
  if (!rig.empty()) {
    calibration_ = loadCalibration(rig, size);
    notes_.push_back("calibration from '" + rig + "'; the bag's CameraInfo and LiDAR extrinsic are not read");
    applySweeping();
    learnFromFirstScan();
    return;
  }
  const auto right = info(options_.right_topic);
  const auto color = has_color_ ? info(options_.color_topic) : nullptr;
  for (const auto& [message, topic] : {std::pair{left, options_.left_topic}, {right, options_.right_topic}})
    if (!message)
      throw CalibrationError("ROS bag '" + path_ + "' has no " + kCameraInfo + " on '" + cameraInfoTopic(topic) +
                             "': give the rig's calibration with -rig FILE (a KITTI calib.txt or a rig YAML)");
  if (has_color_ && !color)
    throw CalibrationError("ROS bag '" + path_ + "' has no " + kCameraInfo + " on '" +
                           cameraInfoTopic(options_.color_topic) + "' for its colour camera: give -color_topic " +
                           "'' to leave colour out, or the rig's calibration with -rig FILE");
  const std::string& lidar_frame = bag_->scans.frame_id;
  const std::string& camera_frame = bag_->left.frame_id;
  Eigen::Isometry3d T_cam0_velo = Eigen::Isometry3d::Identity();
  if (lidar_frame != camera_frame) {
    try {
      T_cam0_velo = isometryFromTransform(bag_->tf->lookupTransform(camera_frame, lidar_frame, ros::Time(0)).transform);
    } catch (const tf2::TransformException& e) {
      throw CalibrationError("ROS bag '" + path_ + "' has no transform from the LiDAR's frame '" + lidar_frame +
                             "' to the left camera's frame '" + camera_frame + "' in /tf_static or /tf (" + e.what() +
                             "): give the LiDAR-camera extrinsic with -rig FILE (a KITTI calib.txt or a rig YAML)");
    }
  }
  calibration_ = rigFromCameraInfo(*left, *right, color.get(), T_cam0_velo, size, path_);
  applySweeping();
  learnFromFirstScan();
}

void BagSource::applySweeping() {
  if (options_.sweeping_scans)
    calibration_.lidar.sweeping = *options_.sweeping_scans;
}

void BagSource::learnFromFirstScan() {
  Frame first;
  scanFromMessage(*bag_->read<sensor_msgs::PointCloud2>(bag_->scans, 0), first,
                  "the first scan of '" + path_ + "', topic '" + options_.lidar_topic + "'");
  if (calibration_.lidar.sweeping && !options_.sweeping_scans && scanTimesAreOneInstant(first))
    notes_.push_back("the first scan's points all have the same time: if the LiDAR takes each scan at one instant, "
                     "say so with -sweeping_scans false (else its scans are taken as swept over their period)");
  if (!calibration_.lidar.beam_elevations_deg.empty())
    return;
  const std::vector<double> beams = beamElevationsFromRings(*first.scan, first.point_ring);
  if (beams.empty())
    return;
  calibration_.lidar.beam_elevations_deg = beams;
  calibration_.lidar.rings = static_cast<int>(beams.size());
  notes_.push_back(beamsFromRingsNote(beams));
}

void BagSource::matchAndPose() {
  const FrameMatches matches =
      matchFrames(bag_->scans.stamps, bag_->left.stamps, bag_->right.stamps, bag_->color.stamps,
                  static_cast<std::int64_t>(std::llround(options_.max_offset_s * 1e9)));
  notes_.insert(notes_.end(), matches.notes.begin(), matches.notes.end());
  std::vector<FrameMessages> frames;
  for (const FrameMatch& m : matches.frames)
    frames.push_back({m.scan, m.left, m.right, m.color});
  if (frames.empty())
    throw InvalidInputError("ROS bag '" + path_ + "' holds no frame: " +
                            (matches.notes.empty() ? std::string("no scan") : matches.notes.front()));

  const std::string& camera_frame = bag_->left.frame_id;
  std::string& world = options_.world_frame;
  if (!bag_->has_dynamic_tf) {
    if (!world.empty())
      throw InvalidInputError("ROS bag '" + path_ + "' has no /tf: no pose in the world frame '" + world + "'");
    frames_ = frames;
    return;
  }
  const bool named = !world.empty();
  if (named && !bag_->tf->_frameExists(world))
    throw InvalidInputError("ROS bag '" + path_ + "' has no tf frame '" + world + "' (the world frame); its frames:\n" +
                            bag_->tf->allFramesAsString());
  if (!named && bag_->tf->_frameExists(kKittiOdometryWorld)) {
    world = kKittiOdometryWorld;
  } else if (!named) { // the root of the camera's tree
    world = camera_frame;
    const ros::Time t = stampFromNs(bag_->left.stamps[frames.front().left]);
    for (std::string parent; bag_->tf->_getParent(world, t, parent) && parent != world;)
      world = parent;
  }

  std::vector<std::int64_t> no_pose;
  std::string first_error;
  for (const FrameMessages& f : frames) {
    const std::int64_t ns = bag_->left.stamps[f.left];
    try {
      poses_.push_back(isometryFromTransform(bag_->tf->lookupTransform(world, camera_frame, stampFromNs(ns)).transform));
      frames_.push_back(f);
    } catch (const tf2::TransformException& e) {
      no_pose.push_back(ns - bag_->scans.stamps[frames.front().scan]);
      if (first_error.empty())
        first_error = e.what();
    }
  }
  const std::string chain = "tf from '" + world + "' to '" + camera_frame + "'";
  if (frames_.empty() && named)
    throw InvalidInputError("ROS bag '" + path_ + "': no " + chain + " at any frame's time (" + first_error + ")");
  if (frames_.empty()) { // no pose at all: the engine's odometry
    notes_.push_back("no " + chain + " at the frames' times (" + first_error + "): no poses read");
    frames_ = frames;
    poses_.clear();
    return;
  }
  if (!no_pose.empty()) {
    std::string at;
    for (std::size_t k = 0; k < no_pose.size() && k < 5; ++k)
      at += (k ? ", " : "") + secondsText(static_cast<double>(no_pose[k]) * 1e-9);
    notes_.push_back(std::to_string(no_pose.size()) + " frames skipped: no " + chain + " at their time (at " + at +
                     (no_pose.size() > 5 ? ", ..." : "") + "; " + first_error + ")");
  }
}

std::string BagSource::frameName(std::size_t i) const {
  char name[32];
  std::snprintf(name, sizeof name, "%06zu", i);
  return name;
}

std::int64_t BagSource::scanStampNs(std::size_t i) const { return bag_->scans.stamps.at(frames_.at(i).scan); }
std::int64_t BagSource::leftStampNs(std::size_t i) const { return bag_->left.stamps.at(frames_.at(i).left); }

std::string BagSource::posesName() const {
  return "tf from '" + options_.world_frame + "' to '" + bag_->left.frame_id + "'";
}

std::string BagSource::scanName(std::size_t i) const {
  const double t = static_cast<double>(scanStampNs(i) - scanStampNs(0)) / 1e9;
  return "the scan at " + secondsText(t) + " on '" + options_.lidar_topic + "' of '" + path_ + "'";
}

Frame BagSource::load(std::size_t i, bool with_color) const {
  if (i >= size())
    throw InvalidInputError("frame " + std::to_string(i) + " is out of range: ROS bag '" + path_ + "' has " +
                            std::to_string(size()) + " frames");
  const FrameMessages& m = frames_[i];
  const auto scan = bag_->read<sensor_msgs::PointCloud2>(bag_->scans, m.scan);
  const std::string what = "frame " + frameName(i) + " of '" + path_ + "'";
  const auto left = bag_->readImage(bag_->left, m.left, what + ", topic '" + options_.left_topic + "'");
  const auto right = bag_->readImage(bag_->right, m.right, what + ", topic '" + options_.right_topic + "'");
  const auto color = with_color && m.color >= 0
                         ? bag_->readImage(bag_->color, static_cast<std::size_t>(m.color),
                                           what + ", topic '" + options_.color_topic + "'")
                         : nullptr;

  Frame f;
  scanFromMessage(*scan, f, what + ", topic '" + options_.lidar_topic + "'");
  if (f.scan->empty())
    throw InvalidInputError(what + ": " + scanName(i) + " has no finite point");
  stampFrame(f, i, scanStampNs(i), scanStampNs(0), scan->header.frame_id);
  greyPairFromMessages(*left, *right, f.left, f.right, what + ", topic '" + options_.left_topic + "'",
                       what + ", topic '" + options_.right_topic + "'");
  if (color)
    f.color = colorFromMessage(*color, what + ", topic '" + options_.color_topic + "'");
  const std::pair<const cv::Mat*, const std::string*> images[] = {
      {&f.left, &options_.left_topic}, {&f.right, &options_.right_topic}, {&f.color, &options_.color_topic}};
  for (const auto& [image, topic] : images)
    if (!image->empty() && image->size() != calibration_.image_size)
      throw InvalidInputError(what + ": the image on '" + *topic + "' is " + std::to_string(image->cols) + "x" +
                              std::to_string(image->rows) + ", not the calibration's " +
                              std::to_string(calibration_.image_size.width) + "x" +
                              std::to_string(calibration_.image_size.height));
  if (hasPoses()) {
    f.has_pose = true;
    f.T_world_cam0 = poses_[i];
  }
  return f;
}

} // namespace msf
