// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/drive_list.h>
#include <msf/batch/one_process_map.h>
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>
#include <msf/pipeline/reconstructor.h>
#include <msf/pipeline/pose_source.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <sstream>

namespace msf {

namespace {

/// One engine runs every drive: their rigs must be one.
void requireSameRig(const Calibration& a, const Calibration& b, const std::string& drive) {
  bool same = a.image_size == b.image_size && a.T_cam0_velo.isApprox(b.T_cam0_velo, 1e-9);
  for (int c = 0; c < 4 && same; ++c)
    same = a.P[c].isApprox(b.P[c], 1e-9);
  if (!same)
    throw InvalidInputError("drive '" + drive + "' has another calibration than the first drive ('" + b.source +
                            "' and '" + a.source + "'): one process integrates drives of one rig only");
}

} // namespace

std::size_t reconstructInOneProcess(const BatchPlan& plan, const std::string& out) {
  std::vector<std::string> inputs;
  for (const Drive& d : plan.drives())
    inputs.insert(inputs.end(), {d.dataset, d.poses});
  inputs.push_back(plan.options().config);
  OutputFolder folder(out, "msf_batch", inputs);
  const PipelineConfig& config = plan.pipelineConfig();
  const std::unique_ptr<FrameSource> first = openDrive(plan.drives().front());
  Reconstructor::Options options;
  options.poses = Reconstructor::PoseMode::Given;
  options.stream_directory = folder.dir();
  Reconstructor engine(first->calibration(), config, options);
  const auto start = std::chrono::steady_clock::now();
  std::size_t frames = 0;
  for (const Drive& d : plan.drives()) {
    const std::unique_ptr<FrameSource> source = openDrive(d);
    requireSameRig(first->calibration(), source->calibration(), d.name);
    const std::vector<std::size_t> indices = source->indices(FrameRange::parse(plan.options().frames));
    const PoseSource poses(d.poses.empty() ? "dataset" : d.poses, *source, indices);
    if (poses.kind() == PoseSource::Kind::Estimated)
      throw InvalidInputError("drive '" + d.name + "' has no poses: one map needs poses in one world");
    engine.setFrameFilter([&poses](Frame& frame) { poses.apply(frame); });
    frames += engine.run(*source, indices, nullptr).frames_done;
  }
  const std::size_t triangles = engine.finishStreaming(folder.dir() + "/mesh.ply");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  if (triangles == 0)
    throw InvalidInputError("no surface was reconstructed from the " + std::to_string(frames) + " frames of " +
                            std::to_string(plan.drives().size()) + " drives: nothing is written to '" + out + "'");
  std::ostringstream json;
  json << "{\n  \"drives\": " << plan.drives().size() << ",\n  \"frames\": " << frames << ",\n  \"wall_s\": " << seconds
       << ",\n  \"triangles\": " << triangles << ",\n  \"voxel_size_m\": " << config.volume.voxel_size_m << "\n}\n";
  writeAtomically(folder.dir() + "/summary.json", [&](const std::string& tmp) {
    std::ofstream file(tmp);
    file << json.str();
    if (!file.flush())
      throw IOError("cannot write '" + tmp + "'");
  });
  folder.commit();
  return triangles;
}

} // namespace msf
