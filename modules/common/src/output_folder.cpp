// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/output_folder.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <set>
#include <system_error>

#include <fcntl.h>    // open, AT_FDCWD
#include <stdio.h>    // renameat2, RENAME_EXCHANGE
#include <sys/file.h> // flock
#include <unistd.h>

namespace fs = std::filesystem;

namespace msf {

namespace {

constexpr const char* kManifest = ".msf_manifest";
constexpr const char* kStagingLock = ".msf_staging";

std::string errnoText(int error) { return std::strerror(error); }

/// Every file and folder under `root`, relative, folders with a trailing '/', symbolic links
/// not followed; sorted.
std::vector<std::string> entriesUnder(const fs::path& root) {
  std::vector<std::string> entries;
  std::error_code ec;
  fs::recursive_directory_iterator it(root, fs::directory_options::none, ec), end;
  if (ec)
    throw IOError("cannot list folder '" + root.string() + "': " + ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec)
      throw IOError("cannot list folder '" + root.string() + "': " + ec.message());
    const std::string rel = it->path().lexically_relative(root).generic_string();
    const bool is_dir = it->is_directory(ec) && !it->is_symlink(ec);
    entries.push_back(is_dir ? rel + "/" : rel);
  }
  std::sort(entries.begin(), entries.end());
  return entries;
}

/// The entries an earlier output's manifest lists; throws IOError when it cannot be read.
std::set<std::string> readManifest(const fs::path& folder) {
  std::ifstream in(folder / kManifest);
  if (!in)
    throw IOError("cannot read the manifest '" + (folder / kManifest).string() + "'");
  std::set<std::string> listed;
  std::string line;
  while (std::getline(in, line))
    if (!line.empty() && line[0] != '#')
      listed.insert(line);
  return listed;
}

bool isInside(const fs::path& inner, const fs::path& outer) {
  const auto rel = inner.lexically_relative(outer);
  return !rel.empty() && *rel.begin() != "..";
}

} // namespace

const char* OutputFolder::manifestName() { return kManifest; }

void OutputFolder::requireOwnOutput(const std::string& folder, const std::string& tool) {
  std::error_code ec;
  const fs::path root(folder);
  if (!fs::exists(fs::symlink_status(root, ec)))
    return;
  // A run puts its folder in the link's place: the link would be replaced, not followed.
  if (fs::is_symlink(fs::symlink_status(root, ec)))
    throw IOError("output folder '" + folder + "' is a symbolic link (to '" + fs::read_symlink(root, ec).string() +
                      "'), which the run's folder would replace: give the folder it points to",
                  folder, ENOTDIR);
  if (!fs::is_directory(root, ec))
    throw IOError("output folder '" + folder + "' exists and is not a folder", folder, ENOTDIR);
  const std::vector<std::string> entries = entriesUnder(root);
  if (entries.empty())
    return;
  const auto advice = "; " + tool + " writes only into a new or empty folder, or one an earlier run wrote: choose another";
  if (!fs::is_regular_file(root / kManifest, ec))
    throw IOError("output folder '" + folder + "' holds '" + entries.front() + "' and is not an output of msfusion (no " +
                  kManifest + ")" + advice);
  const std::set<std::string> listed = readManifest(root);
  for (const std::string& entry : entries)
    if (entry != kManifest && !listed.count(entry))
      throw IOError("output folder '" + folder + "' holds '" + entry + "', which no earlier run wrote there" + advice);
}

OutputFolder::OutputFolder(const std::string& path, const std::string& tool, const std::vector<std::string>& inputs)
    : tool_(tool) {
  if (path.empty())
    throw IOError("no output folder given");
  fs::path target = fs::absolute(path).lexically_normal();
  if (target.filename().empty())
    target = target.parent_path();
  target_ = target.string();
  const fs::path parent = target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(parent, ec))
    throw IOError("output folder '" + path + "': its parent folder '" + parent.string() + "' does not exist",
                  parent.string(), ENOENT);
  if (::access(parent.c_str(), W_OK) != 0)
    throw IOError("output folder '" + path + "': its parent folder '" + parent.string() + "' is not writable: " +
                      errnoText(errno),
                  parent.string(), errno);
  const fs::path real_target = fs::weakly_canonical(target, ec);
  for (const std::string& input : inputs) {
    if (input.empty())
      continue;
    const fs::path real_input = fs::weakly_canonical(fs::absolute(input), ec);
    if (real_input == real_target || isInside(real_input, real_target))
      throw IOError("input '" + input + "' lies inside the output folder '" + path + "', which the run replaces: " +
                    "move it out or choose another output folder");
  }
  requireOwnOutput(target_, tool_);
  removeStaleStaging();
  static std::atomic<unsigned> count{0}; // two outputs of one process to one target
  staging_ = (parent / ("." + target.filename().string() + ".partial." + std::to_string(::getpid()) + "." +
                        std::to_string(count++)))
                 .string();
  if (!fs::create_directory(staging_, ec))
    throw IOError("cannot create the staging folder '" + staging_ + "': " +
                  (ec ? ec.message() : std::string("it exists")));
  lockStaging();
}

