// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/frame_source.h>
#include <msf/pipeline/reconstructor.h>

#include <string>
#include <vector>

namespace msf {

/// Where a reconstruction's poses come from (msf_reconstruct -poses): the dataset's own, a
/// KITTI poses file, LiDAR odometry estimated as the frames are loaded, or the dataset's
/// GPS/INS poses refined by it. A file's poses are set by apply() (a frame filter of the
/// engine); the odometry is the engine's (Reconstructor::PoseMode::Odometry and Refine),
/// anchored at the dataset's pose of the first frame when there is one, so that its map is in
/// the same world as the ground truth.
class PoseSource {
public:
  enum class Kind { Dataset, File, Estimated, Refined };

  /// `option`: "dataset", "estimate", "refine" or the path of a poses file: KITTI's (line i is
  /// frame i) or TUM's (each frame takes the pose at its time, within 5 ms); "" is "refine"
  /// when the source's poses are a GPS/INS's measurement (FrameSource::posesAreMeasured),
  /// "dataset" when it has other poses, else "estimate". Throws InvalidInputError naming the
  /// option when "dataset" or "refine" has no poses or the file has no line for one of
  /// `frames`, and IOError for a malformed file.
  PoseSource(const std::string& option, const FrameSource& source, const std::vector<std::size_t>& frames);

  /// Sets the frame's pose from a file (nothing for the dataset's, which the source set, or
  /// for an estimate, which the engine's odometry gives).
  void apply(Frame& frame) const;
  /// How the engine finds each frame's pose.
  Reconstructor::PoseMode mode() const;

  /// The poses T_world_cam0 of `frames` when they are known before the run (the dataset's or a
  /// file's; the dataset's for refined ones, which stay near them), in order; empty for
  /// estimated ones, which exist only as the frames are tracked.
  PoseList knownPoses(const std::vector<std::size_t>& frames) const;

  Kind kind() const { return kind_; }
  /// In words, for the report: "the dataset's: ...", "file '...'", "estimated (LiDAR odometry)"
  /// or "the dataset's: ..., refined by LiDAR odometry".
  const std::string& description() const { return description_; }
  /// The file's path for Kind::File, else "".
  const std::string& file() const { return file_; }

private:
  /// Throws unless the source has poses of its own for `option`.
  void requireDatasetPoses(const std::string& option) const;
  void readKitti(const std::vector<std::size_t>& frames);
  void readTum(const std::vector<std::size_t>& frames);

  Kind kind_ = Kind::Dataset;
  std::string description_, file_;
  const FrameSource& source_;
  PoseList file_poses_;
};

} // namespace msf
