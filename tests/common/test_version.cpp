// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/version.h>

#include "test_support.h"

#include <filesystem>
#include <regex>
#include <string>

namespace fs = std::filesystem;

namespace {

TEST(Version, IsTheProjectsAndTheCommitBuiltFrom) {
  EXPECT_EQ(std::string(msf::versionString()), std::to_string(MSF_VERSION_MAJOR) + "." +
                                                   std::to_string(MSF_VERSION_MINOR) + "." +
                                                   std::to_string(MSF_VERSION_PATCH));
  const std::string commit = msf::gitCommit();
  EXPECT_TRUE(std::regex_match(commit, std::regex("[0-9a-f]{12}(-dirty)?|unknown"))) << commit;
  if (fs::exists(fs::path(msf::test::sourceDir()) / ".git")) { // a checkout or a worktree (.git a file)
    EXPECT_NE(commit, "unknown");
  }
}

} // namespace
