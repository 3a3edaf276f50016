// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// ROS 1 bags as datasets: bags written with the rosbag API (by the test itself, and by
// writeKittiBag from the KITTI sample) read back by BagSource, and what it refuses.
#include <msf/common/exceptions.h>
#include <msf/datasets/open_dataset.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/io/cloud_io.h>
#include <msf/io/sequence.h>
#include <msf/ros/bag_source.h>
#include <msf/ros/bag_writer.h>
#include <msf/ros/compressed_image.h>
#include <msf/ros/message_conversions.h>

#include "test_support.h"

#include <cv_bridge/cv_bridge.h>
#include <rosbag/bag.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_msgs/TFMessage.h>

#include <opencv2/core.hpp>
#include <pcl/common/io.h>

#include <cstring>
#include <fstream>

namespace {

using msf::test::errorOf;

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

// ---------------------------------------------------------------------------------------
// A tiny rig written with the rosbag API: 64x48 grey cameras of focal 100 px, 0.5 m apart,
// a LiDAR 0.2 m above the left camera (base_link -> lidar and base_link -> camera on
// /tf_static), scans of 4 points.

constexpr int kWidth = 64, kHeight = 48;
constexpr std::int64_t kStart = 1500000000LL * 1000000000LL;
constexpr std::int64_t kMs = 1000000;

struct TinyBag {
  std::string image_name = "image_raw";  // kitti2bag's newer versions write "image"
  std::string intensity = "intensity";   // and its older ones "i"
  bool ring_and_time = false;
  bool instant_scans = false; // with ring_and_time: every point's time 0 (a LiDAR of one instant)
  bool camera_info = true;
  bool extrinsic = true;
  bool poses = false;
  std::int64_t right_lag_ns = 0; // the right camera's stamps after the scan's
  int frames = 3;
  int image_bits = 8; // 12: mono16 of a 12-bit camera, the 8-bit values x 16
  int beam_points = 0; // with ring_and_time: returns of three beams (+2, -4, -10 degrees, numbered from the top)
  // The images as CompressedImage on <image_name>/compressed: "png", or what no camera sends
  // ("depth": a compressedDepth map, "garbage": bytes that do not decode); "" = Image.
  std::string compressed;
};

sensor_msgs::PointCloud2 tinyScan(const std_msgs::Header& header, const TinyBag& b, int frame) {
  sensor_msgs::PointCloud2 m;
  m.header = header;
  sensor_msgs::PointCloud2Modifier modifier(m);
  using F = sensor_msgs::PointField;
  if (b.ring_and_time)
    modifier.setPointCloud2Fields(6, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, b.intensity.c_str(),
                                  1, F::FLOAT32, "ring", 1, F::UINT16, "time", 1, F::FLOAT32);
  else
    modifier.setPointCloud2Fields(4, "x", 1, F::FLOAT32, "y", 1, F::FLOAT32, "z", 1, F::FLOAT32, b.intensity.c_str(),
                                  1, F::FLOAT32);
  modifier.resize(4 + 3 * static_cast<std::size_t>(b.beam_points));
  // The ring and time layout is packed (22 bytes a point): its fields are copied, not referenced.
  const auto put = [&m](const std::string& name, int k, auto value) {
    for (const auto& field : m.fields)
      if (field.name == name)
        std::memcpy(&m.data[static_cast<std::size_t>(k) * m.point_step + field.offset], &value, sizeof value);
  };
  for (int k = 0; k < 4; ++k) {
    put("x", k, 10.f + static_cast<float>(k)); // the LiDAR's x forward
    put("y", k, static_cast<float>(frame));
    put("z", k, k == 3 ? std::nanf("") : 0.f); // a point without a return: dropped
    put(b.intensity, k, 0.25f * static_cast<float>(k));
    if (b.ring_and_time) {
      put("ring", k, static_cast<std::uint16_t>(5 + k));
      // A driver that stamps the sweep's end, or a LiDAR of one instant.
      put("time", k, b.instant_scans ? 0.f : -0.1f + 0.02f * static_cast<float>(k));
    }
  }
  const double beams_deg[] = {2.0, -4.0, -10.0};
  for (int beam = 0; beam < 3; ++beam)
    for (int j = 0; j < b.beam_points; ++j) {
      const int k = 4 + beam * b.beam_points + j;
      const double e = beams_deg[beam] * M_PI / 180.0, azimuth = 0.01 * j;
      put("x", k, static_cast<float>(10.0 * std::cos(e) * std::cos(azimuth)));
      put("y", k, static_cast<float>(10.0 * std::cos(e) * std::sin(azimuth)));
      put("z", k, static_cast<float>(10.0 * std::sin(e)));
      put(b.intensity, k, 0.5f);
      put("ring", k, static_cast<std::uint16_t>(beam));
      put("time", k, 0.f);
    }
  return m;
}

sensor_msgs::CameraInfo tinyInfo(const std_msgs::Header& header, double tx) {
  sensor_msgs::CameraInfo info;
  info.header = header;
  info.width = kWidth;
  info.height = kHeight;
  info.P = {100, 0, 32, tx, 0, 100, 24, 0, 0, 0, 1, 0};
  return info;
}

geometry_msgs::TransformStamped transform(const std::string& parent, const std::string& child,
                                          const Eigen::Isometry3d& T, std::int64_t ns) {
  geometry_msgs::TransformStamped t;
  t.header.frame_id = parent;
  t.header.stamp = msf::stampFromNs(ns);
  t.child_frame_id = child;
  t.transform = msf::transformFromIsometry(T);
  return t;
}

/// The LiDAR (x forward, z up) 0.2 m above the left camera (z forward, y down).
Eigen::Isometry3d tinyCamFromLidar() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, -1, 0, 0, 0, -1, 1, 0, 0;
  T.translation() = Eigen::Vector3d(0, -0.2, 0);
  return T;
}

