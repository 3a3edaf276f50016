// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "test_support.h"

#include <msf/common/exceptions.h>

#include <array>
#include <cerrno>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <sys/mount.h>
#include <sys/wait.h>

namespace fs = std::filesystem;

namespace msf::test {

std::string kittiDir() {
  const char* env = std::getenv("MSF_KITTI_DIR");
  const std::string dir = env ? env : "../shared/data/kitti";
  std::error_code ec;
  if (fs::is_directory(fs::path(dir) / "odometry", ec))
    return fs::absolute(dir).lexically_normal().string();
  return "";
}

bool underCi() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

std::string binDir() {
  const char* env = std::getenv("MSF_BIN_DIR");
  return env ? env : MSF_TEST_BIN_DIR;
}

std::string sourceDir() {
  const char* env = std::getenv("MSF_SOURCE_DIR");
  return env ? env : MSF_TEST_SOURCE_DIR;
}

TempDir::TempDir() {
  std::random_device rd;
  for (int attempt = 0; attempt < 100; ++attempt) {
    const fs::path p = fs::temp_directory_path() / ("msf_test_" + std::to_string(rd()));
    if (fs::create_directory(p)) {
      path_ = p.string();
      return;
    }
  }
  throw std::runtime_error("cannot create a temporary folder");
}

TempDir::~TempDir() {
  std::error_code ec;
  fs::remove_all(path_, ec);
}

FullFilesystem::FullFilesystem(std::size_t free_bytes, std::size_t size_bytes) {
  const std::string mount_point = dir_.file("fs");
  fs::create_directory(mount_point);
  if (::mount("tmpfs", mount_point.c_str(), "tmpfs", 0, ("size=" + std::to_string(size_bytes)).c_str()) != 0) {
    why_ = std::strerror(errno);
    return;
  }
  mounted_ = true;
  // The filler takes all but free_bytes (tmpfs counts whole pages).
  std::ofstream filler(file(".filler"), std::ios::binary);
  const std::string page(4096, 'x');
  for (std::size_t used = 0; used + free_bytes + page.size() <= size_bytes && filler.write(page.data(), page.size());)
    used += page.size();
}

FullFilesystem::~FullFilesystem() {
  if (mounted_)
    ::umount2(dir_.file("fs").c_str(), MNT_DETACH);
}

std::size_t FullFilesystem::countEntries() const {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir_.file("fs")))
    n += e.path().filename() != ".filler";
  return n;
}

namespace {
std::string slurp(const fs::path& p) {
  std::ifstream in(p);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}
} // namespace

CommandResult runCommand(const std::string& command_line) {
  TempDir capture;
  const std::string out = capture.file("out"), err = capture.file("err");
  const std::string full = command_line + " >" + out + " 2>" + err + " </dev/null";
  const int status = std::system(full.c_str());
  CommandResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(out);
  r.err = slurp(err);
  expectNoSanitizerReport(r.err, command_line);
  return r;
}

std::string sanitizerReport(const std::string& output, std::size_t max_lines) {
  // The lines that open a report of GCC's and Clang's sanitizers (compiler-rt's formats).
  static const std::regex opening(
      R"(==[0-9]+==ERROR: [A-Za-z]*Sanitizer|: runtime error: |WARNING: ThreadSanitizer: )");
  std::istringstream in(output);
  std::string line, report;
  std::size_t lines = 0;
  while (std::getline(in, line)) {
    if (lines == 0 && !std::regex_search(line, opening))
      continue;
    report += line + "\n";
    if (++lines == max_lines)
      break;
  }
  while (report.size() > 1 && report[report.size() - 2] == '\n') // no blank lines at the end
    report.pop_back();
  return report;
}

void expectNoSanitizerReport(const std::string& output, const std::string& what) {
  const std::string report = sanitizerReport(output);
  if (!report.empty())
    ADD_FAILURE() << "a sanitizer report in the output of `" << what << "`:\n" << report;
}

CommandResult runTool(const std::string& tool, const std::string& arguments) {
  return runCommand(binDir() + "/" + tool + " " + arguments);
}

bool fileExists(const std::string& path) { return fs::exists(path); }

std::size_t countEntries(const std::string& folder) {
  std::size_t n = 0;
  for ([[maybe_unused]] const auto& entry : fs::directory_iterator(folder))
    ++n;
  return n;
}

std::string errorOf(const std::function<void()>& call) {
  try {
    call();
  } catch (const msf::Error& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace msf::test
