// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/evaluation/reconstruction_evaluation.h>
#include <msf/io/frame_source.h>
#include <msf/pipeline/run_report.h>
#include <msf/pipeline/synthetic_scoring.h>

#include <map>
#include <string>

namespace msf {

// The parts of a run's report that come after its last frame, each written into the run's
// output folder `dir` and named in the report.

/// The mesh from above and from the first frame's camera, one picture (mesh_preview.png).
void writeMeshPreview(const std::string& dir, const TriangleMesh& mesh, const Calibration& calibration,
                      const Eigen::Isometry3d& T_world_cam0_first, RunReport& report);

/// The poses used, moved into the output's world by `T_out_world` (poses.txt in KITTI's format,
/// poses_tum.txt in TUM's with each frame's time), and the trajectory from above
/// (trajectory.png), with the source's own poses beside them when the used ones came from
/// elsewhere and its true ones when it knows them apart (FrameSource::referencePoses); the
/// used poses are scored against the reference whenever they differ from it (protocol 5).
/// `used_name`: "dataset", "poses file", "estimated" or "refined".
void writeTrajectory(const std::string& dir, const PoseList& used, const std::vector<std::size_t>& frames,
                     const std::string& used_name, const FrameSource& source, const Eigen::Isometry3d& T_out_world,
                     RunReport& report);

/// Protocol 4's rows for the report: each source the evaluation scored, in a fixed order, with
/// its mesh's accuracy and ghosts where the ground truth gave them.
void summarizeMapEvaluation(const ReconstructionEvaluation& evaluation,
                            const std::map<std::string, SyntheticScoring::MeshScores>& mesh_scores,
                            RunReport::MapEvaluation& out);

} // namespace msf