void writeTinyBag(const std::string& path, const TinyBag& b) {
  rosbag::Bag bag(path, rosbag::bagmode::Write);
  for (int f = 0; f < b.frames; ++f) {
    const std::int64_t ns = kStart + f * 100 * kMs;
    const auto header = [&](const std::string& frame, std::int64_t at) {
      std_msgs::Header h;
      h.stamp = msf::stampFromNs(at);
      h.frame_id = frame;
      return h;
    };
    if (b.extrinsic) { // through base_link, as a robot's tree has it
      tf2_msgs::TFMessage fixed;
      const Eigen::Isometry3d T_base_cam(Eigen::Translation3d(1.0, 0.0, 0.5));
      fixed.transforms.push_back(transform("base_link", "cam_left", T_base_cam, ns));
      fixed.transforms.push_back(transform("base_link", "lidar", T_base_cam * tinyCamFromLidar(), ns));
      bag.write("/tf_static", msf::stampFromNs(ns), fixed);
    }
    if (b.poses) {
      tf2_msgs::TFMessage pose;
      pose.transforms.push_back(
          transform("odom", "base_link", Eigen::Isometry3d(Eigen::Translation3d(0.0, 0.0, f)), ns));
      bag.write("/tf", msf::stampFromNs(ns), pose);
    }
    const cv::Mat image(kHeight, kWidth, CV_8UC1, cv::Scalar(10 * f + 1));
    const std::int64_t right_ns = ns + b.right_lag_ns;
    const auto message = [&](const cv::Mat& grey, const std_msgs::Header& h) {
      if (b.image_bits == 8)
        return msf::imageToMessage(grey, h);
      cv::Mat wide;
      grey.convertTo(wide, CV_16U, 1 << (b.image_bits - 8));
      sensor_msgs::Image m;
      cv_bridge::CvImage(h, "mono16", wide).toImageMsg(m);
      return m;
    };
    const auto compressed = [&](const cv::Mat& grey, const std_msgs::Header& h) {
      sensor_msgs::CompressedImage m = msf::compressImage(grey, h, "png");
      if (b.compressed == "depth")
        m.format = "16UC1; compressedDepth png";
      if (b.compressed == "garbage")
        m.data.assign(m.data.size(), 7);
      return m;
    };
    if (b.compressed.empty()) {
      bag.write("/cam/left/" + b.image_name, msf::stampFromNs(ns), message(image, header("cam_left", ns)));
      bag.write("/cam/right/" + b.image_name, msf::stampFromNs(right_ns),
                message(image + 1, header("cam_right", right_ns)));
    } else {
      bag.write("/cam/left/" + b.image_name + "/compressed", msf::stampFromNs(ns),
                compressed(image, header("cam_left", ns)));
      bag.write("/cam/right/" + b.image_name + "/compressed", msf::stampFromNs(right_ns),
                compressed(image + 1, header("cam_right", right_ns)));
    }
    if (b.camera_info) {
      bag.write("/cam/left/camera_info", msf::stampFromNs(ns), tinyInfo(header("cam_left", ns), 0.0));
      bag.write("/cam/right/camera_info", msf::stampFromNs(right_ns), tinyInfo(header("cam_right", right_ns), -50.0));
    }
    bag.write("/lidar/points", msf::stampFromNs(ns), tinyScan(header("lidar", ns), b, f));
  }
  bag.close();
}

msf::BagOptions tinyTopics() {
  msf::BagOptions o;
  o.lidar_topic = "/lidar/points";
  o.left_topic = "/cam/left/image_raw";
  o.right_topic = "/cam/right/image_raw";
  o.color_topic = "";
  return o;
}

