// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/drive_resources.h>
#include <msf/batch/drive_list.h>
#include <msf/common/exceptions.h>
#include <msf/pipeline/pose_source.h>
#include <msf/range_image/lidar_projector.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <cmath>

namespace msf {

DriveResources predictDriveResources(const Drive& drive, const PipelineConfig& config, const std::string& frames,
                                     double process_mb) {
  const std::unique_ptr<FrameSource> source = openDrive(drive);
  const std::vector<std::size_t> indices = source->indices(FrameRange::parse(frames));
  if (drive.poses.empty() && !source->hasPoses())
    throw InvalidInputError("drive '" + drive.name + "' ('" + drive.dataset +
                            "') has no poses: a batch merges drives whose poses share a world; give its poses file "
                            "in the drive list (DATASET POSES)");
  const PoseSource poses(drive.poses.empty() ? "dataset" : drive.poses, *source, indices);
  // The radius a streamed run checks at its start, checked before any task is submitted.
  TsdfVolume volume(config.volume.voxel_size_m, config.volume.truncation_m);
  const double reach = TsdfIntegrator(volume, config.integrator)
                           .reach(LidarProjector(source->calibration(), config.projection).canvasCamera());
  config.streaming.requireRadius(reach, config.volume.voxel_size_m);
  Reconstructor engine(source->calibration(), config);
  DriveResources r;
  r.frames = indices.size();
  MemoryEvidence evidence = engine.measureMemory(*source, indices, poses.knownPoses(indices));
  evidence.process_mb = process_mb; // the drive's own process, not this one grown by the drives before
  r.predicted_mb = engine.predictMemory(evidence).total_mb;
  const double step = static_cast<double>(DriveResources::kRequestStepMb);
  r.request_mb = static_cast<std::size_t>(std::ceil(r.predicted_mb * DriveResources::kMargin / step) * step);
  return r;
}

} // namespace msf
