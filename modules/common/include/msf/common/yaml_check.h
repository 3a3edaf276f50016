// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <string>

namespace msf {

/// Throws IOError ("<what> '<path>' is not valid YAML: line N: ...") when the top level of the
/// YAML file at `path` does not start at column 0 of its own line (after directives, `---`,
/// blank and comment lines). OpenCV 4.6's parser loops forever on some files whose top level is
/// indented, e.g. "%YAML:1.0\n k: 4\na: -\n" or "--- k: 4\na: -" (fuzz/fuzz_calibration); every
/// YAML file of ours and OpenCV's writer starts its top level at column 0. Called before
/// cv::FileStorage reads a file a user gives (a .yaml calibration; configuration files are
/// read with yaml-cpp, msf/common/yaml_file.h).
void requireYamlTopLevelAtColumnZero(const std::string& path, const std::string& what);

} // namespace msf