TEST(BagSource, ReadsScansImagesCameraInfoAndTheExtrinsicOfARigsBag) {
  msf::test::TempDir dir;
  TinyBag b;
  b.right_lag_ns = 7 * kMs; // stamped apart, within the 50 ms tolerance
  writeTinyBag(dir.file("rig.bag"), b);
  const msf::BagSource source(dir.file("rig.bag"), tinyTopics());
  ASSERT_EQ(source.size(), 3u);
  EXPECT_EQ(source.frameName(2), "000002");
  EXPECT_FALSE(source.hasColor());
  EXPECT_FALSE(source.hasPoses()); // no /tf
  EXPECT_TRUE(source.notes().empty());
  const msf::Calibration& c = source.calibration();
  EXPECT_EQ(c.image_size, cv::Size(kWidth, kHeight));
  EXPECT_DOUBLE_EQ(c.fx(0), 100.0);
  EXPECT_DOUBLE_EQ(c.baselineGrey(), 0.5);
  // base_link -> cam_left and base_link -> lidar composed into the LiDAR-to-camera extrinsic.
  EXPECT_TRUE(c.T_cam0_velo.isApprox(tinyCamFromLidar(), 1e-12)) << c.T_cam0_velo.matrix();

  const msf::Frame f = source.load(1);
  EXPECT_EQ(f.index, 1u);
  EXPECT_DOUBLE_EQ(f.timestamp, 0.1);
  ASSERT_EQ(f.scan->size(), 3u); // the NaN point dropped
  EXPECT_EQ((*f.scan)[2].x, 12.f);
  EXPECT_EQ((*f.scan)[2].y, 1.f);
  EXPECT_EQ((*f.scan)[2].intensity, 0.5f);
  EXPECT_TRUE(f.point_ring.empty());
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_EQ(f.left.at<std::uint8_t>(0, 0), 11);
  EXPECT_EQ(f.right.at<std::uint8_t>(0, 0), 12);
  EXPECT_TRUE(f.color.empty());
  EXPECT_FALSE(f.has_pose);
  // A scan's place in the scans' stamp order, and a right image 7 ms late still its frame's.
  EXPECT_EQ(source.scanStampNs(1), kStart + 100 * kMs);
}

/// A rig that records its images compressed (image_transport's <image>/compressed): read where
/// the image topic is named, decoded, beside the image topic's CameraInfo; what is no camera's
/// image is refused naming the frame and the topic.
TEST(BagSource, ReadsCompressedImagesAndRefusesWhatIsNoCamerasImage) {
  msf::test::TempDir dir;
  TinyBag b;
  b.compressed = "png";
  writeTinyBag(dir.file("png.bag"), b);
  const msf::BagSource source(dir.file("png.bag"), tinyTopics());
  ASSERT_EQ(source.size(), 3u);
  ASSERT_EQ(source.notes().size(), 2u);
  EXPECT_EQ(source.notes()[0], "topic '/cam/left/image_raw' is absent: the left rectified image read from "
                               "'/cam/left/image_raw/compressed'");
  EXPECT_DOUBLE_EQ(source.calibration().baselineGrey(), 0.5); // /cam/*/camera_info
  const msf::Frame f = source.load(1);
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_EQ(cv::norm(f.left, cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(11)), cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(f.right, cv::Mat(kHeight, kWidth, CV_8UC1, cv::Scalar(12)), cv::NORM_INF), 0.0);

  b.compressed = "depth";
  writeTinyBag(dir.file("depth.bag"), b);
  EXPECT_EQ(errorOf([&] { msf::BagSource(dir.file("depth.bag"), tinyTopics()); }),
            "the first image of '" + dir.file("depth.bag") + "', topic '/cam/left/image_raw/compressed': a "
            "compressedDepth image (format '16UC1; compressedDepth png') is a depth map, not a camera's");
  b.compressed = "garbage";
  writeTinyBag(dir.file("garbage.bag"), b);
  EXPECT_TRUE(contains(errorOf([&] { msf::BagSource(dir.file("garbage.bag"), tinyTopics()); }),
                       "topic '/cam/left/image_raw/compressed': the compressed image (format 'mono8; png compressed "
                       "mono8', "))
      << errorOf([&] { msf::BagSource(dir.file("garbage.bag"), tinyTopics()); });
}

TEST(CompressedImage, TopicsAndCodecs) {
  EXPECT_TRUE(msf::isCompressedTopic("/cam/left/image_raw/compressed"));
  EXPECT_FALSE(msf::isCompressedTopic("/cam/left/image_raw"));
  EXPECT_FALSE(msf::isCompressedTopic("/compressed"));
  EXPECT_EQ(msf::cameraInfoTopic("/cam/left/image_raw/compressed"), "/cam/left/camera_info");
  EXPECT_EQ(msf::cameraInfoTopic("/cam/left/image_raw"), "/cam/left/camera_info");
  EXPECT_EQ(msf::cameraInfoTopic("image"), "camera_info");
  // 12 bits of a mono16 camera, kept by PNG; JPEG holds 8 bits and says so.
  cv::Mat wide(4, 6, CV_16UC1);
  cv::randu(wide, 0, 4096);
  const auto png = msf::compressImage(wide, std_msgs::Header(), "png");
  EXPECT_EQ(png.format, "mono16; png compressed mono16");
  const sensor_msgs::ImageConstPtr back = msf::decodeCompressedImage(png, "test");
  EXPECT_EQ(back->encoding, "mono16");
  EXPECT_EQ(cv::norm(cv_bridge::toCvShare(back)->image, wide, cv::NORM_INF), 0.0);
  EXPECT_EQ(errorOf([&] { msf::compressImage(wide, std_msgs::Header(), "jpeg"); }),
            "JPEG holds 8 bits a channel: a mono16 image is compressed as png");
  EXPECT_EQ(errorOf([&] { msf::compressImage(wide, std_msgs::Header(), "webp"); }),
            "images are compressed as png or jpeg, not 'webp'");
  sensor_msgs::CompressedImage bayer = png;
  bayer.format = "bayer_rggb8; png compressed bayer_rggb8";
  EXPECT_EQ(errorOf([&] { msf::decodeCompressedImage(bayer, "the image on '/cam'"); }),
            "the image on '/cam': a Bayer mosaic (format 'bayer_rggb8; png compressed bayer_rggb8') is not a "
            "rectified camera's image");
}

