// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A user's own recording: the generic folder layout (FolderSource) read as the KITTI reader
// reads the same frames, in every scan and image format, with frames matched to their lines
// by number.
#include <msf/common/exceptions.h>
#include <msf/datasets/open_dataset.h>
#include <msf/io/folder_source.h>
#include <msf/io/image_io.h>
#include <msf/io/scan_file.h>
#include <msf/io/sequence.h>
#include <msf/io/tum_poses.h>

#include "pipeline_fixture.h"
#include "test_support.h"

#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <pcl/io/pcd_io.h>

#include <cmath>
#include <filesystem>
#include <fstream>

namespace {

namespace fs = std::filesystem;

/// `dataset`'s frames `range` in the generic layout, by msf_convert.
std::string converted(const std::string& dataset, const std::string& range, const msf::test::TempDir& dir) {
  const std::string out = dir.file("generic");
  const auto r = msf::test::runTool("msf_convert", dataset + " " + out + " -frames " + range);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  return out;
}

void expectSameScan(const pcl::PointCloud<pcl::PointXYZI>& a, const pcl::PointCloud<pcl::PointXYZI>& b) {
  EXPECT_EQ(a.header.frame_id, b.header.frame_id);
  EXPECT_EQ(a.header.stamp, b.header.stamp);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t k = 0; k < a.size(); ++k)
    ASSERT_TRUE(a[k].getVector4fMap() == b[k].getVector4fMap() && a[k].intensity == b[k].intensity) << "point " << k;
}

void expectSameFrame(const msf::Frame& a, const msf::Frame& b) {
  expectSameScan(*a.scan, *b.scan);
  EXPECT_EQ(cv::norm(a.left, b.left, cv::NORM_INF), 0.0);
  EXPECT_EQ(cv::norm(a.right, b.right, cv::NORM_INF), 0.0);
  EXPECT_EQ(a.color.empty(), b.color.empty());
  if (!a.color.empty()) {
    EXPECT_EQ(cv::norm(a.color, b.color, cv::NORM_INF), 0.0);
  }
  EXPECT_EQ(a.has_pose, b.has_pose);
  EXPECT_TRUE(a.T_world_cam0.isApprox(b.T_world_cam0, 1e-9));
  EXPECT_NEAR(a.timestamp, b.timestamp, 1e-9);
}

} // namespace

TEST(FolderSource, KittiConvertedToTheGenericLayoutGivesTheSameMesh) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string kitti = msf::test::kittiDir() + "/odometry/sequences/04";
  const std::string generic = converted(kitti, "0:2", dir);
  const msf::Sequence sequence(kitti);
  const msf::FolderSource folder(generic);
  ASSERT_EQ(folder.size(), 3u);
  EXPECT_EQ(folder.calibration().image_size, sequence.calibration().image_size);
  for (int i = 0; i < 4; ++i)
    EXPECT_EQ(folder.calibration().P[i], sequence.calibration().P[i]) << "P" << i;
  for (std::size_t i = 0; i < 3; ++i) {
    const msf::Frame frame = sequence.load(i);
    expectSameFrame(folder.load(i), frame);
    // The scan alone (the memory prediction's read) is the frame's scan.
    expectSameScan(*folder.loadScan(i), *frame.scan);
    expectSameScan(*sequence.loadScan(i), *frame.scan);
  }
  EXPECT_THROW(folder.loadScan(3), msf::InvalidInputError);
  EXPECT_THROW(sequence.loadScan(10), msf::InvalidInputError);
  for (const msf::FrameSource* source : std::initializer_list<const msf::FrameSource*>{&sequence, &folder}) {
    EXPECT_THROW(source->frameName(10), msf::InvalidInputError); // a library error, not std::out_of_range
    EXPECT_THROW(source->timestamp(10), msf::InvalidInputError);
    EXPECT_THROW(source->scanName(10), msf::InvalidInputError);
  }
  for (const auto& [name, input] : {std::pair<std::string, std::string>{"kitti_run", kitti + " -frames 0:2"},
                                    {"generic_run", generic}}) {
    const auto r = msf::test::runTool("msf_reconstruct", input + " -panels 0 -o " + dir.file(name));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_TRUE(readFile(dir.file("kitti_run/mesh.ply")) == readFile(dir.file("generic_run/mesh.ply")));
  EXPECT_TRUE(readFile(dir.file("kitti_run/volume.pcd")) == readFile(dir.file("generic_run/volume.pcd")));
}

