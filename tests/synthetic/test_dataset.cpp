// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The written dataset: KITTI's odometry layout that the project's readers open unchanged,
// ground truth that matches the renderer, byte-identical output for a seed, no partial output.
#include <msf/common/exceptions.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/sequence.h>
#include <msf/io/velodyne_io.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/synthetic_generator.h>

#include "test_support.h"

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <pcl/conversions.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>

namespace fs = std::filesystem;

namespace {

using msf::synthetic::GroundTruth;
using msf::synthetic::SyntheticConfig;
using msf::synthetic::SyntheticGenerator;

SyntheticConfig smallConfig(int frames, int seed) {
  SyntheticConfig c;
  c.frames = frames;
  c.seed = seed;
  return c;
}

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

std::vector<fs::path> filesUnder(const fs::path& root) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(root))
    if (e.is_regular_file())
      files.push_back(fs::relative(e.path(), root));
  std::sort(files.begin(), files.end());
  return files;
}

/// A dataset of one frame, written once for the tests of this file (rendering is the slow
/// part; the trajectory over many frames is tested on its own).
class SyntheticDataset : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    dir_ = new msf::test::TempDir;
    generator_ = new SyntheticGenerator(smallConfig(1, 3));
    generator_->writeDataset(root());
  }
  static void TearDownTestSuite() {
    delete generator_;
    delete dir_;
  }
  static std::string root() { return dir_->file("street"); }
  static msf::test::TempDir* dir_;
  static SyntheticGenerator* generator_;
};
msf::test::TempDir* SyntheticDataset::dir_ = nullptr;
SyntheticGenerator* SyntheticDataset::generator_ = nullptr;

TEST_F(SyntheticDataset, WritesTheKittiOdometryLayoutThatSequenceOpensUnchanged) {
  const fs::path r(root());
  for (const char* f :
       {"sequences/00/calib.txt", "sequences/00/times.txt", "poses/00.txt", "gt/scene.ply", "gt/README.txt",
        "gt/synthetic.yaml", "sequences/00/velodyne/000000.bin", "gt/depth_0/000000.png", "gt/disp_0/000000.png",
        "gt/obj_map_0/000000.png", "gt/moving_0/000000.png", "gt/moving_objects.txt", "gt/scene_classes.txt"})
    EXPECT_TRUE(fs::is_regular_file(r / f)) << f;
  for (int c = 0; c < 4; ++c)
    EXPECT_TRUE(fs::is_regular_file(r / "sequences/00" / ("image_" + std::to_string(c)) / "000000.png")) << c;
  EXPECT_EQ(slurp(r / "sequences/00/times.txt"), "0.000000e+00\n");
  // Nothing else is left beside the dataset (no staging folders).
  EXPECT_EQ(msf::test::countEntries(dir_->path()), 1u);

  // msf::Sequence opens the root (one sequence inside) and the sequence folder alike.
  for (const std::string& path : {root(), root() + "/sequences/00"}) {
    const msf::Sequence seq(path);
    EXPECT_EQ(seq.layout(), msf::Sequence::Layout::Odometry);
    ASSERT_EQ(seq.size(), 1u);
    EXPECT_EQ(seq.frameName(0), "000000");
    const msf::Calibration& calib = seq.calibration();
    EXPECT_EQ(calib.image_size, cv::Size(1242, 375));
    EXPECT_NEAR(calib.fx(), 721.5377, 1e-4);
    EXPECT_NEAR(calib.cx(), 609.5593, 1e-4);
    EXPECT_NEAR(calib.cy(), 172.854, 1e-4);
    EXPECT_NEAR(calib.baselineGrey(), 0.537, 0.001);
    EXPECT_NEAR(calib.baselineColor(), 0.532, 0.002);
    // The Velodyne sits about 8 cm above and 27 cm behind camera 0.
    const Eigen::Vector3d velo = calib.T_cam0_velo.translation(); // its origin in camera 0
    EXPECT_NEAR(velo.x(), 0.0, 0.02);
    EXPECT_NEAR(velo.y(), -0.08, 0.02);
    EXPECT_NEAR(velo.z(), -0.27, 0.02);
    ASSERT_TRUE(seq.hasPoses());
    EXPECT_TRUE(seq.poses()[0].isApprox(Eigen::Isometry3d::Identity(), 1e-12));
    EXPECT_EQ(fs::path(seq.groundTruthDir()), fs::path(root()) / "gt");
    const msf::Frame f = seq.load(0);
    EXPECT_EQ(f.left.type(), CV_8UC1);
    EXPECT_EQ(f.color.type(), CV_8UC3);
    EXPECT_GT(f.scan->size(), 90000u);
  }
}