/// A 12-bit camera's mono16 pair: scaled by the bits the brighter image needs, one gain for both,
/// not by 256 (which left it black).
TEST(BagSource, AMono16PairOfA12BitCameraIsScaledByOneGain) {
  msf::test::TempDir dir;
  TinyBag b;
  b.image_bits = 12;
  writeTinyBag(dir.file("wide.bag"), b);
  const msf::Frame f = msf::BagSource(dir.file("wide.bag"), tinyTopics()).load(2);
  // Frame 2: left 21 x 16 = 336, right 22 x 16 = 352, which needs 9 bits: x 255 / 511.
  EXPECT_EQ(f.left.type(), CV_8UC1);
  EXPECT_EQ(f.left.at<std::uint8_t>(0, 0), 168);
  EXPECT_EQ(f.right.at<std::uint8_t>(0, 0), 176);
}

/// A bag's CameraInfo and tf say nothing of the LiDAR's beams: its scans' rings do.
TEST(BagSource, TheBeamsOfARigsBagComeFromItsFirstScansRings) {
  msf::test::TempDir dir;
  TinyBag b;
  b.ring_and_time = true;
  b.beam_points = 50;
  writeTinyBag(dir.file("beams.bag"), b);
  const msf::BagSource source(dir.file("beams.bag"), tinyTopics());
  const std::vector<double>& beams = source.calibration().lidar.beam_elevations_deg;
  ASSERT_EQ(beams.size(), 3u);
  EXPECT_NEAR(beams[0], -10.0, 1e-4);
  EXPECT_NEAR(beams[2], 2.0, 1e-4);
  EXPECT_EQ(source.calibration().lidar.rings, 3);
  ASSERT_FALSE(source.notes().empty());
  EXPECT_TRUE(contains(source.notes().back(), "3 beams from the first scan's rings, -10.0 to 2.0 degrees"))
      << source.notes().back();
  // A bag does not say how its LiDAR takes scans: swept, unless told (-sweeping_scans false).
  EXPECT_TRUE(source.calibration().lidar.sweeping);
  msf::BagOptions snapshots = tinyTopics();
  snapshots.sweeping_scans = false;
  EXPECT_FALSE(msf::BagSource(dir.file("beams.bag"), snapshots).calibration().lidar.sweeping);
  // Without rings, none: KITTI's sizes, as for a rig file that lists no beams.
  writeTinyBag(dir.file("plain.bag"), TinyBag{});
  EXPECT_TRUE(msf::BagSource(dir.file("plain.bag"), tinyTopics()).calibration().lidar.beam_elevations_deg.empty());
}

/// Scans whose points all have one time may come from a LiDAR of one instant, or from a driver
/// that leaves the field unset: still taken as swept, and the run says how to tell it otherwise.
TEST(BagSource, ScansOfOneInstantAreSaidWhileTheRigIsTakenAsSweeping) {
  msf::test::TempDir dir;
  TinyBag b;
  b.ring_and_time = true;
  b.instant_scans = true;
  writeTinyBag(dir.file("instant.bag"), b);
  const auto said = [](const msf::BagSource& source) {
    for (const std::string& note : source.notes())
      if (contains(note, "the first scan's points all have the same time: if the LiDAR takes each scan at one "
                         "instant, say so with -sweeping_scans false"))
        return true;
    return false;
  };
  const msf::BagSource source(dir.file("instant.bag"), tinyTopics());
  EXPECT_TRUE(source.calibration().lidar.sweeping);
  EXPECT_TRUE(said(source));
  msf::BagOptions snapshots = tinyTopics();
  snapshots.sweeping_scans = false; // told: nothing to say
  EXPECT_FALSE(said(msf::BagSource(dir.file("instant.bag"), snapshots)));
  b.instant_scans = false; // the times of a sweep
  writeTinyBag(dir.file("swept.bag"), b);
  EXPECT_FALSE(said(msf::BagSource(dir.file("swept.bag"), tinyTopics())));
  writeTinyBag(dir.file("plain.bag"), TinyBag{}); // no time field: nothing to go by
  EXPECT_FALSE(said(msf::BagSource(dir.file("plain.bag"), tinyTopics())));
}

