#include <msf/common/exceptions.h>
#include <msf/pipeline/pose_source.h>

#include <chrono>

namespace msf {

PoseSource::PoseSource(const std::string& option, const Sequence& sequence, const std::vector<std::size_t>& frames,
                       const LidarOdometry::Config& odometry)
    : sequence_(sequence) {
  const std::string choice = option.empty() ? (sequence.hasPoses() ? "dataset" : "estimate") : option;
  if (choice == "dataset") {
    if (!sequence.hasPoses())
      throw InvalidInputError("-poses dataset: sequence '" + sequence.directory() +
                              "' has no poses (odometry poses/XX.txt or raw oxts/); -poses estimate tracks them "
                              "from the scans");
    kind_ = Kind::Dataset;
    description_ = "the dataset's: " + sequence.posesName();
  } else if (choice == "estimate") {
    kind_ = Kind::Estimated;
    description_ = "estimated (LiDAR odometry)";
    odometry_ = std::make_unique<LidarOdometry>(resolveDeskew(odometry, sequence));
    if (sequence.hasPoses() && !frames.empty())
      T_world_cam0_first_ = sequence.poses()[frames.front()];
  } else {
    kind_ = Kind::File;
    description_ = "file '" + choice + "'";
    file_poses_ = loadOdometryPoses(choice);
    for (std::size_t i : frames)
      if (i >= file_poses_.size())
        throw InvalidInputError("-poses '" + choice + "' has " + std::to_string(file_poses_.size()) +
                                " poses (line i is frame i) and no pose for frame " + std::to_string(i));
  }
}

PoseSource::~PoseSource() = default;

void PoseSource::apply(Frame& frame) const {
  if (kind_ != Kind::File)
    return;
  frame.T_world_cam0 = file_poses_.at(frame.index);
  frame.has_pose = true;
}

PoseList PoseSource::knownPoses(const std::vector<std::size_t>& frames) const {
  PoseList known;
  if (kind_ == Kind::Estimated)
    return known;
  const PoseList& all = kind_ == Kind::File ? file_poses_ : sequence_.poses();
  for (std::size_t i : frames)
    known.push_back(all.at(i));
  return known;
}

Eigen::Isometry3d PoseSource::estimate(const Frame& frame) {
  if (!odometry_)
    throw InvalidInputError("PoseSource::estimate: the poses are " + description_ + ", not estimated");
  const auto start = std::chrono::steady_clock::now();
  const Eigen::Isometry3d T_velo0_velo =
      odometry_->registerScan(*frame.scan, "scan '" + sequence_.scanPath(frame.index) + "'");
  estimate_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  return cameraPose(T_velo0_velo, sequence_.calibration().T_cam0_velo, T_world_cam0_first_);
}

} // namespace msf
