// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Files whose headers, values or shapes are hostile end in an error naming the
// file and what is wrong, before anything large is allocated.
#include <msf/common/exceptions.h>
#include <msf/io/calibration.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/poses.h>
#include <msf/io/sequence.h>

#include "test_support.h"

#include <opencv2/core.hpp>
#include <pcl/point_types.h>

#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <regex>
#include <sstream>

namespace fs = std::filesystem;

namespace {

using msf::test::errorOf;

void write(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

std::string pcdHeader(const std::string& points, const std::string& data) {
  return "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH " + points +
         "\nHEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS " + points + "\nDATA " + data + "\n";
}

TEST(HostileClouds, PointCountBeyondTheFileSizeIsAnErrorNotAnAllocation) {
  msf::test::TempDir dir;
  for (const char* data : {"binary", "ascii", "binary_compressed"}) {
    write(dir.file("bomb.pcd"), pcdHeader("1000000000", data) + std::string(1300, '\0'));
    pcl::PCLPointCloud2 blob;
    const std::string e = errorOf([&] { msf::loadCloudBlob(dir.file("bomb.pcd"), blob); });
    EXPECT_NE(e.find("bomb.pcd' declares 1000000000 points"), std::string::npos) << data << ": " << e;
  }
  write(dir.file("bomb.ply"), "ply\nformat binary_little_endian 1.0\nelement vertex 1000000000\nproperty float x\n"
                              "property float y\nproperty float z\nend_header\n" + std::string(1300, '\0'));
  pcl::PCLPointCloud2 blob;
  EXPECT_NE(errorOf([&] { msf::loadCloudBlob(dir.file("bomb.ply"), blob); }).find("declares 1000000000 vertex"),
            std::string::npos);
  pcl::PolygonMesh mesh;
  EXPECT_NE(errorOf([&] { msf::loadMesh(dir.file("bomb.ply"), mesh); }).find("declares 1000000000 vertex"),
            std::string::npos);
}

TEST(HostileClouds, ValidFilesStillLoad) {
  msf::test::TempDir dir;
  pcl::PointCloud<pcl::PointXYZ> cloud;
  for (int i = 0; i < 50; ++i)
    cloud.push_back(pcl::PointXYZ(float(i), 1.f, 2.f));
  msf::saveCloud(dir.file("c.pcd"), cloud); // binary compressed
  msf::saveCloud(dir.file("c.ply"), cloud);
  write(dir.file("a.pcd"), pcdHeader("2", "ascii") + "1 2 3\nnan nan nan\n");
  for (const char* name : {"c.pcd", "c.ply", "a.pcd"}) {
    pcl::PointCloud<pcl::PointXYZ> back;
    EXPECT_NO_THROW(msf::loadCloud(dir.file(name), back)) << name;
  }
}

TEST(HostileClouds, HeaderThatPclWouldReadOtherwiseIsRefusedBeforeItAllocates) {
  // PCL's readHeader matches keywords as prefixes, reads on after DATA and sizes the data at
  // POINTS (DATA or not): each of these made it allocate POINTS x the point step.
  msf::test::TempDir dir;
  const std::string fields = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n";
  const std::pair<std::string, std::string> cases[] = {
      {fields + "WIDTH 1000000000\nHEIGHT 1\nPOINTS 1000000000\n", "(bad header): no DATA line"},
      {"FIELDS x y z\nSIZE` 8 8 8\nPOINTS 1000000000\nDATA binary\n" + std::string(100, '\0'),
       "line 2 'SIZE` 8 8 8': not a header keyword"},
      {pcdHeader("1", "ascii") + "POINTS 1000000000\n1 2 3\n",
       "a line after DATA starts with 'POINTS 1000000000', which PCL would read as a header line"},
      {pcdHeader("1", "binary") + "\n# comment\n\f HEIGHT 99\n" + std::string(12, '\0'),
       "a line after DATA starts with 'HEIGHT 99'"},
      {fields + "FIELDS a b c d e f g\nPOINTS 1\nDATA ascii\n1 2 3\n", "line 6 'FIELDS a b c d e f g': FIELDS given twice"},
      {fields + "POINTS 1e9\nDATA ascii\n", "'1e9' is not a whole number 0 .. 2147483647"},
      {"FIELDS x y\nSIZE 4 4\nTYPE F F\nCOUNT 1 3000000\nPOINTS 1\nDATA ascii\n1 2\n",
       "count '3000000' is not a whole number 0 .. 1048576"},
      {"FIELDS x y\nSIZE 4 4 4\nPOINTS 1\nDATA ascii\n1 2\n", "3 values for 2 fields"},
      {"FIELDS x y\nSIZE 4 1\nPOINTS 1\nDATA binary\n12345", "DATA before TYPE"},
      {"FIELDS x y\nSIZE 4 2\nTYPE F F\nPOINTS 1\nDATA binary\n123456", "field 2 is F of size 2 (4 or 8)"},
  };
  for (const auto& [text, expected] : cases) {
    write(dir.file("h.pcd"), text);
    pcl::PCLPointCloud2 blob;
    const std::string e = errorOf([&] { msf::loadCloudBlob(dir.file("h.pcd"), blob); });
    EXPECT_NE(e.find(expected), std::string::npos) << text << "\n -> " << e;
  }
}

TEST(HostileClouds, AsciiValueThatIsNotANumberIsNamed) {
  msf::test::TempDir dir;
  write(dir.file("abc.pcd"), pcdHeader("2", "ascii") + "1 2 3\n1 2 abc\n");
  pcl::PointCloud<pcl::PointXYZ> cloud;
  EXPECT_NE(errorOf([&] { msf::loadCloud(dir.file("abc.pcd"), cloud); }).find("value 'abc' on data line 2"),
            std::string::npos);
}

TEST(HostileImages, HugePngHeaderIsRefusedBeforeDecoding) {
  msf::test::TempDir dir;
  // The signature and an IHDR of 30000 x 20000 (CRC not checked before the size).
  std::string png("\x89PNG\r\n\x1a\n\0\0\0\x0dIHDR\0\0\x75\x30\0\0\x4e\x20\x08\0\0\0\0\0\0\0\0", 33);
  write(dir.file("huge.png"), png);
  EXPECT_NE(errorOf([&] { msf::readImage(dir.file("huge.png")); }).find("image size 30000x20000 is outside"),
            std::string::npos);
}

TEST(HostileImages, HugeDepthSaturatesInsteadOfWrapping) {
  msf::test::TempDir dir;
  cv::Mat d(1, 2, CV_32FC1);
  d.at<float>(0, 0) = 1e30f; // lround(1e30 * 256) overflowed: written as 0.004 m
  d.at<float>(0, 1) = std::numeric_limits<float>::max();
  msf::writeKittiDepthPng(dir.file("d.png"), d);
  const cv::Mat back = msf::readKittiDepthPng(dir.file("d.png"));
  EXPECT_NEAR(back.at<float>(0, 0), 65535.0 / 256, 1e-4);
  EXPECT_NEAR(back.at<float>(0, 1), 65535.0 / 256, 1e-4);
}

class HostileCalibration : public ::testing::Test {
protected:
  msf::test::TempDir dir;
  msf::Calibration good;
  void SetUp() override {
    good.image_size = cv::Size(64, 48);
    for (auto& P : good.P)
      P << 60, 0, 32, 0, 0, 60, 24, 0, 0, 0, 1, 0;
    good.P[1](0, 3) = -30;
  }
  std::string errorLoading(const msf::Calibration& c) {
    msf::saveCalibrationYaml(c, dir.file("c.yaml"));
    return errorOf([&] { msf::loadCalibration(dir.file("c.yaml")); });
  }
};

TEST_F(HostileCalibration, PhysicalCalibrationLoads) { EXPECT_EQ(errorLoading(good), "(no error)"); }

TEST_F(HostileCalibration, FocalLengthZeroOrNaN) {
  msf::Calibration c = good;
  c.P[0](0, 0) = 0;
  EXPECT_NE(errorLoading(c).find("P0 has fx 0"), std::string::npos);
  c = good;
  c.P[2](1, 2) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(errorLoading(c).find("P2 has a value that is not finite"), std::string::npos);
}

TEST_F(HostileCalibration, ImageSizeBeyondTheLimit) {
  msf::Calibration c = good;
  c.image_size = cv::Size(100000, 100000);
  EXPECT_NE(errorLoading(c).find("image size 100000x100000 is outside"), std::string::npos);
}

TEST_F(HostileCalibration, ExtrinsicsThatAreNotRigid) {
  msf::Calibration c = good;
  c.T_cam0_velo.linear() *= 1000.0;
  EXPECT_NE(errorLoading(c).find("LiDAR-to-camera transform is not a rigid transform"), std::string::npos);
}

TEST_F(HostileCalibration, ZeroBaselineIsAnErrorWhereItIsUsed) {
  msf::Calibration c = good;
  c.P[1](0, 3) = 0;
  EXPECT_EQ(errorLoading(c), "(no error)"); // a mono calibration is fine...
  c.source = "mono";
  EXPECT_NE(errorOf([&] { c.focalBaseline(); }).find("'mono': the grey pair's focal length x baseline is 0"),
            std::string::npos); // ...until a disparity needs it
}

TEST_F(HostileCalibration, ASwappedOrImplausibleStereoPairIsAnErrorWhereItIsUsed) {
  const auto stereoError = [&](double p1_tx, double p1_fx = 60, double p1_ty = 0) {
    msf::Calibration c = good;
    c.P[1](0, 3) = p1_tx;
    c.P[1](0, 0) = p1_fx;
    c.P[1](1, 3) = p1_ty;
    EXPECT_EQ(errorLoading(c), "(no error)"); // what projects a scan needs is there
    c.source = "rig";
    return errorOf([&] { c.focalBaseline(); });
  };
  EXPECT_EQ(stereoError(-30), "(no error)");
  // Swapped images: the right camera's centre left of the left one's.
  EXPECT_NE(stereoError(30).find("'rig': camera 1 is 0.5 m left of camera 0 (P1's fourth value 30 is positive"),
            std::string::npos);
  // A baseline of a nanometre or of 990 km (within the translation limit) is a unit or digit slip.
  EXPECT_NE(stereoError(-60e-9).find("'rig': the grey pair's baseline is 1e-09 m, outside 0.001 .. 10 m"),
            std::string::npos);
  EXPECT_NE(stereoError(-60 * 990e3).find("the grey pair's baseline is 990000 m, outside 0.001 .. 10 m"),
            std::string::npos);
  // A rectified pair shares its intrinsics and differs along x only.
  EXPECT_NE(stereoError(-30, 61).find("'rig': P1's fx 61 is not P0's 60"), std::string::npos);
  EXPECT_NE(stereoError(-30, 60, 3).find("P1 is shifted up, down or along the axis from P0"), std::string::npos);
}

TEST_F(HostileCalibration, AKeyGivenTwiceIsAnError) {
  // The last P0 won: which one the user meant is unknown.
  write(dir.file("calib.txt"), "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 600 -380 0 700 180 0 0 0 1 0\n"
                               "P2: 700 0 600 0 0 700 180 0 0 0 1 0\nP3: 700 0 600 0 0 700 180 0 0 0 1 0\n"
                               "P0: 710 0 600 0 0 710 180 0 0 0 1 0\nTr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_EQ(errorOf([&] { msf::loadCalibration(dir.file("calib.txt")); }),
            "calibration '" + dir.file("calib.txt") + "': key 'P0' is given twice, on lines 1 and 5");
}

TEST_F(HostileCalibration, AYamlMatrixOfAnIntegerTypeIsRefused) {
  // dt u: OpenCV clipped 707.09 to 255 and -379.8 to 0.
  msf::saveCalibrationYaml(good, dir.file("c.yaml"));
  std::ifstream in(dir.file("c.yaml"));
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  yaml.replace(yaml.find("dt: d"), 5, "dt: u");
  write(dir.file("u.yaml"), yaml);
  EXPECT_NE(errorOf([&] { msf::loadCalibration(dir.file("u.yaml")); })
                .find("u.yaml': key 'P0' has dt 'u', not d (float64) or f (float32)"),
            std::string::npos);
}

TEST_F(HostileCalibration, ValueThatIsNotANumberIsNamed) {
  write(dir.file("calib.txt"), "P0: 700 0 600 0 0 700 180 0 0 0 1 0\nP1: 700 0 1.0x -380 0 700 180 0 0 0 1 0\n"
                               "P2: 700 0 600 0 0 700 180 0 0 0 1 0\nP3: 700 0 600 0 0 700 180 0 0 0 1 0\n"
                               "Tr: 1 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] { msf::loadCalibration(dir.file("calib.txt")); })
                .find("key 'P1' has a value that is not a number: '1.0x'"),
            std::string::npos);
}

TEST(HostilePoses, NanAndTextAreNamedNotMiscounted) {
  msf::test::TempDir dir;
  write(dir.file("nan.txt"), "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 nan 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] { msf::loadOdometryPoses(dir.file("nan.txt")); }).find("line 2: value 4 'nan' is not finite"),
            std::string::npos);
  write(dir.file("x.txt"), "1 0 0 0 0 1 0 0 0 0 1 0x\n");
  EXPECT_NE(errorOf([&] { msf::loadOdometryPoses(dir.file("x.txt")); }).find("value 12 '0x' is not a number"),
            std::string::npos);
}

TEST(HostilePoses, AHeaderCommentIsSkippedAndTheLinesKeepTheirNumbers) {
  msf::test::TempDir dir;
  write(dir.file("p.txt"), "# T_world_cam0, KITTI's 12 numbers\n1 0 0 0 0 1 0 0 0 0 1 0\n  # moved\n1 0 0 2 0 1 0 0 0 0 1 0\n"
                           "1 0 0 x 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] { msf::loadOdometryPoses(dir.file("p.txt")); }).find("line 5: value 4 'x' is not a number"),
            std::string::npos);
  write(dir.file("p.txt"), "# T_world_cam0\n1 0 0 0 0 1 0 0 0 0 1 0\n  # moved\n1 0 0 2 0 1 0 0 0 0 1 0\n");
  const msf::PoseList poses = msf::loadOdometryPoses(dir.file("p.txt"));
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[1].translation().x(), 2.0);
}

TEST(HostilePoses, RotationThatIsNotARotation) {
  msf::test::TempDir dir;
  write(dir.file("p.txt"), "1000 0 0 0 0 1000 0 0 0 0 1000 0\n");
  EXPECT_NE(errorOf([&] { msf::loadOdometryPoses(dir.file("p.txt")); }).find("line 1 is not a rigid transform"),
            std::string::npos);
  write(dir.file("far.txt"), "1 0 0 1e30 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(errorOf([&] { msf::loadOdometryPoses(dir.file("far.txt")); }).find("translation of 1e+30 m"),
            std::string::npos);
}

/// A copy of odometry 04 (links) with `frames` images a camera and `scans` scans.
std::string smallDataset(const msf::test::TempDir& dir, int frames, int scans) {
  const fs::path seq = fs::path(msf::test::kittiDir()) / "odometry/sequences/04";
  const fs::path d = fs::path(dir.path()) / "sequences/04";
  for (const char* sub : {"image_0", "image_1", "velodyne"})
    fs::create_directories(d / sub);
  fs::create_directories(fs::path(dir.path()) / "poses");
  fs::create_symlink(seq / "calib.txt", d / "calib.txt");
  char name[16];
  for (int i = 0; i < frames; ++i) {
    std::snprintf(name, sizeof name, "%06d.png", i);
    fs::create_symlink(seq / "image_0" / name, d / "image_0" / name);
    fs::create_symlink(seq / "image_1" / name, d / "image_1" / name);
  }
  for (int i = 0; i < scans; ++i) {
    std::snprintf(name, sizeof name, "%06d.bin", i);
    fs::create_symlink(seq / "velodyne" / name, d / "velodyne" / name);
  }
  return d.string();
}

TEST(HostileSequence, MoreScansThanImagesIsAnError) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string d = smallDataset(dir, 3, 4);
  EXPECT_NE(errorOf([&] { msf::Sequence s(d); }).find("has 3 images in camera 0's folder but 4 .bin files"),
            std::string::npos);
}

