// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>

#include <algorithm>
#include <cerrno>
#include <atomic>
#include <filesystem>
#include <system_error>
#include <unistd.h>

namespace fs = std::filesystem;

namespace msf {

std::string fileExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

void requireFile(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::exists(path, ec))
    throw IOError(what + " '" + path + "' does not exist", path, ENOENT);
  if (!fs::is_regular_file(path, ec))
    throw IOError(what + " '" + path + "' is not a regular file", path, fs::is_directory(path, ec) ? EISDIR : EINVAL);
}

void requireDirectory(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (!fs::is_directory(path, ec))
    throw IOError(what + " '" + path + "' does not exist or is not a directory", path,
                  fs::exists(path, ec) ? ENOTDIR : ENOENT);
}

std::vector<std::string> filesIn(const std::string& dir, const std::vector<std::string>& extensions,
                                 const std::string& what) {
  requireDirectory(dir, what);
  std::vector<std::string> found;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.is_regular_file() &&
        std::find(extensions.begin(), extensions.end(), fileExtension(e.path().string())) != extensions.end())
      found.push_back(e.path().string());
  std::sort(found.begin(), found.end());
  if (found.empty()) {
    std::string list;
    for (const auto& ext : extensions)
      list += (list.empty() ? "" : " or ") + ext;
    throw IOError(what + " '" + dir + "' has no " + list + " file");
  }
  return found;
}

void ensureOutputDirectory(const std::string& path) {
  std::error_code ec;
  if (fs::is_directory(path, ec))
    return;
  if (fs::exists(path, ec))
    throw IOError("output folder '" + path + "' exists and is not a directory", path, ENOTDIR);
  const fs::path parent = fs::absolute(path).lexically_normal().parent_path();
  if (!fs::is_directory(parent, ec))
    throw IOError("output folder '" + path + "': its parent '" + parent.string() + "' does not exist", parent.string(),
                  ENOENT);
  if (!fs::create_directory(path, ec) && !fs::is_directory(path))
    throw IOError("cannot create output folder '" + path + "': " + ec.message(), path, ec.value());
}

namespace {

/// The folder a file `path` goes into.
fs::path folderOf(const fs::path& path) { return path.has_parent_path() ? path.parent_path() : fs::path("."); }

} // namespace

void requireWritableFolder(const std::string& path) {
  const fs::path dir = folderOf(path);
  std::error_code ec;
  if (!fs::is_directory(dir, ec))
    throw IOError("cannot write '" + path + "': output folder '" + dir.string() + "' does not exist", dir.string(),
                  ENOENT);
  if (::access(dir.c_str(), W_OK) != 0)
    throw IOError("cannot write '" + path + "': output folder '" + dir.string() + "' is not writable", dir.string(),
                  EACCES);
}

void writeAtomically(const std::string& path, const std::function<void(const std::string&)>& write) {
  requireWritableFolder(path);
  const fs::path target(path), dir = folderOf(target);
  std::error_code ec;

  static std::atomic<unsigned> counter{0};
  const fs::path tmp = dir / ("." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                              std::to_string(counter++) + target.extension().string());
  try {
    write(tmp.string());
  } catch (...) {
    fs::remove(tmp, ec);
    throw;
  }
  if (!fs::is_regular_file(tmp, ec)) {
    fs::remove(tmp, ec);
    throw IOError("cannot write '" + path + "': the writer produced no file");
  }
  fs::rename(tmp, target, ec);
  if (ec) {
    const std::string reason = ec.message(); // before the cleanup overwrites ec
    fs::remove(tmp, ec);
    throw IOError("cannot write '" + path + "': rename failed: " + reason);
  }
}

} // namespace msf
