// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <gtest/gtest.h>

#include <cstddef>
#include <functional>
#include <string>

namespace msf::test {

/// Root of the KITTI sample (../shared/data/kitti or $MSF_KITTI_DIR); "" when absent.
std::string kittiDir();

/// True when running under CI (CI=true), where a missing KITTI sample is a failure.
bool underCi();

/// Folder of the msf_* tools (build/bin, or $MSF_BIN_DIR).
std::string binDir();

/// Root of the source tree (config/, README.md), or $MSF_SOURCE_DIR.
std::string sourceDir();

/// A fresh empty folder, removed with its contents when the object goes away.
class TempDir {
public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

private:
  std::string path_;
};

/// A small filesystem of its own (a tmpfs mounted on a fresh folder, unmounted when the object
/// goes away), filled to `free_bytes` of free space, for writes that meet a full disk as they
/// would a real one. Mounting needs root: mounted() is false otherwise, with why().
class FullFilesystem {
public:
  explicit FullFilesystem(std::size_t free_bytes = 0, std::size_t size_bytes = 256 * 1024);
  ~FullFilesystem();
  FullFilesystem(const FullFilesystem&) = delete;
  FullFilesystem& operator=(const FullFilesystem&) = delete;
  bool mounted() const { return mounted_; }
  const std::string& why() const { return why_; }
  std::string file(const std::string& name) const { return dir_.file("fs/" + name); }
  /// The entries of the filesystem other than the filler.
  std::size_t countEntries() const;

private:
  TempDir dir_;
  bool mounted_ = false;
  std::string why_;
};

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

/// Runs a shell command line; captures its exit code, stdout and stderr. A sanitizer report
/// in its stderr (see sanitizerReport) fails the calling test, quoting the report, whatever
/// the exit code: under `make test-sanitize` a sanitizer that stops a tool exits as an error
/// does, which a test that expects a failure would otherwise accept.
CommandResult runCommand(const std::string& command_line);

/// Runs build/bin/<tool> with `arguments` (already quoted as needed); as runCommand.
CommandResult runTool(const std::string& tool, const std::string& arguments);

/// The first sanitizer report in a process's output: from the line that opens it
/// ("==PID==ERROR: AddressSanitizer: ...", "... LeakSanitizer: ...", "...
/// UndefinedBehaviorSanitizer: ...", UBSan's "file:line:col: runtime error: ...", "WARNING:
/// ThreadSanitizer: ...") up to `max_lines` lines; "" when there is none.
std::string sanitizerReport(const std::string& output, std::size_t max_lines = 12);

/// Fails the calling test (ADD_FAILURE) when `output` holds a sanitizer report, quoting it and
/// naming `what` (the command that printed it).
void expectNoSanitizerReport(const std::string& output, const std::string& what);

bool fileExists(const std::string& path);

/// The message of the msf::Error that `call` throws, or "(no error)": tests of hostile inputs
/// check that the message names the option, key or file at fault.
std::string errorOf(const std::function<void()>& call);

/// Number of entries in a folder (to check that a failed tool left no file behind).
std::size_t countEntries(const std::string& folder);

} // namespace msf::test

/// Declares `name`, a FullFilesystem(free_bytes), at the start of a test: skips when it cannot be
/// mounted (not root), but fails under CI=true, which runs as root.
#define MSF_FULL_FILESYSTEM(name, free_bytes)                                                 \
  ::msf::test::FullFilesystem name(free_bytes);                                               \
  do {                                                                                        \
    if (!name.mounted()) {                                                                    \
      if (::msf::test::underCi())                                                             \
        FAIL() << "cannot mount a small tmpfs (" << name.why() << "); CI=true requires it";  \
      GTEST_SKIP() << "cannot mount a small tmpfs (" << name.why() << "): needs root";        \
    }                                                                                         \
  } while (0)

/// Use at the start of a test that needs the real KITTI sample: skips when it is absent,
/// but fails under CI=true, so CI never passes by skipping.
#define MSF_REQUIRE_KITTI()                                                                   \
  do {                                                                                        \
    if (::msf::test::kittiDir().empty()) {                                                    \
      if (::msf::test::underCi())                                                             \
        FAIL() << "KITTI sample not found (set MSF_KITTI_DIR); CI=true requires it";          \
      GTEST_SKIP() << "KITTI sample not found (set MSF_KITTI_DIR)";                           \
    }                                                                                         \
  } while (0)