TEST_F(SyntheticDataset, FilesHoldWhatTheGeneratorRendered) {
  const SyntheticGenerator& gen = *generator_;
  const msf::synthetic::SyntheticFrame frame = gen.renderFrame(0, false);
  const fs::path seq = fs::path(root()) / "sequences/00";
  for (int c = 0; c < 4; ++c) {
    const cv::Mat image = msf::readImage((seq / ("image_" + std::to_string(c)) / "000000.png").string(), -1);
    EXPECT_EQ(image.size(), cv::Size(1242, 375));
    EXPECT_EQ(image.type(), c < 2 ? CV_8UC1 : CV_8UC3);
    if (c < 2) {
      EXPECT_EQ(cv::norm(image, frame.images[c], cv::NORM_INF), 0.0) << "camera " << c;
    }
  }
  EXPECT_TRUE(frame.images[2].empty());
  pcl::PointCloud<pcl::PointXYZI> scan;
  msf::loadVelodyneBin((seq / "velodyne/000000.bin").string(), scan);
  ASSERT_EQ(scan.size(), frame.scan.size());
  for (std::size_t i = 0; i < scan.size(); i += 997) {
    EXPECT_EQ(scan[i].x, frame.scan[i].x);
    EXPECT_EQ(scan[i].intensity, frame.scan[i].intensity);
  }

  for (const std::string& path : {root(), (seq).string(), root() + "/gt"}) {
    const GroundTruth gt(path);
    ASSERT_EQ(gt.size(), 1u);
    const cv::Mat depth = gt.depth(0), disparity = gt.disparity(0), objects = gt.objectMap(0);
    // 16-bit PNGs hold 1/256 steps.
    cv::Mat diff = cv::abs(depth - frame.depth);
    EXPECT_LE(cv::norm(diff, cv::NORM_INF), 0.5 / 256 + 1e-6);
    diff = cv::abs(disparity - frame.disparity);
    EXPECT_LE(cv::norm(diff, cv::NORM_INF), 0.5 / 256 + 1e-6);
    EXPECT_EQ(cv::norm(objects, frame.objects, cv::NORM_INF), 0.0);
    const cv::Mat moving = gt.movingMask(0);
    EXPECT_EQ(moving.type(), CV_8UC1);
    EXPECT_EQ(cv::norm(moving, frame.moving, cv::NORM_INF), 0.0);
    EXPECT_GT(cv::countNonZero(moving), 1000);
    // The box file holds the generator's boxes (to the float; see test_movers.cpp).
    const std::vector<msf::synthetic::MovingBox> boxes = gt.movingBoxes(), written = gen.movingBoxes();
    ASSERT_EQ(boxes.size(), written.size());
    ASSERT_EQ(boxes.size(), gen.scene().movers.size()); // all on the street at frame 0
    for (std::size_t k = 0; k < boxes.size(); ++k) {
      EXPECT_EQ(boxes[k].object, written[k].object);
      EXPECT_EQ(static_cast<float>(boxes[k].center.z()), static_cast<float>(written[k].center.z()));
    }
    // Disparity is f B / z where depth exists, and absent exactly where depth is.
    const double fB = gen.calibration().focalBaseline();
    for (int v = 0; v < depth.rows; v += 7)
      for (int u = 0; u < depth.cols; u += 7) {
        const float z = frame.depth.at<float>(v, u);
        ASSERT_EQ(z > 0.f, disparity.at<float>(v, u) > 0.f) << u << "," << v;
        if (z > 0.f) {
          ASSERT_NEAR(disparity.at<float>(v, u), fB / z, 0.5 / 256 + 1e-4);
        }
      }
    const msf::synthetic::GroundTruth::Split split = gt.split(0);
    const int fg = cv::countNonZero(split.foreground), bg = cv::countNonZero(split.background);
    EXPECT_EQ(cv::countNonZero(split.foreground != gt.split(0, depth).foreground), 0) << "the depth given or read";
    EXPECT_GT(fg, 1000);
    EXPECT_EQ(fg + bg, cv::countNonZero(depth > 0.f));
    EXPECT_TRUE(fs::is_regular_file(gt.sceneMeshPath()));
    EXPECT_EQ(gt.indexOf("000000"), 0u);
    EXPECT_THROW(gt.depth(1), msf::InvalidInputError);
  }
  EXPECT_THROW(GroundTruth(dir_->path() + "/nothing"), msf::IOError);
  EXPECT_EQ(GroundTruth::find("/"), "");
}

