// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/io/cloud_io.h>
#include <msf/io/image_io.h>
#include <msf/io/organized_conversion.h>
#include <msf/io/velodyne_io.h>
#include <msf/io/rig_file.h>
#include <msf/synthetic/ins_error.h>
#include <msf/synthetic/scene_mesh.h>
#include <msf/synthetic/street_scene.h>
#include <msf/synthetic/synthetic_rig.h>
#include <msf/synthetic/synthetic_generator.h>
#include <msf/synthetic/trajectory.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <future>
#include <memory>
#include <optional>
#include <sstream>
#include <unistd.h>

namespace fs = std::filesystem;

namespace msf::synthetic {

namespace {

/// The 16-bit KITTI PNGs hold at most 255.996 m; farther pixels get no ground truth.
constexpr float kMaxGroundTruthDepthM = 255.f;

SyntheticConfig validated(const SyntheticConfig& config) {
  config.validate();
  const double path = (config.frames - 1) * config.speed_mps / config.frame_rate_hz;
  if (path > 5000.0)
    throw ConfigError("config keys 'synthetic.frames', 'speed_mps', 'frame_rate_hz' make a path of " +
                      std::to_string(path) + " m; at most 5000 m");
  return config;
}

std::string frameName(std::size_t i) {
  char name[24]; // 20 digits at most
  std::snprintf(name, sizeof name, "%06zu", i);
  return name;
}

/// How far the street is built along z: config.street_length_m (shared by the drives of one
/// world), or as far as this drive goes (a loop comes back). Throws ConfigError naming the keys
/// when the drive leaves the street (below z = 0, or beyond street_length_m).
double streetEnd(const SyntheticConfig& config, const PoseList& poses) {
  double lo = 0.0, hi = 0.0;
  for (const auto& T : poses) {
    lo = std::min(lo, T.translation().z());
    hi = std::max(hi, T.translation().z());
  }
  if (lo < 0.0)
    throw ConfigError("config keys 'synthetic.start_m' = " + std::to_string(config.start_m) +
                      " and 'reverse' make a drive that leaves the street's start (it reaches z = " +
                      std::to_string(lo) + " m): start a reversed drive at least as far along as it drives");
  if (config.street_length_m == 0.0)
    return hi;
  if (hi > config.street_length_m + 1e-9)
    throw ConfigError("config key 'synthetic.street_length_m' = " + std::to_string(config.street_length_m) +
                      " is shorter than the drive, which reaches z = " + std::to_string(hi) +
                      " m (start_m, frames, speed_mps): the drive must lie on the street");
  return config.street_length_m;
}

void writeText(const fs::path& path, const std::string& text) {
  writeStreamAtomically(path.string(), [&](std::ostream& out) { out << text; });
}

const char* kGroundTruthReadme =
    "Ground truth of a synthetic sequence written by msf_synth (msfusion).\n"
    "depth_0/NNNNNN.png    camera 0 depth z, 16-bit, metres x 256, 0 = none (sky, beyond 255 m)\n"
    "disp_0/NNNNNN.png     grey-pair disparity f B / z, 16-bit, pixels x 256, 0 = none\n"
    "obj_map_0/NNNNNN.png  8-bit, 0 = background, 1..255 = foreground instance (cars, poles, people)\n"
    "moving_0/NNNNNN.png   8-bit, 255 = the pixel sees a moving object (a car driving), 0 = static\n"
    "moving_objects.txt    the moving objects' oriented boxes at every frame, in the world of poses/00.txt\n"
    "                      (one line per frame and object; its header names the columns)\n"
    "scene.ply             the true static surface (no moving objects), in the world of poses/00.txt\n"
    "                      (camera 0 at frame 0)\n"
    "scene_classes.txt     what each vertex of scene.ply is (ground, building, car, pole, person, tree), in runs\n"
    "                      of vertices: first_vertex vertex_count class\n"
    "synthetic.yaml        the generator's configuration\n"
    "poses.txt             with ins_poses: the true T_world_cam0 (poses/00.txt then holds them as a GPS/INS\n"
    "                      measures them, with a drifting heading and a wandering position)\n"
    "Every pixel is exact: the value of the ray through the pixel centre.\n";

} // namespace

SyntheticGenerator::SyntheticGenerator(const SyntheticConfig& config)
    : config_(validated(config)),
      calibration_(syntheticRig(config_)),
      poses_(streetTrajectory(config_)),
      scene_(buildStreetScene(config_, streetEnd(config_, poses_))),
      renderer_(calibration_, config_),
      lidar_(config_) {}

SceneSnapshot SyntheticGenerator::sceneAt(std::size_t i) const {
  if (i >= poses_.size())
    throw InvalidInputError("frame " + std::to_string(i) + " is out of range: the sequence has " +
                            std::to_string(poses_.size()) + " frames");
  return SceneSnapshot(scene_, static_cast<double>(i) / config_.frame_rate_hz);
}

std::vector<MovingBox> SyntheticGenerator::movingBoxes() const {
  std::vector<MovingBox> boxes;
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    const SceneSnapshot snapshot = sceneAt(i);
    for (const MovingObject* mover : snapshot.movers()) {
      boxes.push_back(mover->boxAt(snapshot.time()));
      boxes.back().frame = i;
    }
  }
  return boxes;
}

