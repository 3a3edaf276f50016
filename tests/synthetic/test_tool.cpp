// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// msf_synth: writes a dataset; bad input is an error naming the culprit, with no output.
#include "test_support.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>

namespace fs = std::filesystem;

namespace {

using msf::test::runTool;

TEST(MsfSynth, WritesADatasetOtherToolsCanRead) {
  msf::test::TempDir dir;
  const auto r = runTool("msf_synth", "-o " + dir.file("ds") + " -frames 1 -seed 5 -print_config");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("Wrote"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("seed: 5"), std::string::npos) << r.out;
  for (const char* f : {"sequences/00/calib.txt", "sequences/00/image_0/000000.png", "sequences/00/image_3/000000.png",
                        "sequences/00/velodyne/000000.bin", "poses/00.txt", "gt/depth_0/000000.png",
                        "gt/disp_0/000000.png", "gt/obj_map_0/000000.png", "gt/scene.ply"})
    EXPECT_TRUE(fs::is_regular_file(fs::path(dir.file("ds")) / f)) << f;
}

TEST(MsfSynth, HelpExitsCleanly) {
  const auto r = runTool("msf_synth", "-h");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE((r.out + r.err).find("-frames"), std::string::npos);
}

TEST(MsfSynth, BadInputIsAnErrorNamingItAndLeavesNothing) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("a_file")) << "x";
  std::ofstream(dir.file("bad.yaml")) << "%YAML:1.0\nsynthetic:\n  lidar_dropout: 2.0\n";
  const std::string out = dir.file("ds");
  struct Case {
    std::string args, expected;
  };
  const std::vector<Case> cases = {
      {"-o " + out + " -frames 0", "-frames"},
      {"-o " + out + " -frames ten", "-frames"},
      {"-o " + out + " -seed -1", "-seed"},
      {"-o " + out + " -scene moon", "moon"},
      {"-o " + out + " -framez 3", "-framez"},
      {"-frames 2", "-o"},
      {"-o " + dir.file("a_file") + "/ds", "a_file"},
      {"-o " + out + " -config " + dir.file("bad.yaml"), "synthetic.lidar_dropout"},
      {"-o " + out + " -config " + dir.file("missing.yaml"), "missing.yaml"},
  };
  for (const Case& c : cases) {
    const auto r = runTool("msf_synth", c.args);
    EXPECT_NE(r.exit_code, 0) << c.args;
    EXPECT_EQ(r.err.rfind("msf_synth: error: ", 0), 0u) << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(c.expected), std::string::npos) << c.args << "\n" << r.err;
    EXPECT_EQ(msf::test::countEntries(dir.path()), 2u) << c.args << ": output left behind";
  }
}

} // namespace