TEST(BagSource, ReadsKitti2bagsOtherNamesRingsTimesAndPosesFromTf) {
  msf::test::TempDir dir;
  TinyBag b;
  b.image_name = "image";
  b.intensity = "i";
  b.ring_and_time = true;
  b.poses = true;
  writeTinyBag(dir.file("old.bag"), b);
  const msf::BagSource source(dir.file("old.bag"), tinyTopics());
  EXPECT_EQ(source.options().left_topic, "/cam/left/image");
  ASSERT_EQ(source.notes().size(), 2u);
  EXPECT_EQ(source.notes()[0], "topic '/cam/left/image_raw' is absent: the left rectified image read from '/cam/left/image'");
  // The world: the root of the camera's tree (odom -> base_link -> cam_left).
  EXPECT_EQ(source.options().world_frame, "odom");
  ASSERT_TRUE(source.hasPoses());
  EXPECT_TRUE(source.poses()[2].translation().isApprox(Eigen::Vector3d(1.0, 0.0, 2.5), 1e-12))
      << source.poses()[2].translation().transpose();
  const msf::Frame f = source.load(2);
  EXPECT_TRUE(f.has_pose);
  EXPECT_EQ((*f.scan)[1].intensity, 0.25f);
  ASSERT_EQ(f.point_ring.size(), 3u);
  EXPECT_EQ(f.point_ring[2], 7);
  ASSERT_EQ(f.point_time_s.size(), 3u);
  EXPECT_FLOAT_EQ(f.point_time_s[0], 0.f); // from the sweep's start
  EXPECT_FLOAT_EQ(f.point_time_s[2], 0.04f);
}

/// A driver's cloud of float64 coordinates (and an int intensity): read as their values; one
/// without z: refused naming the fields it has.
TEST(MessageConversions, AScanOfFloat64CoordinatesIsReadAndOneWithoutZIsNamed) {
  sensor_msgs::PointCloud2 m;
  sensor_msgs::PointCloud2Modifier modifier(m);
  using F = sensor_msgs::PointField;
  modifier.setPointCloud2Fields(4, "x", 1, F::FLOAT64, "y", 1, F::FLOAT64, "z", 1, F::FLOAT64, "intensity", 1,
                                F::UINT16);
  modifier.resize(2);
  const double xyz[2][3] = {{10.5, -2.25, 1.0}, {20.0, 0.5, -1.5}};
  for (std::size_t k = 0; k < 2; ++k) {
    std::memcpy(&m.data[k * m.point_step], xyz[k], sizeof xyz[k]);
    const std::uint16_t intensity = static_cast<std::uint16_t>(100 * (k + 1));
    std::memcpy(&m.data[k * m.point_step + m.fields[3].offset], &intensity, sizeof intensity);
  }
  msf::Frame frame;
  msf::scanFromMessage(m, frame, "the scan");
  ASSERT_EQ(frame.scan->size(), 2u);
  EXPECT_EQ((*frame.scan)[0].y, -2.25f);
  EXPECT_EQ((*frame.scan)[1].z, -1.5f);
  EXPECT_EQ((*frame.scan)[1].intensity, 200.f);

  m.fields[2].datatype = 42;
  EXPECT_EQ(errorOf([&] { msf::scanFromMessage(m, frame, "the scan"); }),
            "the scan: PointCloud2 field 'z' has datatype 42, which sensor_msgs/PointField does not define");
  modifier.setPointCloud2Fields(3, "x", 1, F::FLOAT64, "y", 1, F::FLOAT64, "intensity", 1, F::FLOAT32);
  EXPECT_EQ(errorOf([&] { msf::scanFromMessage(m, frame, "the scan"); }),
            "the scan: PointCloud2 has no field 'z' (fields: x y intensity)");
}