TEST(HostileSequence, FrameRangeBeyondTheEndIsAnError) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const msf::Sequence s(smallDataset(dir, 3, 3));
  EXPECT_EQ(s.indices(msf::FrameRange::parse("0:2")).size(), 3u);
  EXPECT_NE(errorOf([&] { s.indices(msf::FrameRange::parse("0:100000")); }).find("goes beyond the last frame"),
            std::string::npos);
}

TEST(HostileSequence, WrongSizeRightImageIsNamedWithItsOwnSize) {
  MSF_REQUIRE_KITTI();
  msf::test::TempDir dir;
  const std::string d = smallDataset(dir, 2, 2);
  fs::remove(fs::path(d) / "image_1/000000.png");
  msf::writeImage((fs::path(d) / "image_1/000000.png").string(), cv::Mat(6, 8, CV_8UC1, cv::Scalar(9)));
  const msf::Sequence s(d);
  const std::string e = errorOf([&] { s.load(0, false); });
  EXPECT_NE(e.find("image_1/000000.png' is 8x6, not the calibration's 1226x370"), std::string::npos) << e;
}

/// The inputs fuzz/ found crashes with (tests/io/fuzz_regressions/<target>/), read as the
/// fuzz target reads them: the first byte picks the format. Each must load or end in an
/// msf::Error; any other exception (PCL's std::out_of_range, OpenCV's cv::Exception) fails.
std::vector<fs::path> regressions(const std::string& target) {
  std::vector<fs::path> files;
  for (const auto& e : fs::directory_iterator(fs::path(msf::test::sourceDir()) / "tests/io/fuzz_regressions" / target))
    files.push_back(e.path());
  return files;
}