SyntheticFrame SyntheticGenerator::renderFrame(std::size_t i, bool with_color) const {
  const SceneSnapshot snapshot = sceneAt(i);
  const Eigen::Isometry3d& T_world_cam0 = poses_[i];
  SyntheticFrame f;
  cv::Mat ids;
  f.images[0] = renderer_.render(snapshot, 0, T_world_cam0, i, &f.depth, &ids);
  for (int camera = 1; camera < (with_color ? 4 : 2); ++camera)
    f.images[camera] = renderer_.render(snapshot, camera, T_world_cam0, i);
  f.scan = lidar_.scan(snapshot, T_world_cam0 * calibration_.T_cam0_velo, i);

  std::vector<bool> is_moving(scene_.objectCount() + 1, false);
  for (const MovingObject& mover : scene_.movers)
    is_moving[mover.object()] = true;
  f.objects.create(ids.size(), CV_8UC1);
  f.moving.create(ids.size(), CV_8UC1);
  for (int v = 0; v < ids.rows; ++v) {
    float* d = f.depth.ptr<float>(v);
    const std::int32_t* id = ids.ptr<std::int32_t>(v);
    std::uint8_t* o = f.objects.ptr<std::uint8_t>(v);
    std::uint8_t* m = f.moving.ptr<std::uint8_t>(v);
    for (int u = 0; u < ids.cols; ++u) {
      if (d[u] > kMaxGroundTruthDepthM)
        d[u] = 0.f;
      o[u] = (id[u] > 0 && d[u] > 0.f) ? static_cast<std::uint8_t>((id[u] - 1) % 255 + 1) : 0;
      // From the exact id, not the 8-bit map (whose ids repeat on long streets).
      m[u] = is_moving[static_cast<std::size_t>(id[u])] ? 255 : 0;
    }
  }
  f.disparity = depthToDisparity(f.depth, calibration_);
  return f;
}

pcl::PolygonMesh SyntheticGenerator::mesh(SurfaceClasses* classes) const {
  return sceneMesh(scene_, config_.mesh_max_edge_m, classes);
}

void SyntheticGenerator::writeDataset(const std::string& root_arg, const Progress& progress) const {
  if (root_arg.empty())
    throw InvalidInputError("no output folder given");
  OutputFolder output(root_arg, "msf_synth");
  const fs::path staging = output.dir();
  const fs::path seq = staging / "sequences" / "00", gt = staging / "gt";
  std::error_code ec;
  for (const fs::path& dir : {seq / "image_0", seq / "image_1", seq / "image_2", seq / "image_3", seq / "velodyne",
                              staging / "poses", gt / "depth_0", gt / "disp_0", gt / "obj_map_0", gt / "moving_0"})
    if (!fs::create_directories(dir, ec) || ec)
      throw IOError("cannot create folder '" + dir.string() + "'" + (ec ? ": " + ec.message() : ""));
  writeSequenceFiles(seq, staging / "poses", gt);
  writeGroundTruthFiles(gt);
  writeFrames(seq, gt, progress);
  output.commit();
}