TEST(BagSource, RefusesWhatItCannotReadNamingWhatToGive) {
  msf::test::TempDir dir;
  TinyBag no_extrinsic;
  no_extrinsic.extrinsic = false;
  writeTinyBag(dir.file("no_tf.bag"), no_extrinsic);
  const std::string missing_tf = errorOf([&] { msf::BagSource(dir.file("no_tf.bag"), tinyTopics()); });
  EXPECT_TRUE(contains(missing_tf, "no transform from the LiDAR's frame 'lidar' to the left camera's frame 'cam_left'"))
      << missing_tf;
  EXPECT_TRUE(contains(missing_tf, "give the LiDAR-camera extrinsic with -rig FILE")) << missing_tf;

  // A rig file gives what the bag lacks.
  msf::Calibration rig;
  rig.P[0] << 100, 0, 32, 0, 0, 100, 24, 0, 0, 0, 1, 0;
  rig.P[1] = rig.P[0];
  rig.P[1](0, 3) = -30.0;
  rig.P[2] = rig.P[0];
  rig.P[3] = rig.P[1];
  rig.T_cam0_velo = tinyCamFromLidar();
  msf::saveOdometryCalibration(rig, dir.file("calib.txt"));
  const msf::BagSource with_rig(dir.file("no_tf.bag"), tinyTopics(), dir.file("calib.txt"));
  EXPECT_DOUBLE_EQ(with_rig.calibration().baselineGrey(), 0.3);
  EXPECT_EQ(with_rig.calibration().image_size, cv::Size(kWidth, kHeight));

  TinyBag no_info;
  no_info.camera_info = false;
  writeTinyBag(dir.file("no_info.bag"), no_info);
  const std::string missing_info = errorOf([&] { msf::BagSource(dir.file("no_info.bag"), tinyTopics()); });
  EXPECT_TRUE(contains(missing_info, "no sensor_msgs/CameraInfo on '/cam/left/camera_info'")) << missing_info;

  writeTinyBag(dir.file("rig.bag"), TinyBag{});
  msf::BagOptions wrong = tinyTopics();
  wrong.lidar_topic = "/velodyne_points";
  const std::string missing_topic = errorOf([&] { msf::BagSource(dir.file("rig.bag"), wrong); });
  EXPECT_TRUE(contains(missing_topic, "has no topic '/velodyne_points' where the LiDAR's scans")) << missing_topic;
  EXPECT_TRUE(contains(missing_topic, "-lidar_topic")) << missing_topic;
  EXPECT_TRUE(contains(missing_topic, "/lidar/points (sensor_msgs/PointCloud2)")) << missing_topic;
  wrong = tinyTopics();
  wrong.left_topic = "/lidar/points";
  EXPECT_TRUE(contains(errorOf([&] { msf::BagSource(dir.file("rig.bag"), wrong); }),
                       "has topic '/lidar/points' of type sensor_msgs/PointCloud2 where the left rectified image"));
  wrong = tinyTopics();
  wrong.world_frame = "map";
  EXPECT_TRUE(contains(errorOf([&] { msf::BagSource(dir.file("rig.bag"), wrong); }), "has no /tf"));

  // Images too far from every scan: no frame, and why.
  TinyBag late;
  late.right_lag_ns = 30 * kMs;
  writeTinyBag(dir.file("late.bag"), late);
  msf::BagOptions strict = tinyTopics();
  strict.max_offset_s = 0.01;
  const std::string no_frame = errorOf([&] { msf::BagSource(dir.file("late.bag"), strict); });
  EXPECT_TRUE(contains(no_frame, "holds no frame: 3 scans skipped: no right image within 10 ms")) << no_frame;

  std::ofstream(dir.file("not.bag")) << "#ROSBAG V2.0 and then nothing";
  EXPECT_TRUE(contains(errorOf([&] { msf::BagSource(dir.file("not.bag")); }), "cannot read ROS bag"));
}

TEST(BagSource, OpenDatasetKnowsABagByItsFirstBytes) {
  msf::test::TempDir dir;
  writeTinyBag(dir.file("recording"), TinyBag{}); // no .bag extension
  EXPECT_TRUE(msf::isRosBag(dir.file("recording")));
  msf::DatasetOptions options;
  options.bag = tinyTopics();
  const auto source = msf::openDataset(dir.file("recording"), options);
  EXPECT_NE(dynamic_cast<const msf::BagSource*>(source.get()), nullptr);
  EXPECT_EQ(source->size(), 3u);
  EXPECT_TRUE(contains(errorOf([&] { msf::openDataset(dir.path(), options); }), "for a ROS bag"));
}

/// A rig's own bag, its topics named on msf_convert's command line as on msf_reconstruct's, into
/// the generic layout (what msf_batch runs): the same rig, frames, images and scans.
TEST(BagSource, ABagOfARigsOwnTopicsConvertsToTheGenericLayout) {
  msf::test::TempDir dir;
  TinyBag b;
  b.poses = true;
  writeTinyBag(dir.file("rig.bag"), b);
  const std::string topics = " -lidar_topic /lidar/points -left_topic /cam/left/image_raw -right_topic "
                             "/cam/right/image_raw -color_topic ''";
  const msf::test::CommandResult r =
      msf::test::runTool("msf_convert", "'" + dir.file("rig.bag") + "' '" + dir.file("rig") + "'" + topics);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const msf::BagSource bag(dir.file("rig.bag"), tinyTopics());
  const auto folder = msf::openDataset(dir.file("rig"));
  ASSERT_EQ(folder->size(), bag.size());
  EXPECT_EQ(folder->calibration().image_size, bag.calibration().image_size);
  EXPECT_TRUE(folder->calibration().P[1].isApprox(bag.calibration().P[1], 1e-12));
  EXPECT_TRUE(folder->calibration().T_cam0_velo.isApprox(bag.calibration().T_cam0_velo, 1e-9));
  for (std::size_t i = 0; i < bag.size(); ++i) {
    const msf::Frame a = bag.load(i), c = folder->load(i);
    EXPECT_EQ(cv::norm(a.left, c.left, cv::NORM_INF), 0.0) << i;
    EXPECT_EQ(cv::norm(a.right, c.right, cv::NORM_INF), 0.0) << i;
    ASSERT_EQ(a.scan->size(), c.scan->size()) << i;
    EXPECT_EQ(a.scan->back().getVector3fMap(), c.scan->back().getVector3fMap()) << i;
    EXPECT_NEAR(a.timestamp, c.timestamp, 1e-9) << i;
    ASSERT_TRUE(c.has_pose) << i;
    EXPECT_TRUE(a.T_world_cam0.isApprox(c.T_world_cam0, 1e-6)) << i;
  }
  const msf::test::CommandResult default_topics =
      msf::test::runTool("msf_convert", "'" + dir.file("rig.bag") + "' '" + dir.file("other") + "'");
  EXPECT_TRUE(contains(default_topics.err, "-lidar_topic")) << default_topics.err;
  EXPECT_FALSE(msf::test::fileExists(dir.file("other")));
}