/// Distance from p to triangle abc (Ericson, Real-Time Collision Detection 5.1.5).
double pointTriangleDistance(const Eigen::Vector3d& p, const Eigen::Vector3d& a, const Eigen::Vector3d& b,
                             const Eigen::Vector3d& c) {
  const Eigen::Vector3d ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0)
    return ap.norm();
  const Eigen::Vector3d bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3)
    return bp.norm();
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0)
    return (p - (a + ab * (d1 / (d1 - d3)))).norm();
  const Eigen::Vector3d cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6)
    return cp.norm();
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0)
    return (p - (a + ac * (d2 / (d2 - d6)))).norm();
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0)
    return (p - (b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))))).norm();
  const double denom = 1.0 / (va + vb + vc);
  return (p - (a + ab * (vb * denom) + ac * (vc * denom))).norm();
}

TEST_F(SyntheticDataset, SceneMeshIsTheSurfaceTheCamerasSee) {
  pcl::PolygonMesh mesh;
  msf::loadMesh(GroundTruth(root()).sceneMeshPath(), mesh);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(mesh.cloud, vertices);
  ASSERT_GT(mesh.polygons.size(), 10000u);
  // Back-project ground-truth pixels of frame 0 that see the static world into the world
  // (poses/00.txt's frame) and measure their distance to the mesh: only tessellation of
  // curved solids may differ.
  const msf::Sequence seq(root());
  const GroundTruth gt(root());
  const cv::Mat depth = gt.depth(0), moving = gt.movingMask(0);
  ASSERT_GT(cv::countNonZero(moving), 1000); // the cars driving ahead and oncoming
  const msf::Calibration& calib = seq.calibration();
  std::vector<Eigen::Vector3d> points;
  for (int v = 5; v < depth.rows; v += 37)
    for (int u = 5; u < depth.cols; u += 61) {
      const double z = depth.at<float>(v, u);
      if (z <= 0.0 || z > 60.0 || moving.at<std::uint8_t>(v, u) != 0)
        continue;
      const Eigen::Vector3d cam((u - calib.cx()) * z / calib.fx(), (v - calib.cy()) * z / calib.fy(), z);
      points.push_back(seq.poses()[0] * cam);
    }
  ASSERT_GT(points.size(), 100u);
  std::vector<double> distances;
  for (const Eigen::Vector3d& p : points) {
    double best = 1e9;
    for (const auto& poly : mesh.polygons) {
      const auto& a = vertices[poly.vertices[0]], &b = vertices[poly.vertices[1]], &c = vertices[poly.vertices[2]];
      // Quick reject by the bounding box grown by the best distance so far.
      const double lo_x = std::min({a.x, b.x, c.x}) - best, hi_x = std::max({a.x, b.x, c.x}) + best;
      const double lo_z = std::min({a.z, b.z, c.z}) - best, hi_z = std::max({a.z, b.z, c.z}) + best;
      if (p.x() < lo_x || p.x() > hi_x || p.z() < lo_z || p.z() > hi_z)
        continue;
      best = std::min(best, pointTriangleDistance(p, a.getVector3fMap().cast<double>(),
                                                  b.getVector3fMap().cast<double>(), c.getVector3fMap().cast<double>()));
    }
    distances.push_back(best);
    if (best > 0.1)
      std::printf("far: %.3f %.3f %.3f -> %.3f\n", p.x(), p.y(), p.z(), best);
  }
  std::sort(distances.begin(), distances.end());
  const double median = distances[distances.size() / 2], p95 = distances[distances.size() * 95 / 100];
  std::printf("scene.ply: %zu triangles; distance of %zu true surface points to it: median %.4f m, 95th %.4f m\n",
              mesh.polygons.size(), distances.size(), median, p95);
  EXPECT_LT(median, 0.005);
  EXPECT_LT(p95, 0.03);
}

