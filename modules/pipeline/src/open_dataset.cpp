// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/io/folder_source.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/open_dataset.h>
#ifdef MSF_WITH_ROS
#include <msf/ros/bag_source.h>
#endif

#include <fstream>

namespace msf {

bool isRosBag(const std::string& path) {
  std::ifstream file(path, std::ios::binary);
  char magic[9] = {};
  return file.read(magic, sizeof magic) && std::string(magic, sizeof magic) == "#ROSBAG V";
}

std::unique_ptr<FrameSource> openDataset(const std::string& path, const DatasetOptions& options) {
  if (isRosBag(path)) {
#ifdef MSF_WITH_ROS
    return std::make_unique<BagSource>(path, options.bag, options.rig);
#else
    throw IOError("'" + path + "' is a ROS bag, and this build has no ROS module (install ROS 1 with `make deps` "
                  "and build again; CMake option MSF_BUILD_ROS)");
#endif
  }
  if (!options.bag.isDefault())
    throw InvalidInputError("bag topics and frames are for a ROS bag, and '" + path + "' is not one");
  if (FolderSource::looksLikeOne(path))
    return std::make_unique<FolderSource>(path, options.rig);
  return std::make_unique<Sequence>(path, options.rig);
}

} // namespace msf