// ---------------------------------------------------------------------------------------
// KITTI odometry 04 through writeKittiBag and back.

TEST(KittiBag, ReadBackEqualsTheKittiReader) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  const std::vector<std::size_t> frames{0, 1, 2, 3};
  msf::writeKittiBag(sequence, frames, dir.file("04.bag"));
  EXPECT_TRUE(contains(errorOf([&] { msf::writeKittiBag(sequence, frames, dir.file("04.bag")); }),
                       "exists: a bag is not written over a file unless told to"));
  msf::KittiBagOptions replace;
  replace.overwrite = true;
  msf::writeKittiBag(sequence, frames, dir.file("04.bag"), replace); // the same bag again

  const msf::BagSource bag(dir.file("04.bag")); // kitti2bag's topics, the default
  ASSERT_EQ(bag.size(), frames.size());
  EXPECT_TRUE(bag.notes().empty()) << bag.notes().front();
  EXPECT_TRUE(bag.hasColor());
  EXPECT_EQ(bag.options().world_frame, "camera_init");
  const msf::Calibration &a = sequence.calibration(), &b = bag.calibration();
  for (int camera = 0; camera < 3; ++camera)
    EXPECT_EQ(a.P[camera], b.P[camera]) << "P" << camera; // CameraInfo's P holds doubles: exact
  EXPECT_EQ(a.image_size, b.image_size);
  // tf carries rotations as quaternions: KITTI's matrices come back to within their own
  // orthonormality (~1e-7), not bit for bit.
  EXPECT_TRUE(a.T_cam0_velo.isApprox(b.T_cam0_velo, 1e-6)) << b.T_cam0_velo.matrix();
  ASSERT_TRUE(bag.hasPoses());
  for (std::size_t i : frames) {
    const msf::Frame k = sequence.load(i), r = bag.load(i);
    EXPECT_EQ(k.timestamp, r.timestamp) << "frame " << i;
    ASSERT_EQ(k.scan->size(), r.scan->size());
    EXPECT_EQ(std::memcmp(k.scan->points.data(), r.scan->points.data(), k.scan->size() * sizeof(pcl::PointXYZI)), 0);
    EXPECT_EQ(k.scan->header.stamp, r.scan->header.stamp);
    EXPECT_EQ(cv::norm(k.left, r.left, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(k.right, r.right, cv::NORM_INF), 0.0);
    EXPECT_EQ(cv::norm(k.color, r.color, cv::NORM_INF), 0.0);
    EXPECT_TRUE(k.T_world_cam0.isApprox(r.T_world_cam0, 1e-6)) << "frame " << i;
    EXPECT_LT((k.T_world_cam0.translation() - r.T_world_cam0.translation()).norm(), 1e-9);
  }
}

/// The sequence written with compressed images: PNG reads back as the folder's images, byte for
/// byte; JPEG close to them. An unknown codec is refused before a bag is written.
TEST(KittiBag, CompressedImagesReadBackLosslessAsPngAndCloseAsJpeg) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Sequence sequence(msf::test::kittiDir() + "/odometry/sequences/04");
  const std::vector<std::size_t> frames{0, 1};
  msf::KittiBagOptions options;
  for (const std::string codec : {"png", "jpeg"}) {
    options.images = codec;
    msf::writeKittiBag(sequence, frames, dir.file(codec + ".bag"), options);
    const msf::BagSource bag(dir.file(codec + ".bag"));
    ASSERT_EQ(bag.size(), frames.size());
    ASSERT_EQ(bag.notes().size(), 3u) << codec;
    EXPECT_EQ(bag.notes()[2], "topic '/kitti/camera_color_left/image_raw' is absent: the colour image read from "
                              "'/kitti/camera_color_left/image_raw/compressed'");
    EXPECT_EQ(sequence.calibration().P[1], bag.calibration().P[1]);
    for (std::size_t i : frames) {
      const msf::Frame k = sequence.load(i), r = bag.load(i);
      for (const auto& [a, b] : {std::pair{&k.left, &r.left}, {&k.right, &r.right}, {&k.color, &r.color}}) {
        ASSERT_EQ(a->type(), b->type()) << codec;
        if (codec == "png") {
          EXPECT_EQ(cv::norm(*a, *b, cv::NORM_INF), 0.0) << "frame " << i;
        } else {
          // Within 2 grey levels on average; colour more, its chroma halved each way (4:2:0).
          EXPECT_LT(cv::norm(*a, *b, cv::NORM_L1) / static_cast<double>(a->total() * a->channels()),
                    a->channels() == 1 ? 2.0 : 5.0);
          EXPECT_GT(cv::norm(*a, *b, cv::NORM_INF), 0.0); // lossy: not the raw bag again
        }
      }
    }
  }
  options.images = "webp";
  EXPECT_EQ(errorOf([&] { msf::writeKittiBag(sequence, frames, dir.file("webp.bag"), options); }),
            "the bag's images must be raw, png or jpeg, not 'webp'");
  EXPECT_FALSE(msf::test::fileExists(dir.file("webp.bag")));
}

