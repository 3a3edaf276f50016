// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the batch's tests share: three short synthetic drives over one street, made once per
// build, the options that keep their runs short, and reading what a batch wrote.
#include "test_support.h"

#include <msf/common/atomic_file.h>
#include <msf/evaluation/mesh_accuracy.h>
#include <msf/io/cloud_io.h>
#include <msf/io/sequence.h>
#include <msf/synthetic/ground_truth.h>
#include <msf/synthetic/seen_surface.h>
#include <msf/synthetic/synthetic_generator.h>

#include <gtest/gtest.h>
#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <sys/file.h>
#include <unistd.h>
#include <vector>

namespace msf::test {

class StreetTruth;

/// Three drives of 5 frames on one 60 m street (seed 7, no moving cars: the maps are compared
/// with the static truth): from the start, from 12 m on, and from 44 m back the other way in
/// the other lane. Each sees part of what another saw. Generated once for all the test
/// processes of a build, under a file lock, in the build folder.
class BatchDrives : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    namespace fs = std::filesystem;
    // The frame count in the name: a build whose drives have other frames does not reuse these.
    const fs::path root = fs::absolute("test_data") / ("batch_street_seed_7_frames_" + std::to_string(kFrames));
    fs::create_directories(root);
    const int lock = ::open((root / "drives.lock").c_str(), O_CREAT | O_RDWR, 0644);
    ASSERT_GE(lock, 0);
    ::flock(lock, LOCK_EX);
    drives_.clear();
    const struct {
      const char* name;
      double start_m;
      bool reverse;
    } places[] = {{"a_from_start", 0.0, false}, {"b_from_12m", 12.0, false}, {"c_back_from_44m", 44.0, true}};
    for (const auto& place : places) {
      const fs::path dir = root / place.name;
      if (!fs::exists(dir / "gt" / "scene.ply")) {
        synthetic::SyntheticConfig config;
        config.frames = kFrames;
        config.seed = 7;
        config.street_length_m = 60.0;
        config.start_m = place.start_m;
        config.reverse = place.reverse;
        config.moving_cars_ahead = 0;
        config.moving_cars_oncoming = 0;
        fs::remove_all(dir); // the tests' own drive, as an older build wrote it
        synthetic::SyntheticGenerator(config).writeDataset(dir.string());
      }
      drives_.push_back(dir.string());
    }
    config_ = (root / "batch.yaml").string();
    plain_config_ = (root / "plain_mean.yaml").string();
    // Replaced whole, never truncated: a test process already set up may be reading them.
    writeText(config_, "%YAML:1.0\ntsdf_volume:\n  voxel_size_m: 0.2\n");
    // Integration as a plain weighted mean: no carving, no weight cap reached.
    writeText(plain_config_, "%YAML:1.0\ntsdf_volume:\n  voxel_size_m: 0.2\ntsdf_integrator:\n"
                             "  space_carving: false\n  max_weight: 1.0e+30\n");
    ::flock(lock, LOCK_UN);
    ::close(lock);
  }

  static constexpr int kFrames = 5;
  /// A radius above the integrator's reach plus a tile at 0.2 m voxels (the shipped bands).
  static constexpr const char* kStream = "120";
  static const std::vector<std::string>& drives() { return drives_; }
  /// 0.2 m voxels; and the same as a plain weighted mean.
  static const std::string& config() { return config_; }
  static const std::string& plainConfig() { return plain_config_; }
  /// The drives as msf_batch's arguments.
  static std::string driveArguments() {
    std::string args;
    for (const std::string& d : drives_)
      args += " '" + d + "'";
    return args;
  }

  /// The map of batch `out` against its drives' maps: more complete than each (by 5 points), and
  /// where a drive's map has a surface, within 5 mm of its accuracy. Returns the map's scores.
  static MeshAccuracy expectBetterThanEachDrive(const std::string& out, const StreetTruth& truth);

  static void writeText(const std::string& path, const std::string& text) {
    writeAtomically(path, [&](const std::string& temporary) { std::ofstream(temporary) << text; });
  }

  inline static std::vector<std::string> drives_;
  inline static std::string config_, plain_config_;
};

inline std::string readText(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

inline std::size_t lineCount(const std::string& path) {
  std::ifstream in(path);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    ++n;
  return n;
}

/// The street's true surface (gt/scene.ply) and what the three drives saw of it (up to 40 m),
/// read once: the same yardstick for one drive's map and the merged one.
class StreetTruth {
public:
  explicit StreetTruth(const std::vector<std::string>& drives) {
    for (const std::string& d : drives) {
      const Sequence sequence(d);
      seen_.add(sequence, sequence.indices(FrameRange::parse("0:")), 40.0);
    }
    loadMesh(synthetic::GroundTruth(Sequence(drives.front()).groundTruthDir()).sceneMeshPath(), truth_);
    distance_ = std::make_unique<SurfaceDistance>(truth_);
  }

  /// Accuracy and completeness of `mesh` (protocol 3, 0.4 m: two voxels).
  MeshAccuracy score(const std::string& mesh) const {
    pcl::PolygonMesh m;
    loadMesh(mesh, m);
    return evaluateMesh(m, truth_, seen_.points, 0.4);
  }

  /// The accuracy of `mesh` where the map `region` has a surface: the mean distance to the truth
  /// (capped at 1 m) of its vertices within `radius` of `region`. The merged map against one
  /// drive's there: does merging make the surface that drive saw any worse?
  double accuracyWhere(const std::string& mesh, const std::string& region, float radius = 0.4f) const {
    pcl::PolygonMesh m, r;
    loadMesh(mesh, m);
    loadMesh(region, r);
    const SurfaceDistance to_region(r);
    pcl::PointCloud<pcl::PointXYZ> vertices;
    pcl::fromPCLPointCloud2(m.cloud, vertices);
    double sum = 0;
    std::size_t n = 0;
    for (const auto& p : vertices) {
      const Eigen::Vector3f v = p.getVector3fMap();
      if (to_region.distance(v, 2 * radius) > radius)
        continue;
      sum += distance_->distance(v, 1.f);
      ++n;
    }
    return n ? sum / static_cast<double>(n) : 1.0;
  }

private:
  synthetic::SeenSurface seen_;
  pcl::PolygonMesh truth_;
  std::unique_ptr<SurfaceDistance> distance_;
};

inline MeshAccuracy BatchDrives::expectBetterThanEachDrive(const std::string& out, const StreetTruth& truth) {
  const std::string map = out + "/map/mesh.ply";
  const MeshAccuracy merged = truth.score(map);
  for (const char* name : {"a_from_start", "b_from_12m", "c_back_from_44m"}) {
    const std::string single = out + "/drives/" + name + "/mesh.ply";
    EXPECT_GT(merged.completeness, truth.score(single).completeness + 0.05) << name;
    EXPECT_LE(truth.accuracyWhere(map, single), truth.accuracyWhere(single, single) + 0.005) << name;
  }
  return merged;
}

} // namespace msf::test
