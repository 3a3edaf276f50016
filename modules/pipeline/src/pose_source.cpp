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
    description_ = !sequence.groundTruthDir().empty()            ? "dataset (synthetic ground truth)"
                   : sequence.layout() == Sequence::Layout::Raw ? "dataset (OXTS)"
                                                                 : "dataset (odometry poses file)";
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

void PoseSource::apply(Frame& frame) {
  if (kind_ == Kind::Dataset)
    return; // Sequence::load set it
  if (kind_ == Kind::File) {
    frame.T_world_cam0 = file_poses_.at(frame.index);
  } else {
    const auto start = std::chrono::steady_clock::now();
    const Eigen::Isometry3d T_velo0_velo =
        odometry_->registerScan(*frame.scan, "scan '" + sequence_.scanPath(frame.index) + "'");
    frame.T_world_cam0 = cameraPose(T_velo0_velo, sequence_.calibration().T_cam0_velo, T_world_cam0_first_);
    estimate_ms_.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
  }
  frame.has_pose = true;
}

} // namespace msf