TEST(FolderSource, TheOdometryToolsReadItAsTheyReadKitti) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string kitti = msf::test::kittiDir() + "/odometry/sequences/04";
  const std::string generic = converted(kitti, "0:3", dir);
  for (const auto& [name, input] : {std::pair<std::string, std::string>{"kitti.txt", kitti + " -frames 0:3"},
                                    {"generic.txt", generic}}) {
    const auto r = msf::test::runTool("msf_odometry", input + " -o " + dir.file(name));
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  EXPECT_TRUE(readFile(dir.file("kitti.txt")) == readFile(dir.file("generic.txt")));
  const auto scored = msf::test::runTool("msf_eval_odometry", dir.file("generic.txt") + " " + generic);
  ASSERT_EQ(scored.exit_code, 0) << scored.err;
  EXPECT_NE(scored.out.find("ATE"), std::string::npos) << scored.out;
  // The KITTI reader names the layout and who reads it, rather than listing it as its own.
  const std::string error = msf::test::errorOf([&] { msf::Sequence{generic}; });
  EXPECT_NE(error.find("is a folder of your own rig's layout (left/, right/, lidar/): msf_reconstruct, msf_odometry"),
            std::string::npos) << error;
}

TEST(FolderSource, ACalibrationWithoutAnImageSizeTakesTheImagesOwn) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string kitti = msf::test::kittiDir() + "/odometry/sequences/04";
  const std::string generic = converted(kitti, "0:0", dir);
  fs::create_directory(dir.file("calib"));
  fs::copy_file(kitti + "/calib.txt", dir.file("calib/calib.txt")); // no image_0/ beside it: no size
  EXPECT_EQ(msf::loadCalibration(dir.file("calib/calib.txt")).image_size, cv::Size(0, 0));
  const msf::FolderSource folder(generic, dir.file("calib/calib.txt"));
  EXPECT_EQ(folder.calibration().image_size, msf::Sequence(kitti).calibration().image_size);
  // Names that are not frame numbers (a ROS export's nanoseconds): what names the reader takes.
  for (const char* side : {"left", "right"})
    fs::rename(generic + "/" + side + "/000000.png", generic + "/" + side + "/1700000000000000000.png");
  const std::string error = msf::test::errorOf([&] { msf::FolderSource{generic}; });
  EXPECT_NE(error.find("no PNG or JPEG image in left/ named by a frame number of up to 18 digits"), std::string::npos)
      << error;
}