OutputFolder::~OutputFolder() {
  if (lock_fd_ >= 0)
    ::close(lock_fd_);
  if (!committed_ && !staging_.empty()) {
    std::error_code ec;
    fs::remove_all(staging_, ec);
  }
}

void OutputFolder::lockStaging() {
  const std::string lock = (fs::path(staging_) / kStagingLock).string();
  lock_fd_ = ::open(lock.c_str(), O_CREAT | O_RDWR | O_CLOEXEC, 0600);
  if (lock_fd_ < 0 || ::flock(lock_fd_, LOCK_EX | LOCK_NB) != 0)
    throw IOError("cannot lock the staging folder '" + staging_ + "': " + errnoText(errno));
}

void OutputFolder::removeStaleStaging() const {
  const fs::path target(target_);
  const std::string prefix = "." + target.filename().string() + ".partial.";
  std::error_code ec;
  for (const auto& e : fs::directory_iterator(target.parent_path(), ec)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) != 0 || !e.is_directory(ec))
      continue;
    // Ours, and its run gone: a living run holds the lock of its staging folder.
    const int fd = ::open((e.path() / kStagingLock).c_str(), O_RDONLY | O_CLOEXEC);
    if (fd < 0)
      continue;
    const bool stale = ::flock(fd, LOCK_EX | LOCK_NB) == 0;
    if (stale)
      fs::remove_all(e.path(), ec);
    ::close(fd);
  }
}

void OutputFolder::commit() {
  if (committed_)
    throw IOError("output folder '" + target_ + "' was already committed");
  requireOwnOutput(target_, tool_); // again: something may have been put there during the run
  const fs::path staging(staging_), target(target_);
  std::error_code ec;
  fs::remove(staging / kStagingLock, ec); // the lock stays held on the open descriptor

  // The manifest: every entry this run wrote.
  {
    const std::string path = (staging / kManifest).string();
    std::ofstream out(path);
    out << "# msfusion output of " << tool_ << ": the entries below were written by it, and a later run replaces them\n";
    for (const std::string& entry : entriesUnder(staging))
      if (entry != kManifest)
        out << entry << "\n";
    out.close();
    if (!out)
      throw IOError("cannot write the manifest '" + path + "': " + errnoText(errno));
  }

  const bool replace = fs::exists(fs::symlink_status(target, ec));
  std::set<std::string> earlier;
  if (replace && fs::is_regular_file(target / kManifest, ec))
    earlier = readManifest(target);
  if (!replace) {
    if (::rename(staging_.c_str(), target_.c_str()) != 0)
      throw IOError("cannot rename '" + staging_ + "' to '" + target_ + "': " + errnoText(errno));
    committed_ = true;
    return;
  }
  if (::renameat2(AT_FDCWD, staging_.c_str(), AT_FDCWD, target_.c_str(), RENAME_EXCHANGE) != 0)
    throw IOError("cannot replace '" + target_ + "' by '" + staging_ + "': " + errnoText(errno));
  committed_ = true;
  // The staging path now holds the earlier output: remove what its manifest lists, deepest
  // first, and nothing else.
  earlier.insert(kManifest);
  for (auto it = earlier.rbegin(); it != earlier.rend(); ++it) {
    const fs::path p = staging / *it;
    if (it->back() == '/')
      ::rmdir(p.c_str()); // only when empty
    else
      fs::remove(p, ec);
  }
  if (::rmdir(staging_.c_str()) != 0) {
    const fs::path kept = target.parent_path() / ("." + target.filename().string() + ".kept." + std::to_string(::getpid()));
    fs::rename(staging, kept, ec);
    pcl::console::print_warn("the earlier output of '%s' held entries its manifest does not list (put there during "
                             "the run): they are kept in '%s'\n", target_.c_str(), kept.string().c_str());
  }
}

} // namespace msf
