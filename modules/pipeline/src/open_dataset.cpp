// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/io/folder_source.h>
#include <msf/io/sequence.h>
#include <msf/pipeline/open_dataset.h>

namespace msf {

std::unique_ptr<FrameSource> openDataset(const std::string& path, const DatasetOptions& options) {
  if (FolderSource::looksLikeOne(path))
    return std::make_unique<FolderSource>(path, options.rig);
  return std::make_unique<Sequence>(path, options.rig);
}

} // namespace msf