std::string bodyOf(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return bytes;
}

TEST(FuzzRegressions, CloudReaders) {
  msf::test::TempDir dir;
  const auto files = regressions("cloud");
  ASSERT_FALSE(files.empty());
  for (const auto& f : files) {
    const std::string bytes = bodyOf(f);
    const std::string path = dir.file(bytes.at(0) & 1 ? "c.ply" : "c.pcd");
    write(path, bytes.substr(1));
    pcl::PointCloud<pcl::PointXYZI> cloud;
    try {
      msf::loadCloud(path, cloud);
    } catch (const msf::Error&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
}

/// The error loading tests/io/fuzz_regressions/cloud/<name> gives, read as fuzz_cloud reads
/// it (as c.pcd or c.ply).
std::string cloudFindingError(const std::string& name) {
  msf::test::TempDir dir;
  const std::string bytes = bodyOf(fs::path(msf::test::sourceDir()) / "tests/io/fuzz_regressions/cloud" / name);
  const std::string path = dir.file(bytes.at(0) & 1 ? "c.ply" : "c.pcd");
  write(path, bytes.substr(1));
  pcl::PointCloud<pcl::PointXYZI> cloud;
  return errorOf([&] { msf::loadCloud(path, cloud); });
}

TEST(FuzzRegressions, CloudHeaderOfFourGigabytesIsRefusedByItsOwnCheck) {
  // fuzz_cloud (make fuzz FUZZ_SECONDS=600, after ~2 min): a 1.2 KB .pcd whose header PCL
  // reads as 14444444 points of 284 bytes, allocated in readHeader (4.1 GB) before any check
  // of ours saw it.
  const std::string e = cloudFindingError("oom-12af5ddfa0561690bbe07b4073cc500b4bba8130");
  EXPECT_NE(e.find("c.pcd' is not a valid .pcd file (bad header): line "), std::string::npos) << e;
}

TEST(FuzzRegressions, CloudFieldsBeyondThePointAreRefused) {
  // fuzz_cloud (the 600 s run after the fix above, after ~15 s): SIZE 4 4 1 1 and no TYPE, so
  // PCL laid out four 4-byte floats in a 10-byte point and pcl::fromPCLPointCloud2 read past
  // the data (ASan: heap-buffer-overflow).
  const std::string e = cloudFindingError("crash-d9dc1c7e5b5b383059c75f3b64745c85cb4909d6");
  EXPECT_NE(e.find("c.pcd' is not a valid .pcd file (bad header): line 9 'DATA binary': DATA before TYPE"),
            std::string::npos)
      << e;
}

TEST(FuzzRegressions, APlyOfNoVertexLoadsAsAnEmptyCloud) {
  // fuzz_cloud (the third 600 s run, after ~4 min): a binary .ply with `element vertex 00`.
  // PCL's conversion bound a reference to the first point of the empty cloud (UBSan); the
  // loader now gives an empty cloud without converting. The finding itself has a damaged
  // property line (`property float inte<binary> z`) that the strict header check of the next
  // finding refuses; the same header without it loads as an empty cloud.
  EXPECT_NE(cloudFindingError("crash-9c6e2c26854529edb4fb60c3e495ecbd0c554cab")
                .find("c.ply' is not a valid .ply file (bad header): line 7 'property float inte"),
            std::string::npos);
  msf::test::TempDir dir;
  const std::string path = dir.file("c.ply");
  write(path, "ply\nformat binary_little_endian 1.0\nelement vertex 00\nproperty float x\nproperty float y\n"
              "property float z\nproperty float intensity\nend_header\n");
  pcl::PointCloud<pcl::PointXYZI> cloud;
  cloud.push_back(pcl::PointXYZI(1.f));
  EXPECT_EQ(errorOf([&] { msf::loadCloud(path, cloud); }), "(no error)");
  EXPECT_TRUE(cloud.empty());
  EXPECT_EQ(cloud.width * cloud.height, 0u);
}

TEST(FuzzRegressions, APlyHeaderLineStartingWithABlankIsRefusedBeforePclAssertsOnIt) {
  // fuzz_cloud: ' obj_info x' passed the header check (which split the line at blanks) and PCL's
  // PLYReader, which asserts that the line's first word is obj_info, aborted the program.
  EXPECT_NE(cloudFindingError("crash-7c247a34df5eacb31f4f9a6e61a64e328c9a51a2").find("c.ply' is not a valid .ply file (bad header): line 3 ' obj_info x': a line "
                                         "that starts with a blank"),
            std::string::npos);
}

TEST(FuzzRegressions, APlyElementCountThatIsNotAWholeNumberIsRefusedBeforePclSizesTheCloud) {
  // fuzz_cloud (the fourth 600 s run): a binary .ply with `element vertex -7`, which PCL's
  // parser reads into a std::size_t as 2^64 - 7 and sized the cloud from (~52 GB). Its second
  // line ("\x01ply") is no header keyword: PCL passed over it, the strict check refuses it.
  // Without that line, the count itself is refused (HostileClouds.PlyHeadersAreReadStrictly).
  const std::string e = cloudFindingError("crash-49553d3f70fb08fbec9f97d3a5cba192487efcc5");
  EXPECT_NE(e.find("c.ply' is not a valid .ply file (bad header): line 2 '?ply': not a header keyword (format, "
                   "element, property, comment, obj_info, end_header)"),
            std::string::npos)
      << e;
}

TEST(FuzzRegressions, ACompressedBodyWhoseSizesDisagreeWithTheHeaderIsRefused) {
  // fuzz_cloud (make fuzz FUZZ_SECONDS=600, the first run with a binary_compressed seed, after
  // ~6 min): a binary_compressed .pcd of 64 points of 8 bytes whose body says it unpacks to
  // 0 bytes. PCL resized the cloud to that size and copied 64 points out of an empty buffer
  // (SEGV in PCDReader::readBodyBinary).
  const std::string e = cloudFindingError("crash-4b835f08d95ba59075cbc02443a421dcdc87d7de");
  EXPECT_NE(e.find("c.pcd': its binary_compressed body says it unpacks to 0 bytes, but the header's 64 points "
                   "of 8 bytes make 512 (a damaged file)"),
            std::string::npos)
      << e;
  // The compressed size beyond the file, and a body shorter than the two sizes.
  msf::test::TempDir dir;
  const auto sizes = [](std::uint32_t compressed, std::uint32_t uncompressed) {
    std::string bytes(8, '\0');
    std::memcpy(&bytes[0], &compressed, 4);
    std::memcpy(&bytes[4], &uncompressed, 4);
    return bytes;
  };
  pcl::PCLPointCloud2 blob;
  write(dir.file("c.pcd"), pcdHeader("2", "binary_compressed") + sizes(1000, 24) + std::string(30, '\0'));
  EXPECT_NE(errorOf([&] { msf::loadCloudBlob(dir.file("c.pcd"), blob); })
                .find("says 1000 bytes of compressed data, but the file has 30 after the sizes"),
            std::string::npos);
  write(dir.file("c.pcd"), pcdHeader("2", "binary_compressed") + "abcd");
  EXPECT_NE(errorOf([&] { msf::loadCloudBlob(dir.file("c.pcd"), blob); })
                .find("its binary_compressed body has 4 bytes, not even the 8 of its two sizes"),
            std::string::npos);
  // What saveCloud writes (binary_compressed) still loads.
  pcl::PointCloud<pcl::PointXYZI> cloud, back;
  for (int i = 0; i < 20; ++i)
    cloud.push_back(pcl::PointXYZI(float(i)));
  msf::saveCloud(dir.file("saved.pcd"), cloud);
  EXPECT_EQ(errorOf([&] { msf::loadCloud(dir.file("saved.pcd"), back); }), "(no error)");
  EXPECT_EQ(back.size(), 20u);
}

/// The error loading a .ply of this header and `body` bytes, as a cloud.
std::string plyError(const std::string& header, const std::string& body = std::string(64, '\0')) {
  msf::test::TempDir dir;
  write(dir.file("h.ply"), header + body);
  pcl::PCLPointCloud2 blob;
  return errorOf([&] { msf::loadCloudBlob(dir.file("h.ply"), blob); });
}

TEST(HostileClouds, PlyHeadersAreReadStrictly) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  const std::string binary = "ply\nformat binary_little_endian 1.0\n";
  const std::pair<std::string, std::string> cases[] = {
      {binary + "element vertex -7\n" + xyz + "end_header\n",
       "line 3 'element vertex -7': count '-7' is not a whole number 0 .. 2147483647"},
      {binary + "element vertex +7\n" + xyz + "end_header\n",
       "line 3 'element vertex +7': count '+7' is not a whole number 0 .. 2147483647"},
      {binary + "element vertex 3000000000\n" + xyz + "end_header\n", "count '3000000000' is not a whole number"},
      {binary + "element vertex 1e3\n" + xyz + "end_header\n", "count '1e3' is not a whole number"},
      {binary + "element vertex 2 3\n" + xyz + "end_header\n", "element takes a name and a count"},
      {binary + "element vertex 2\n" + xyz + "element vertex 2\n" + xyz + "end_header\n",
       "element 'vertex' given twice"},
      {binary + "element vertex 2\nproperty float x\nproperty float x\nend_header\n",
       "property 'x' given twice in element 'vertex'"},
      {binary + "element vertex 2\nproperty float128 x\nend_header\n", "type 'float128' is not a PLY scalar type"},
      {binary + "element face 2\nproperty list float int vertex_indices\nend_header\n",
       "type 'float' is not a list's count type"},
      {binary + "property float x\nelement vertex 2\nend_header\n", "property before any element"},
      {binary + "element vertex 1000000\nend_header\n", "element 'vertex' has 1000000 items but no property"},
      {binary + "elemnt vertex 2\n" + xyz + "end_header\n", "'elemnt vertex 2': not a header keyword"},
      {binary + "format ascii 1.0\nend_header\n", "format given twice"},
      {"ply\nformat binary_little_endian 2.0\nend_header\n", "format is ascii, binary_little_endian or"},
      {"ply\nelement vertex 2\n" + xyz + "end_header\n", "line 6 'end_header': no format line before end_header"},
      {"plyX\nformat ascii 1.0\nend_header\n", "line 1 'plyX': the first line is not 'ply'"},
      {"ply\r\nformat ascii 1.0\nend_header\r\n", "line 2 'format ascii 1.0': a line that does not end in CR LF"},
      // Counts against the file's size: 20 vertices of 12 bytes are 240 bytes; the body has 64.
      {binary + "element vertex 20\n" + xyz + "end_header\n",
       "declares 20 vertex elements in its header, which need at least 240 bytes, but the file has 64"},
      // Lists hold at least their count: 100 faces of a uchar count need 100 bytes.
      {binary + "element vertex 0\n" + xyz + "element face 100\nproperty list uchar int vertex_indices\n"
                "end_header\n",
       "declares 100 face elements in its header, which need at least 100 bytes, but the file has 64"},
      // PCL's reader asserts that an obj_info line starts with obj_info: a blank before it aborted.
      {binary + " obj_info x\nelement vertex 2\n" + xyz + "end_header\n",
       "line 3 ' obj_info x': a line that starts with a blank"},
      {binary + "element vertex 2\n\tproperty float x\nend_header\n", "a line that starts with a blank"},
      // obj_info num_cols x num_rows size the cloud before a vertex is read.
      {binary + "obj_info num_cols 100000\nobj_info num_rows 100000\nelement vertex 2\n" + xyz + "end_header\n",
       "obj_info num_cols 100000 x num_rows 100000 make 10000000000 points, not its 2 vertices"},
      {binary + "obj_info num_cols 99999999999\nelement vertex 2\n" + xyz + "end_header\n",
       "num_cols '99999999999' is not a whole number 0 .. 2147483647"},
      // ascii: each vertex is a line of 3 values, at least 6 bytes.
      {"ply\nformat ascii 1.0\nelement vertex 11\n" + xyz + "end_header\n",
       "declares 11 vertex elements in its header, which need at least 66 bytes, but the file has 64"},
  };
  for (const auto& [header, expected] : cases) {
    const std::string e = plyError(header);
    EXPECT_NE(e.find("h.ply'"), std::string::npos) << header << "\n" << e;
    EXPECT_NE(e.find(expected), std::string::npos) << header << "\n" << e;
  }
  EXPECT_NE(plyError(binary + "element vertex 2\n" + xyz, "").find("h.ply' is not a valid .ply file (bad header): "
                                                                  "no end_header line"),
            std::string::npos);
  // The same header check for a mesh, named as one.
  msf::test::TempDir dir;
  write(dir.file("m.ply"), binary + "element vertex -7\n" + xyz + "end_header\n");
  pcl::PolygonMesh mesh;
  EXPECT_NE(errorOf([&] { msf::loadMesh(dir.file("m.ply"), mesh); }).find("mesh '"), std::string::npos);
}

TEST(HostileClouds, PlyFilesOfEveryAcceptedFormLoad) {
  const std::string xyz = "property float x\nproperty float y\nproperty float z\n";
  std::string two(24, '\0');
  const std::pair<std::string, std::string> files[] = {
      {"ply\nformat binary_little_endian 1.0\ncomment c\nobj_info o\n\nelement vertex 2\n" + xyz + "end_header\n",
       two},
      {"ply\nformat ascii 1.0\nelement vertex 2\n" + xyz + "end_header\n", "1 2 3\n4 5 6\n"},
      {"ply\nformat ascii 1.0\nelement vertex 2\n" + xyz + "end_header\n", "1 2 3\n4 5 6"}, // no last LF
      {"ply\r\nformat ascii 1.0\r\nelement vertex 2\r\nproperty float x\r\nproperty float y\r\n"
       "property float z\r\nend_header\r\n",
       "1 2 3\r\n4 5 6\r\n"},
      {"ply\nformat binary_little_endian 1.0\nelement vertex 2\n" + xyz +
           "element face 0\nproperty list uchar int vertex_indices\nend_header\n",
       two},
  };
  for (const auto& [header, body] : files) {
    msf::test::TempDir dir;
    write(dir.file("ok.ply"), header + body);
    pcl::PointCloud<pcl::PointXYZ> cloud;
    EXPECT_EQ(errorOf([&] { msf::loadCloud(dir.file("ok.ply"), cloud); }), "(no error)") << header;
    EXPECT_EQ(cloud.size(), 2u) << header;
  }
}

TEST(FuzzRegressions, CalibrationParsers) {
  msf::test::TempDir dir;
  const auto files = regressions("calibration");
  ASSERT_FALSE(files.empty());
  for (const auto& f : files) {
    const std::string bytes = bodyOf(f);
    const char* names[] = {"calib.txt", "000000.txt", "calib_cam_to_cam.txt", "camera.yaml"};
    const std::string path = dir.file(names[static_cast<unsigned char>(bytes.at(0)) % 4]);
    write(path, bytes.substr(1));
    try {
      msf::loadCalibration(path);
    } catch (const msf::Error&) {
    } catch (const std::exception& e) {
      ADD_FAILURE() << f << ": " << e.what();
    }
  }
}

TEST(FuzzRegressions, AYamlCalibrationWhoseTopLevelIsIndentedIsRefusedBeforeOpenCvLoops) {
  // fuzz_calibration (600 s run at 3cf9cc6, after ~35 s; the earlier 600 s run had not met
  // it): a 0.8 KB camera.yaml whose first key is indented by 3 and a later one not, with a value
  // starting with '-': OpenCV 4.6's cv::FileStorage::open never returned (msf_project -calib
  // looped until killed).
  const std::string bytes = bodyOf(fs::path(msf::test::sourceDir()) /
                                   "tests/io/fuzz_regressions/calibration/timeout-96c63e39dc2d02d384c70be46d69677daf853527");
  ASSERT_EQ(bytes.at(0) % 4, 3); // fuzz_calibration reads it as camera.yaml
  msf::test::TempDir dir;
  write(dir.file("camera.yaml"), bytes.substr(1));
  const std::string e = errorOf([&] { msf::loadCalibration(dir.file("camera.yaml")); });
  EXPECT_NE(e.find("camera.yaml' is not valid YAML: line 3: the top level is indented by 3 characters"),
            std::string::npos)
      << e;
}

} // namespace
