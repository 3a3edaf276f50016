// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/tum_poses.h>
#include <msf/pipeline/pose_source.h>

#include <algorithm>
#include <cmath>
#include <filesystem>

namespace msf {

PoseSource::PoseSource(const std::string& option, const FrameSource& source, const std::vector<std::size_t>& frames)
    : source_(source) {
  const std::string choice = !option.empty()         ? option
                             : source.posesAreMeasured() ? "refine"
                             : source.hasPoses()         ? "dataset"
                                                         : "estimate";
  if (choice == "dataset") {
    requireDatasetPoses(choice);
    kind_ = Kind::Dataset;
    description_ = "the dataset's: " + source.posesName();
  } else if (choice == "refine") {
    requireDatasetPoses(choice);
    kind_ = Kind::Refined;
    description_ = "the dataset's: " + source.posesName() + ", refined by LiDAR odometry";
  } else if (choice == "estimate") {
    kind_ = Kind::Estimated;
    description_ = "estimated (LiDAR odometry)";
  } else {
    if (!std::filesystem::is_regular_file(choice))
      throw InvalidInputError("-poses '" + choice +
                              "': no such file, and not one of dataset, refine (the dataset's GPS/INS poses refined by "
                              "the scans) or estimate");
    kind_ = Kind::File;
    file_ = choice;
    description_ = "file '" + choice + "'";
    if (isTumPoses(choice))
      readTum(frames);
    else
      readKitti(frames);
  }
}

void PoseSource::requireDatasetPoses(const std::string& option) const {
  if (!source_.hasPoses())
    throw InvalidInputError("-poses " + option + ": '" + source_.description() +
                            "' has no poses (odometry poses/XX.txt, raw oxts/ or a poses file of its own); "
                            "-poses estimate tracks them from the scans");
}

void PoseSource::readKitti(const std::vector<std::size_t>& frames) {
  file_poses_ = loadOdometryPoses(file_);
  for (std::size_t i : frames)
    if (i >= file_poses_.size())
      throw InvalidInputError("-poses '" + file_ + "' has " + std::to_string(file_poses_.size()) +
                              " poses (line i is frame i) and no pose for frame " + std::to_string(i));
}

void PoseSource::readTum(const std::vector<std::size_t>& frames) {
  // TUM's lines carry their time: each frame takes the pose at its own time (the dataset's,
  // from its first frame), within 5 ms: a 100 Hz INS's nearest record.
  constexpr double kToleranceS = 0.005;
  const StampedPoses tum = loadTumPoses(file_);
  file_poses_.assign(source_.size(), Eigen::Isometry3d::Identity());
  for (std::size_t i : frames) {
    const double t = source_.timestamp(i);
    const auto it = std::lower_bound(tum.timestamps.begin(), tum.timestamps.end(), t - kToleranceS);
    if (it == tum.timestamps.end() || std::abs(*it - t) > kToleranceS)
      throw InvalidInputError("-poses '" + file_ + "' (TUM: timestamp tx ty tz qx qy qz qw) has no pose within 5 ms "
                              "of frame " + source_.frameName(i) + "'s time " + std::to_string(t) +
                              " s (times from the dataset's first frame)");
    file_poses_[i] = tum.poses[static_cast<std::size_t>(it - tum.timestamps.begin())];
  }
}

void PoseSource::apply(Frame& frame) const {
  if (kind_ != Kind::File)
    return;
  frame.T_world_cam0 = file_poses_.at(frame.index);
  frame.has_pose = true;
}

Reconstructor::PoseMode PoseSource::mode() const {
  switch (kind_) {
  case Kind::Estimated:
    return Reconstructor::PoseMode::Odometry;
  case Kind::Refined:
    return Reconstructor::PoseMode::Refine;
  case Kind::Dataset:
  case Kind::File:
    break;
  }
  return Reconstructor::PoseMode::Given;
}

PoseList PoseSource::knownPoses(const std::vector<std::size_t>& frames) const {
  PoseList known;
  if (kind_ == Kind::Estimated)
    return known;
  const PoseList& all = kind_ == Kind::File ? file_poses_ : source_.poses();
  for (std::size_t i : frames)
    known.push_back(all.at(i));
  return known;
}

} // namespace msf
