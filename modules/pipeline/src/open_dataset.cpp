#include <msf/common/exceptions.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/open_dataset.h>

namespace msf {

std::unique_ptr<FrameSource> openDataset(const std::string& path, const DatasetOptions& options) {
  if (!options.rig.empty())
    throw InvalidInputError("a rig file is not read for KITTI and synthetic datasets, which carry their calibration: "
                            "'" + options.rig + "'");
  return std::make_unique<Sequence>(path);
}

} // namespace msf