std::string readBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

/// The vertices of a mesh file.
std::vector<Eigen::Vector3f> vertices(const pcl::PolygonMesh& mesh) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  pcl::fromPCLPointCloud2(mesh.cloud, cloud);
  std::vector<Eigen::Vector3f> points;
  for (const auto& p : cloud)
    points.push_back(p.getVector3fMap());
  return points;
}

TEST(KittiBag, MsfReconstructOfTheBagMakesTheKittiFoldersMesh) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string sequence = msf::test::kittiDir() + "/odometry/sequences/04";
  const std::string bag = dir.file("04.bag");
  auto r = msf::test::runTool("msf_kitti2bag", "'" + sequence + "' -frames 0:4 -o '" + bag + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = msf::test::runTool("msf_kitti2bag", "'" + sequence + "' -o '" + bag + "'");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_TRUE(contains(r.err, "msf_kitti2bag: error: output '" + bag + "' exists; give -overwrite")) << r.err;

  r = msf::test::runTool("msf_reconstruct", "'" + bag + "' -panels 0 -o '" + dir.file("bag") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(contains(r.out, "poses: the dataset's: tf from 'camera_init' to 'camera_gray_left'")) << r.out;
  r = msf::test::runTool("msf_reconstruct", "'" + sequence + "' -frames 0:4 -panels 0 -o '" + dir.file("kitti") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  pcl::PolygonMesh from_bag, from_kitti;
  msf::loadMesh(dir.file("bag/mesh.ply"), from_bag);
  msf::loadMesh(dir.file("kitti/mesh.ply"), from_kitti);
  // The same surface, not the same bytes: tf carries rotations as quaternions, which move
  // KITTI's poses and extrinsic (orthonormal to ~1e-7 only) by ~1e-7; a LiDAR return then
  // lands in the next pixel now and then, and the depth and mesh change around it.
  const std::size_t n_bag = from_bag.polygons.size(), n_kitti = from_kitti.polygons.size();
  EXPECT_NEAR(static_cast<double>(n_bag), static_cast<double>(n_kitti), 1e-3 * static_cast<double>(n_kitti));
  const msf::MeshAccuracy a = msf::evaluateMesh(from_bag, from_kitti, vertices(from_kitti), 1e-3, 1.0, 1u << 30);
  EXPECT_GT(a.precision, 0.99) << "bag vertices within 1 mm of the KITTI mesh";
  EXPECT_GT(a.completeness, 0.99) << "KITTI vertices within 1 mm of the bag's mesh";
  EXPECT_EQ(a.accuracy_median_m, 0.0);
  std::printf("bag: %zu triangles, KITTI folder: %zu; bag vertices within 1 mm of the KITTI mesh %.5f, KITTI "
              "vertices within 1 mm of the bag's %.5f, mean distance %.2e m\n",
              n_bag, n_kitti, a.precision, a.completeness, a.accuracy_mean_m);

  // With KITTI's own extrinsic and poses (-rig, -poses), the bag's frames make the folder's
  // mesh byte for byte: scans, images, stamps and P came back exact.
  r = msf::test::runTool("msf_reconstruct", "'" + bag + "' -rig '" + sequence + "/calib.txt' -poses '" +
                                                msf::test::kittiDir() + "/odometry/poses/04.txt' -panels 0 -o '" +
                                                dir.file("bag_kitti_poses") + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(readBytes(dir.file("bag_kitti_poses/mesh.ply")), readBytes(dir.file("kitti/mesh.ply")));
  EXPECT_EQ(readBytes(dir.file("bag_kitti_poses/volume.pcd")), readBytes(dir.file("kitti/volume.pcd")));

  // Bag options with a folder, and a topic the bag lacks: errors that name them.
  r = msf::test::runTool("msf_reconstruct", "'" + sequence + "' -lidar_topic /points -o '" + dir.file("x") + "'");
  EXPECT_TRUE(contains(r.err, "bag topics and frames are for a ROS bag")) << r.err;
  r = msf::test::runTool("msf_reconstruct", "'" + bag + "' -lidar_topic /points -o '" + dir.file("x") + "'");
  EXPECT_TRUE(contains(r.err, "has no topic '/points' where the LiDAR's scans")) << r.err;
  EXPECT_FALSE(msf::test::fileExists(dir.file("x")));
}

} // namespace