TEST_F(SyntheticDataset, SceneClassesNameWhatEachVertexOfTheSceneMeshIs) {
  const GroundTruth gt(root());
  ASSERT_TRUE(gt.hasSceneClasses());
  pcl::PolygonMesh mesh;
  msf::loadMesh(gt.sceneMeshPath(), mesh);
  pcl::PointCloud<pcl::PointXYZ> vertices;
  pcl::fromPCLPointCloud2(mesh.cloud, vertices);
  const msf::SurfaceClasses classes = gt.sceneClasses(vertices.size());
  ASSERT_EQ(classes.vertex_class.size(), vertices.size());
  // Heights above the road (y points down; the road is the lowest surface), per class.
  float road_y = -1e9f;
  for (const auto& p : vertices)
    road_y = std::max(road_y, p.y);
  std::map<std::string, std::pair<float, float>> height; // least and greatest
  for (std::size_t i = 0; i < vertices.size(); ++i) {
    auto [it, fresh] = height.try_emplace(classes.names[classes.vertex_class[i]], 1e9f, -1e9f);
    const float h = road_y - vertices[i].y;
    it->second = {std::min(it->second.first, h), std::max(it->second.second, h)};
  }
  for (const char* name : {"ground", "building", "car", "pole", "tree"})
    EXPECT_TRUE(height.count(name)) << name;
  EXPECT_LT(height["ground"].second, 0.3f); // the road and the kerbs' sidewalk
  EXPECT_LT(height["car"].second, 2.5f);    // parked cars
  EXPECT_GT(height["tree"].second, 4.f);    // crowns
  EXPECT_GT(height["building"].second, 8.f);
  EXPECT_THROW(gt.sceneClasses(vertices.size() + 1), msf::IOError); // another mesh's
}

TEST_F(SyntheticDataset, SameSeedGivesByteIdenticalFilesAndAnotherSeedDoesNot) {
  msf::test::TempDir other;
  const std::string again = other.file("again");
  SyntheticGenerator(smallConfig(1, 3)).writeDataset(again);
  const auto files = filesUnder(root());
  ASSERT_EQ(files, filesUnder(again));
  for (const auto& f : files)
    EXPECT_TRUE(slurp(fs::path(root()) / f) == slurp(fs::path(again) / f)) << f;

  // Another seed: another street, other noise.
  const SyntheticGenerator different(smallConfig(1, 4));
  const cv::Mat image = msf::readImage((fs::path(root()) / "sequences/00/image_0/000000.png").string(), -1);
  EXPECT_GT(cv::norm(image, different.renderFrame(0, false).images[0], cv::NORM_L1), 10.0 * image.total());
}

