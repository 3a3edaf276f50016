// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/tool.h>
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

TEST(Version, EveryToolPrintsItOnVersionAndAtTheEndOfItsHelp) {
  const std::string line = std::string("(msfusion) ") + msf::versionString() + ", commit " + msf::gitCommit();
  std::size_t tools = 0;
  for (const auto& e : fs::directory_iterator(fs::path(msf::test::sourceDir()) / "tools")) {
    const std::string name = e.path().stem().string();
    if (name.rfind("msf_", 0) != 0 || e.path().extension() != ".cpp")
      continue;
    ++tools;
    const auto version = msf::test::runTool(name, "--version");
    EXPECT_EQ(version.exit_code, 0) << name;
    EXPECT_EQ(version.out, name + " " + line + "\n") << name;
    const auto help = msf::test::runTool(name, "-h");
    EXPECT_EQ(help.exit_code, 0) << name;
    EXPECT_NE(help.out.find(name + " " + line), std::string::npos) << name << ": " << help.out;
  }
  EXPECT_GE(tools, 16u);
}

} // namespace
