// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// What the pipeline's tests share: a small synthetic street made once per build, and reading
// the tools' summary.json.
#include <msf/synthetic/synthetic_generator.h>

#include <gtest/gtest.h>

#include <cmath>
#include <fcntl.h>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <sys/file.h>
#include <unistd.h>

/// A 4-frame synthetic street, generated once for all the test processes of a build (ctest
/// runs each test in its own process): in the build folder, under a file lock, so parallel
/// tests wait for the first one instead of generating it again.
class PipelineTest : public ::testing::Test {
protected:
  static void SetUpTestSuite() {
    namespace fs = std::filesystem;
    const fs::path root = fs::absolute("test_data");
    fs::create_directories(root);
    dataset_ = (root / "street_4_frames_seed_7_with_movers").string(); // the default street
    const int lock = ::open((root / "street.lock").c_str(), O_CREAT | O_RDWR, 0644);
    ASSERT_GE(lock, 0);
    ::flock(lock, LOCK_EX);
    // Written again when an older build's lacks a file that ground truth has since gained.
    if (!fs::exists(fs::path(dataset_) / "gt" / "scene.ply") ||
        !fs::exists(fs::path(dataset_) / "gt" / "scene_classes.txt")) {
      msf::synthetic::SyntheticConfig config;
      config.frames = 4;
      config.seed = 7;
      fs::remove_all(dataset_); // the tests' own street, as an older build wrote it
      msf::synthetic::SyntheticGenerator(config).writeDataset(dataset_);
    }
    ::flock(lock, LOCK_UN);
    ::close(lock);
  }
  static const std::string& dataset() { return dataset_; }
  inline static std::string dataset_;
};

inline std::string readFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The number after "key": in a JSON text (the first occurrence after `after`).
inline double jsonNumber(const std::string& json, const std::string& key, const std::string& after = "") {
  const std::size_t from = after.empty() ? 0 : json.find("\"" + after + "\"");
  std::smatch m;
  const std::string rest = json.substr(from == std::string::npos ? 0 : from);
  if (!std::regex_search(rest, m, std::regex("\"" + key + "\": (-?[0-9.eE+-]+)")))
    return std::nan("");
  return std::stod(m[1]);
}
