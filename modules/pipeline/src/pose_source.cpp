#include <msf/common/exceptions.h>
#include <msf/pipeline/pose_source.h>

namespace msf {

PoseSource::PoseSource(const std::string& option, const FrameSource& source, const std::vector<std::size_t>& frames)
    : source_(source) {
  const std::string choice = option.empty() ? (source.hasPoses() ? "dataset" : "estimate") : option;
  if (choice == "dataset") {
    if (!source.hasPoses())
      throw InvalidInputError("-poses dataset: '" + source.description() +
                              "' has no poses (odometry poses/XX.txt, raw oxts/ or a poses file of its own); "
                              "-poses estimate tracks them from the scans");
    kind_ = Kind::Dataset;
    description_ = "the dataset's: " + source.posesName();
  } else if (choice == "estimate") {
    kind_ = Kind::Estimated;
    description_ = "estimated (LiDAR odometry)";
  } else {
    kind_ = Kind::File;
    file_ = choice;
    description_ = "file '" + choice + "'";
    file_poses_ = loadOdometryPoses(choice);
    for (std::size_t i : frames)
      if (i >= file_poses_.size())
        throw InvalidInputError("-poses '" + choice + "' has " + std::to_string(file_poses_.size()) +
                                " poses (line i is frame i) and no pose for frame " + std::to_string(i));
  }
}

void PoseSource::apply(Frame& frame) const {
  if (kind_ != Kind::File)
    return;
  frame.T_world_cam0 = file_poses_.at(frame.index);
  frame.has_pose = true;
}

Reconstructor::PoseMode PoseSource::mode() const {
  return kind_ == Kind::Estimated ? Reconstructor::PoseMode::Odometry : Reconstructor::PoseMode::Given;
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
