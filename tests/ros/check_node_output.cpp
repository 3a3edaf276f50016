// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// What msf_ros_node published for a played bag, recorded by `rosbag record`, against the engine
// run here on the same bag's frames: tests/ros/ros_node.sh runs it. Prints each finding; exits 1
// when one fails.
//   check_node_output PLAYED.bag RECORDED.bag
#include <msf/pipeline/reconstructor.h>
#include <msf/ros/bag_source.h>

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <visualization_msgs/Marker.h>

#include <opencv2/core.hpp>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

namespace {

int failures = 0;

void expect(bool ok, const std::string& what) {
  std::printf("%s: %s\n", ok ? "ok" : "FAILED", what.c_str());
  failures += ok ? 0 : 1;
}

template <typename Message>
std::vector<typename Message::ConstPtr> messagesOn(const rosbag::Bag& bag, const std::string& topic) {
  std::vector<typename Message::ConstPtr> messages;
  for (const rosbag::MessageInstance& m : rosbag::View(bag, rosbag::TopicQuery(topic)))
    if (auto message = m.instantiate<Message>())
      messages.push_back(message);
  return messages;
}

/// Pixels where the two float images differ; NaN in `published` stands for <= 0 in `engine` (REP 118).
int differingPixels(const cv::Mat& published, const cv::Mat& engine, bool nan_for_none) {
  int differ = 0;
  for (int r = 0; r < engine.rows; ++r)
    for (int c = 0; c < engine.cols; ++c) {
      const float p = published.at<float>(r, c), e = engine.at<float>(r, c);
      const bool none = nan_for_none && !(e > 0);
      differ += none ? !std::isnan(p) : p != e;
    }
  return differ;
}

/// Each frame's depth and weight image: the engine's (addFrame) on the played bag's frame, bit for bit.
void checkImages(const std::vector<sensor_msgs::Image::ConstPtr>& depth,
                 const std::vector<sensor_msgs::Image::ConstPtr>& weight, const msf::BagSource& played) {
  expect(depth.size() == played.size(), std::to_string(depth.size()) + " depth images for " +
                                            std::to_string(played.size()) + " frames");
  expect(weight.size() == played.size(), std::to_string(weight.size()) + " weight images");
  msf::Reconstructor engine(played.calibration(), msf::PipelineConfig());
  const cv::Size size = played.calibration().image_size;
  for (std::size_t i = 0; i < std::min({depth.size(), weight.size(), played.size()}); ++i) {
    // As the node runs it: the small holes filled after the map took the frame.
    const msf::FrameResult expected = engine.addFrame(played.load(i));
    const std::string frame = "frame " + std::to_string(i);
    for (const auto& [name, message, image, nan] :
         {std::tuple{"depth", depth[i], expected.fused.depth, true}, {"weight", weight[i], expected.fused.weight, false}}) {
      const bool shaped = message->encoding == "32FC1" && message->width == static_cast<unsigned>(size.width) &&
                          message->height == static_cast<unsigned>(size.height);
      expect(shaped, frame + " " + name + ": " + message->encoding + " " + std::to_string(message->width) + "x" +
                         std::to_string(message->height) + " (32FC1 " + std::to_string(size.width) + "x" +
                         std::to_string(size.height) + ")");
      expect(message->header.frame_id == "camera_gray_left", frame + " " + name + " in '" + message->header.frame_id + "'");
      if (!shaped)
        continue;
      const cv::Mat published = cv_bridge::toCvShare(message)->image;
      const int differ = differingPixels(published, image, nan);
      const int finite = cv::countNonZero(image > 0);
      expect(differ == 0, frame + " " + name + ": " + std::to_string(differ) + " pixels differ from the engine's (" +
                              std::to_string(finite) + " with depth, finite" + (nan ? ", NaN elsewhere)" : ")"));
    }
  }
}

/// Each frame's fused points: organized like the image, a finite point where the depth is.
void checkPoints(const std::vector<sensor_msgs::PointCloud2::ConstPtr>& points,
                 const std::vector<sensor_msgs::Image::ConstPtr>& depth, const cv::Size& size) {
  expect(points.size() == depth.size(), std::to_string(points.size()) + " fused clouds");
  for (std::size_t i = 0; i < std::min(points.size(), depth.size()); ++i) {
    const sensor_msgs::PointCloud2& cloud = *points[i];
    const bool organized = cloud.width == static_cast<unsigned>(size.width) &&
                           cloud.height == static_cast<unsigned>(size.height);
    int finite = 0;
    for (sensor_msgs::PointCloud2ConstIterator<float> z(cloud, "z"); z != z.end(); ++z)
      finite += std::isfinite(*z);
    const cv::Mat d = cv_bridge::toCvShare(depth[i])->image;
    const int with_depth = cv::countNonZero(d == d); // not NaN
    expect(organized && finite == with_depth && finite > 0,
           "frame " + std::to_string(i) + " points: " + std::to_string(cloud.width) + "x" + std::to_string(cloud.height) +
               ", " + std::to_string(finite) + " finite (depth at " + std::to_string(with_depth) + " pixels)");
  }
}

/// The mesh markers: each a coloured triangle list in the world frame holding the engine's mesh of
/// the frames up to the one it is stamped with. The node meshes every 1 / mesh_rate_hz and as it
/// shuts down; a marker still being sent when the node exits is lost (ROS drops it), so which
/// frame the last recorded one holds depends on the machine's load; the saved mesh, which holds
/// them all, ros_node.sh compares with msf_reconstruct's.
void checkMarkers(const std::vector<visualization_msgs::Marker::ConstPtr>& markers,
                  const std::vector<sensor_msgs::Image::ConstPtr>& depth, const msf::BagSource& played) {
  expect(!markers.empty(), std::to_string(markers.size()) + " mesh markers");
  msf::Reconstructor engine(played.calibration(), msf::PipelineConfig());
  std::vector<std::size_t> triangles; // the engine's mesh after each frame, as the node was fed
  for (std::size_t i = 0; i < played.size(); ++i) {
    engine.addFrame(played.load(i));
    triangles.push_back(engine.mesh().triangles.size());
  }
  for (const auto& marker : markers) {
    std::size_t frame = depth.size();
    for (std::size_t i = 0; i < depth.size(); ++i)
      if (depth[i]->header.stamp == marker->header.stamp)
        frame = i;
    expect(frame < triangles.size(), "a marker stamped " + std::to_string(marker->header.stamp.toSec()) +
                                         " s, the stamp of the frame whose map it holds");
    if (frame >= triangles.size())
      continue;
    expect(marker->type == visualization_msgs::Marker::TRIANGLE_LIST && marker->header.frame_id == "camera_init",
           "the marker of frame " + std::to_string(frame) + ": type " + std::to_string(marker->type) +
               " (TRIANGLE_LIST " + std::to_string(visualization_msgs::Marker::TRIANGLE_LIST) + ") in '" +
               marker->header.frame_id + "'");
    expect(marker->points.size() == 3 * triangles[frame] && marker->colors.size() == marker->points.size(),
           "the marker of frame " + std::to_string(frame) + ": " + std::to_string(marker->points.size()) +
               " points, " + std::to_string(marker->colors.size()) + " colours for the engine's " +
               std::to_string(triangles[frame]) + " triangles");
  }
}

} // namespace

int main(int argc, char** argv) {
  if (argc != 3) {
    std::fprintf(stderr, "usage: %s PLAYED.bag RECORDED.bag\n", argv[0]);
    return 2;
  }
  try {
    const msf::BagSource played(argv[1]);
    rosbag::Bag recorded(argv[2], rosbag::bagmode::Read);
    const auto depth = messagesOn<sensor_msgs::Image>(recorded, "/msf_ros_node/depth");
    checkImages(depth, messagesOn<sensor_msgs::Image>(recorded, "/msf_ros_node/weight"), played);
    checkPoints(messagesOn<sensor_msgs::PointCloud2>(recorded, "/msf_ros_node/points"), depth,
                played.calibration().image_size);
    checkMarkers(messagesOn<visualization_msgs::Marker>(recorded, "/msf_ros_node/mesh"), depth, played);
  } catch (const std::exception& e) {
    std::fprintf(stderr, "check_node_output: error: %s\n", e.what());
    return 1;
  }
  return failures == 0 ? 0 : 1;
}