TEST(SyntheticRendering, ColourImagesWithTiedSolidsArePixelForPixelAsBefore) {
  // Frames of the default 40-frame loop (msf_synth -frames 40 -loop) whose pixels, hashed
  // (FNV-1a 64 of the rows), are those b42915f rendered: each holds one ray whose nearest
  // solids tie (coplanar faces; in frame 8, solid 346 over 345, not the lower index). A ray
  // caster that meets solids in another order (a 4-wide hierarchy by lowest index did)
  // changes them, and so the datasets a seed gives.
  SyntheticConfig config;
  config.frames = 40;
  config.loop = true;
  const SyntheticGenerator generator(config);
  auto fnv = [](const cv::Mat& image) {
    std::uint64_t h = 0xcbf29ce484222325ULL;
    for (int v = 0; v < image.rows; ++v)
      for (std::size_t k = 0; k < static_cast<std::size_t>(image.cols) * image.elemSize(); ++k) {
        h ^= image.ptr<std::uint8_t>(v)[k];
        h *= 0x100000001b3ULL;
      }
    return h;
  };
  const struct {
    std::size_t frame;
    int camera;
    std::uint64_t hash;
  } pinned[] = {{8, 2, 0x0661470b67fc8cfdULL}, {20, 3, 0x06ae1d35a2ab8a36ULL}};
  for (const auto& p : pinned) {
    const cv::Mat image =
        generator.renderer().render(generator.sceneAt(p.frame), p.camera, generator.poses()[p.frame], p.frame);
    EXPECT_EQ(fnv(image), p.hash) << "frame " << p.frame << " camera " << p.camera;
  }
}

TEST(SyntheticDatasetOutput, ReplacesAnEarlierDatasetAndRefusesAnyOtherFolder) {
  msf::test::TempDir dir;
  // A dataset msf_synth wrote is replaced as a whole, not merged.
  const std::string root = dir.file("ds");
  SyntheticGenerator(smallConfig(2, 1)).writeDataset(root);
  ASSERT_TRUE(fs::exists(root + "/sequences/00/image_0/000001.png"));
  SyntheticGenerator(smallConfig(1, 1)).writeDataset(root);
  EXPECT_EQ(msf::Sequence(root).size(), 1u);
  EXPECT_FALSE(fs::exists(root + "/sequences/00/image_0/000001.png"));
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);

  // A file the user put into it since is theirs: the folder is refused and the file kept.
  std::ofstream(root + "/gt/my_notes.txt") << "mine";
  const std::string error = msf::test::errorOf([&] { SyntheticGenerator(smallConfig(1, 1)).writeDataset(root); });
  EXPECT_NE(error.find("gt/my_notes.txt"), std::string::npos) << error;
  EXPECT_TRUE(fs::exists(root + "/gt/my_notes.txt"));

  // So is a folder that looks like a dataset but that msf_synth did not write (no manifest).
  const std::string lookalike = dir.file("lookalike");
  fs::create_directories(lookalike + "/gt");
  fs::create_directories(lookalike + "/sequences/00/image_0");
  std::ofstream(lookalike + "/gt/scene.ply") << "mine";
  EXPECT_THROW(SyntheticGenerator(smallConfig(1, 1)).writeDataset(lookalike), msf::IOError);
  EXPECT_TRUE(fs::exists(lookalike + "/gt/scene.ply"));

  const std::string foreign = dir.file("photos");
  fs::create_directory(foreign);
  std::ofstream(foreign + "/keep.jpg") << "x";
  try {
    SyntheticGenerator(smallConfig(1, 1)).writeDataset(foreign);
    ADD_FAILURE() << "a non-empty foreign folder was overwritten";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find(foreign), std::string::npos) << e.what();
  }
  EXPECT_EQ(msf::test::countEntries(foreign), 1u);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 3u);

  std::ofstream(dir.file("plain_file")) << "x";
  EXPECT_THROW(SyntheticGenerator(smallConfig(1, 1)).writeDataset(dir.file("plain_file") + "/ds"), msf::IOError);
  EXPECT_THROW(SyntheticGenerator(smallConfig(1, 1)).writeDataset(dir.file("missing/ds")), msf::IOError);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 4u);
}

TEST(SyntheticDatasetOutput, AFailureMidwayLeavesNothing) {
  msf::test::TempDir dir;
  const SyntheticGenerator gen(smallConfig(2, 1));
  EXPECT_THROW(gen.writeDataset(dir.file("ds"),
                                [](std::size_t frame, double, std::size_t) {
                                  if (frame == 0)
                                    throw msf::IOError("disk full (simulated)");
                                }),
               msf::IOError);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u);
  EXPECT_THROW(gen.renderFrame(2), msf::InvalidInputError);
}

} // namespace
