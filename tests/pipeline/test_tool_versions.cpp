// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Every tool of tools/ answers --version and ends its help with the same line. A pipeline
// test: it runs every tool, which only a whole build has (a sanitizer subset builds a few).
#include <msf/common/version.h>

#include "test_support.h"

#include <filesystem>
#include <string>

namespace fs = std::filesystem;

namespace {

TEST(ToolVersion, EveryToolPrintsItOnVersionAndAtTheEndOfItsHelp) {
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