TEST_F(PipelineTest, EveryScanAndImageFormatReadsTheSameFrame) {
  msf::test::TempDir dir;
  const std::string generic = converted(dataset(), "0:0", dir);
  const msf::Frame reference = msf::FolderSource(generic).load(0);
  const fs::path g(generic);
  // The scan as an ASCII .pcd of doubles with ring and time fields, then as a binary .ply.
  const pcl::PointCloud<pcl::PointXYZI>& points = *reference.scan;
  {
    std::ofstream pcd(g / "lidar" / "000000.pcd.new");
    pcd << "VERSION 0.7\nFIELDS x y z intensity ring time\nSIZE 8 8 8 4 2 4\nTYPE F F F F U F\nCOUNT 1 1 1 1 1 1\n"
        << "WIDTH " << points.size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << points.size()
        << "\nDATA ascii\n";
    pcd.precision(9);
    for (std::size_t k = 0; k < points.size(); ++k)
      pcd << points[k].x << ' ' << points[k].y << ' ' << points[k].z << ' ' << points[k].intensity << ' ' << k % 32
          << ' ' << 1e-5 * static_cast<double>(k) << '\n';
  }
  fs::remove(g / "lidar" / "000000.bin");
  fs::rename(g / "lidar" / "000000.pcd.new", g / "lidar" / "000000.pcd");
  // The left image as 16 bits (a 16-bit camera), the right as colour with equal channels, and a
  // colour JPEG of the left camera as camera 2.
  cv::Mat wide, bgr;
  reference.left.convertTo(wide, CV_16U, 257.0);
  cv::imwrite((g / "left" / "000000.png").string(), wide);
  cv::cvtColor(reference.right, bgr, cv::COLOR_GRAY2BGR);
  cv::imwrite((g / "right" / "000000.png").string(), bgr);
  fs::remove_all(g / "color");
  fs::create_directory(g / "color");
  cv::imwrite((g / "color" / "000000.jpg").string(), reference.color);
  // Files that are not frames are no matter.
  std::ofstream(g / "left" / ".DS_Store") << "x";
  std::ofstream(g / "lidar" / "README.txt") << "scans";

  const msf::Frame frame = msf::FolderSource(generic).load(0);
  ASSERT_EQ(frame.scan->size(), points.size());
  for (std::size_t k = 0; k < points.size(); k += 97)
    EXPECT_TRUE(frame.scan->at(k).getVector3fMap().isApprox(points[k].getVector3fMap(), 1e-6f)) << k;
  ASSERT_EQ(frame.point_ring.size(), points.size());
  EXPECT_EQ(frame.point_ring[33], 1);
  ASSERT_EQ(frame.point_time_s.size(), points.size());
  EXPECT_NEAR(frame.point_time_s[1000], 0.01, 1e-7);
  EXPECT_EQ(cv::norm(frame.left, reference.left, cv::NORM_INF), 0.0);  // 16 bits scaled back exactly
  EXPECT_EQ(cv::norm(frame.right, reference.right, cv::NORM_INF), 0.0); // colour to grey
  EXPECT_LT(cv::norm(frame.color, reference.color, cv::NORM_L1) / static_cast<double>(frame.color.total() * 3), 3.0);
}

/// A rig file without the LiDAR's beams, and scans with a ring field: the beams are the rings'.
TEST_F(PipelineTest, ARigWithoutBeamsTakesThemFromTheScansRings) {
  msf::test::TempDir dir;
  const std::string generic = converted(dataset(), "0:0", dir);
  const fs::path g(generic);
  const std::vector<double> street_beams = msf::FolderSource(generic).calibration().lidar.beam_elevations_deg;
  ASSERT_EQ(street_beams.size(), 64u) << "the street's HDL-64E, as msf_convert wrote its rig";
  { // the rig file without its beams
    std::ifstream in(g / "rig.yaml");
    std::string text, line;
    while (std::getline(in, line))
      if (line.find("beam_elevations_deg") == std::string::npos && line.find("rings:") == std::string::npos)
        text += line + "\n";
    in.close();
    std::ofstream(g / "rig.yaml") << text;
  }
  EXPECT_TRUE(msf::FolderSource(generic).calibration().lidar.beam_elevations_deg.empty())
      << "KITTI's .bin scans have no rings";
  // Each return's ring is its beam's, as a driver numbers them.
  const msf::Frame frame = msf::FolderSource(generic).load(0);
  std::ofstream pcd(g / "lidar" / "000000.pcd");
  pcd << "VERSION 0.7\nFIELDS x y z intensity ring\nSIZE 4 4 4 4 2\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH "
      << frame.scan->size() << "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " << frame.scan->size() << "\nDATA ascii\n";
  pcd.precision(9);
  for (const auto& p : *frame.scan) {
    const double elevation = std::atan2(p.z, std::hypot(p.x, p.y)) * 180.0 / M_PI;
    std::size_t ring = 0;
    for (std::size_t b = 1; b < street_beams.size(); ++b)
      if (std::abs(street_beams[b] - elevation) < std::abs(street_beams[ring] - elevation))
        ring = b;
    pcd << p.x << ' ' << p.y << ' ' << p.z << ' ' << p.intensity << ' ' << ring << '\n';
  }
  pcd.close();
  fs::remove(g / "lidar" / "000000.bin");
  const msf::FolderSource source(generic);
  const std::vector<double>& beams = source.calibration().lidar.beam_elevations_deg;
  ASSERT_EQ(beams.size(), street_beams.size());
  for (std::size_t b = 0; b < beams.size(); ++b)
    EXPECT_NEAR(beams[b], street_beams[b], 1e-3) << b;
  ASSERT_EQ(source.notes().size(), 1u);
  EXPECT_NE(source.notes()[0].find("beams from the first scan's rings"), std::string::npos) << source.notes()[0];
}