void SyntheticGenerator::writeSequenceFiles(const fs::path& seq, const fs::path& poses, const fs::path& gt) const {
  saveOdometryCalibration(calibration_, (seq / "calib.txt").string());
  saveRigFile(calibration_, (seq / "rig.yaml").string());
  std::ostringstream times;
  for (int i = 0; i < config_.frames; ++i) {
    char line[32];
    std::snprintf(line, sizeof line, "%e\n", i / config_.frame_rate_hz);
    times << line;
  }
  writeText(seq / "times.txt", times.str());
  if (config_.ins_poses) {
    saveOdometryPoses((poses / "00.txt").string(), insPoses(poses_, config_));
    saveOdometryPoses((gt / "poses.txt").string(), poses_);
  } else {
    saveOdometryPoses((poses / "00.txt").string(), poses_);
  }
}

void SyntheticGenerator::writeGroundTruthFiles(const fs::path& gt) const {
  std::ostringstream yaml; // plain YAML, which msf_synth -config reads back to the same dataset
  std::vector<KeyText> keys = listKeys(config_);
  if (config_.sky == SyntheticConfig().sky) // the default sky unnamed: the file reads as before the key
    keys.erase(std::find_if(keys.begin(), keys.end(), [](const KeyText& k) { return k.name == "sky"; }));
  printSection(yaml, SyntheticConfig::kSection, keys);
  writeText(gt / "synthetic.yaml", yaml.str());
  std::string readme = kGroundTruthReadme;
  if (config_.placed()) // the world is the street's, where this drive does not start
    readme.replace(readme.find("(camera 0 at frame 0)"), 21, "(the street's: camera 0 where a drive from its start begins)");
  writeText(gt / "README.txt", readme);
  SurfaceClasses classes;
  saveMesh((gt / "scene.ply").string(), mesh(&classes));
  writeText(gt / "scene_classes.txt", formatSurfaceClasses(classes));
  writeText(gt / "moving_objects.txt", formatMovingBoxes(movingBoxes()));
}

void SyntheticGenerator::writeFrames(const fs::path& seq, const fs::path& gt, const Progress& progress) const {
  // Frame i's files are written (PNG compression, a tenth of a frame's time) on a thread of
  // their own while frame i + 1 renders: they fill the renderer's idle moments instead of
  // following them. A frame's writes end before the next frame's begin.
  struct Pending {
    std::future<void> written;
    std::size_t frame, points;
    std::chrono::steady_clock::time_point start;
  };
  std::optional<Pending> pending; // its future waits for the writes when an error unwinds
  using Clock = std::chrono::steady_clock;
  const auto seconds = [](Clock::duration d) { return std::chrono::duration<double>(d).count(); };
  // A frame's time: from its start to the next frame's, plus any wait for its writes.
  const auto finishPending = [&](Clock::time_point next_start) {
    const auto wait_start = Clock::now();
    pending->written.get();
    if (progress)
      progress(pending->frame, seconds(next_start - pending->start) + seconds(Clock::now() - wait_start),
               pending->points);
    pending.reset();
  };
  for (std::size_t i = 0; i < poses_.size(); ++i) {
    const auto start = Clock::now();
    auto f = std::make_shared<const SyntheticFrame>(renderFrame(i));
    if (pending)
      finishPending(start);
    const std::string png = frameName(i) + ".png", bin = frameName(i) + ".bin";
    // One after another: a parallel loop here would run serially while the renderer holds
    // OpenCV's pool (or make the renderer's run serially).
    auto write = [&seq, &gt, f, png, bin] {
      for (int c = 0; c < 4; ++c)
        writeImage((seq / ("image_" + std::to_string(c)) / png).string(), f->images[c]);
      saveVelodyneBin((seq / "velodyne" / bin).string(), f->scan);
      writeKittiDepthPng((gt / "depth_0" / png).string(), f->depth);
      writeKittiDisparityPng((gt / "disp_0" / png).string(), f->disparity);
      writeImage((gt / "obj_map_0" / png).string(), f->objects);
      writeImage((gt / "moving_0" / png).string(), f->moving);
    };
    pending = Pending{std::async(std::launch::async, write), i, f->scan.size(), start};
  }
  if (pending)
    finishPending(Clock::now());
}

} // namespace msf::synthetic
