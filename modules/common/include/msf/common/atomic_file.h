// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <functional>
#include <string>
#include <vector>

namespace msf {

/// Writes `path` through a temporary file in the same folder and a rename, so a reader
/// never sees a partial file and a failed write leaves nothing behind.
/// `write` receives the temporary path and must create it (it may throw; the temporary
/// is then removed). The temporary keeps the extension of `path`, so writers that pick
/// a format by extension (PCL, OpenCV) still work.
/// Throws IOError naming the folder if it does not exist or is not writable, and naming
/// the file if `write` did not produce it.
void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write);

/// Throws IOError naming `path` and its folder when the folder does not exist or is not
/// writable: what writeAtomically checks first, for a tool to check before its work.
void requireWritableFolder(const std::string& path);

/// Throws IOError if `path` is not an existing regular file; `what` names its role ("scan").
void requireFile(const std::string& path, const std::string& what = "file");

/// Throws IOError if `path` is not an existing directory.
void requireDirectory(const std::string& path, const std::string& what = "folder");

/// An output folder: created when missing, if its parent exists (a typo in the parent
/// should not scatter new folders). Throws IOError naming the folder or its parent.
void ensureOutputDirectory(const std::string& path);

/// Lower-case extension of `path` with its dot (".pcd"), or "" when there is none.
std::string fileExtension(const std::string& path);

/// The regular files of folder `dir` whose fileExtension is one of `extensions` (".pcd"), in
/// name order. Throws IOError naming `what` ("input folder") when `dir` is not a folder or
/// holds no such file.
std::vector<std::string> filesIn(const std::string& dir, const std::vector<std::string>& extensions,
                                 const std::string& what = "folder");

} // namespace msf