TEST_F(PipelineTest, A16BitPairIsScaledAlikeSoItsImagesMatchAtOneGain) {
  msf::test::TempDir dir;
  const std::string generic = converted(dataset(), "0:0", dir);
  const fs::path g(generic);
  // One 12-bit picture for both cameras; the right one has a single pixel that needs 13 bits.
  const cv::Mat picture = msf::FolderSource(generic).load(0).left;
  cv::Mat left, right;
  picture.convertTo(left, CV_16U, 4095.0 / 255.0);
  right = left.clone();
  right.at<std::uint16_t>(0, 0) = 5000;
  cv::imwrite((g / "left" / "000000.png").string(), left);
  cv::imwrite((g / "right" / "000000.png").string(), right);
  const msf::Frame frame = msf::FolderSource(generic).load(0);
  cv::Mat differs;
  cv::compare(frame.left, frame.right, differs, cv::CMP_NE);
  EXPECT_EQ(cv::countNonZero(differs), 1) << "the pair scaled at two gains"; // pixel (0, 0) alone
  double brightest = 0, brightest_12_bit = 0;
  cv::minMaxLoc(frame.left, nullptr, &brightest);
  cv::minMaxLoc(left, nullptr, &brightest_12_bit);
  EXPECT_NEAR(brightest, brightest_12_bit * 255.0 / 8191.0, 0.5); // 13 bits for both
}

TEST_F(PipelineTest, FramesTakeTheirLinesByNumberAndPosesInEitherFormat) {
  msf::test::TempDir dir;
  const std::string generic = converted(dataset(), "0:3", dir);
  const fs::path g(generic);
  const msf::FolderSource whole(generic);
  // Frame 000002 removed: frame 000003 keeps line 3 of the times and the poses.
  for (const char* folder : {"lidar", "left", "right", "color"})
    for (const auto& e : fs::directory_iterator(g / folder))
      if (e.path().stem() == "000002")
        fs::remove(e.path());
  const msf::FolderSource gap(generic);
  ASSERT_EQ(gap.size(), 3u);
  EXPECT_EQ(gap.frameName(2), "000003");
  EXPECT_TRUE(gap.poses()[2].isApprox(whole.poses()[3]));
  EXPECT_NEAR(gap.load(2).timestamp, whole.load(3).timestamp, 1e-9);
  // The same poses in TUM's format, matched by time.
  msf::StampedPoses tum;
  std::ifstream times(g / "timestamps.txt");
  for (double t; times >> t;)
    tum.timestamps.push_back(t);
  tum.poses = whole.poses();
  fs::remove(g / "poses.txt");
  msf::saveTumPoses((g / "poses.txt").string(), tum);
  const msf::FolderSource timed(generic);
  for (std::size_t i = 0; i < timed.size(); ++i)
    EXPECT_TRUE(timed.poses()[i].isApprox(gap.poses()[i], 1e-9)) << i;
  // A frame without its right image is named, and a scan without a left image too.
  fs::remove(g / "right" / "000001.png");
  EXPECT_NE(msf::test::errorOf([&] { msf::FolderSource{generic}; }).find("frame 000001 has no file in right/"),
            std::string::npos);
  std::ofstream(g / "right" / "000001.png") << "x";
  fs::copy_file(g / "lidar" / "000000.bin", g / "lidar" / "000009.bin");
  EXPECT_NE(msf::test::errorOf([&] { msf::FolderSource{generic}; }).find("000009.bin' has no left image"),
            std::string::npos);
  fs::remove(g / "lidar" / "000009.bin");
  // Without a rig file, the error says what to write or give.
  fs::rename(g / "rig.yaml", g / "my_rig.yaml");
  EXPECT_NE(msf::test::errorOf([&] { msf::openDataset(generic); }).find("has no rig.yaml"), std::string::npos);
  msf::DatasetOptions with_rig;
  with_rig.rig = (g / "my_rig.yaml").string();
  EXPECT_EQ(msf::openDataset(generic, with_rig)->size(), 3u);
}
