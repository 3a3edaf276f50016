// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The project's configuration files: made from the keys' declarations, read whole by every tool.
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/pipeline/config_catalog.h>
#include <msf/pipeline/config_documents.h>
#include <msf/pipeline/pipeline_config.h>

#include "test_support.h"

#include <filesystem>
#include <fstream>
#include <sstream>

namespace {

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

template <class Config>
std::string printed(const Config& config) {
  std::ostringstream out;
  msf::printConfig(out, config);
  return out.str();
}

TEST(ConfigFiles, TheShippedFilesAndTheReferenceAreMadeFromTheDeclarations) {
  // `make config-files` (msf_config -write .) makes them; an edit of a key's default, range or
  // meaning in the code without it fails here.
  for (const std::string& name : msf::shippedConfigNames())
    EXPECT_EQ(readFile(msf::test::sourceDir() + "/config/" + name + ".yaml"), msf::shippedConfigText(name))
        << "config/" << name << ".yaml is not what make config-files writes";
  EXPECT_EQ(readFile(msf::test::sourceDir() + "/docs/configuration.md"), msf::configurationReference())
      << "docs/configuration.md is not what make config-files writes";
}

TEST(ConfigFiles, TheShippedFilesHoldEveryKeyAtItsDefault) {
  const msf::ConfigFile synthetic = msf::openConfigFile(msf::test::sourceDir() + "/config/synthetic.yaml");
  const msf::ConfigFile kitti = msf::openConfigFile(msf::test::sourceDir() + "/config/kitti.yaml");
  EXPECT_EQ(synthetic.sections(), msf::configSectionNames());
  std::vector<std::string> kitti_sections;
  msf::forEachConfigSection([&](const auto& defaults) {
    using Config = std::decay_t<decltype(defaults)>;
    const std::string name = defaults.kSection;
    EXPECT_EQ(printed(synthetic.get<Config>()), printed(defaults)) << name;
    EXPECT_EQ(printed(kitti.get<Config>()), printed(defaults)) << name;
    // Each key's meaning above it, with its range.
    const std::string file = readFile(msf::test::sourceDir() + "/config/synthetic.yaml");
    for (const msf::KeyText& key : msf::listKeys(defaults))
      EXPECT_NE(file.find(key.meaning.substr(0, 20)), std::string::npos) << name << "." << key.name;
    if (name != "synthetic" && name != "lambda_study")
      kitti_sections.push_back(name);
  });
  EXPECT_EQ(kitti.sections(), kitti_sections);
}

TEST(ConfigFiles, EveryKeyIsDocumentedWithItsDefaultRangeAndMeaning) {
  const std::string reference = msf::configurationReference();
  std::size_t keys = 0;
  msf::forEachConfigSection([&](const auto& defaults) {
    for (const msf::KeyText& key : msf::listKeys(defaults)) {
      EXPECT_FALSE(key.meaning.empty()) << defaults.kSection << "." << key.name;
      EXPECT_NE(reference.find("| `" + std::string(defaults.kSection) + "` | `" + key.name + "` | `"), std::string::npos)
          << defaults.kSection << "." << key.name;
      ++keys;
    }
  });
  EXPECT_GT(keys, 150u);
  EXPECT_NE(reference.find("| `stereo` | `block_size_px` | `5` | 1..11 | matched block's side, px (odd) |"),
            std::string::npos);
  EXPECT_NE(reference.find("| `fusion` | `method` | `uncertainty` | uncertainty \\| paper |"), std::string::npos);
}

TEST(ConfigFiles, AMisspeltSectionIsRefusedLikeAMisspeltKey) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("typo.yaml")) << "tsdf_volume:\n  voxel_size_m: 0.2\ntsdf_volumes:\n  voxel_size_m: 0.05\n";
  const std::string e = msf::test::errorOf([&] { msf::PipelineConfig::load(dir.file("typo.yaml")); });
  EXPECT_EQ(e.rfind("config '" + dir.file("typo.yaml") + "' line 3: 'tsdf_volumes' is not a section of the "
                                                         "configuration (its sections: synthetic, projection, ",
                    0),
            0u)
      << e;
  // Every tool, whatever section it reads: msf_mesh reads marching_cubes only.
  const auto r = msf::test::runTool("msf_mesh", "in.pcd out.ply -config " + dir.file("typo.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("msf_mesh: error: config '" + dir.file("typo.yaml") + "' line 3: 'tsdf_volumes' is not a "
                                                                              "section"),
            std::string::npos)
      << r.err;
}

TEST(ConfigFiles, AToolChecksTheWholeFileNotOnlyItsSections) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("bad.yaml")) << "marching_cubes:\n  min_weight: 2\nfusion:\n  lidar_sigma_px: -1\n";
  const auto r = msf::test::runTool("msf_mesh", "in.pcd out.ply -config " + dir.file("bad.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("config '" + dir.file("bad.yaml") + "' line 4: fusion.lidar_sigma_px must be a finite number "
                                                            "> 0, not -1"),
            std::string::npos)
      << r.err;
}

TEST(ConfigFiles, AnIntegerBeyondItsRangeIsAnErrorNotAWrap) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("threads.yaml")) << "interpolation:\n  threads: 4294967297\n";
  const auto r = msf::test::runTool("msf_reconstruct", dir.path() + " -config " + dir.file("threads.yaml"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("line 2: interpolation.threads must be a whole number in 0..256, not 4294967297"),
            std::string::npos)
      << r.err;
}

TEST(ConfigFiles, AnErrorBetweenTwoKeysNamesTheLineOfTheKey) {
  const std::string e = msf::test::errorOf([] {
    msf::PipelineConfig config;
    config.read(msf::openConfigText("# c\nstereo:\n  block_size_px: 5\n  p1: 900\n  p2: 100\n", "c.yaml"));
  });
  EXPECT_EQ(e, "config 'c.yaml' line 5: stereo.p2 must be greater than p1 (100 <= 900)");
  const std::string camera = msf::test::errorOf([] {
    msf::PipelineConfig config;
    config.read(msf::openConfigText("projection:\n  camera: 2\n", "c.yaml"));
  });
  EXPECT_EQ(camera.rfind("config 'c.yaml' line 2: projection.camera is 2: the pipeline fuses", 0), 0u) << camera;
}

TEST(ConfigFiles, MsfConfigPrintsWhatAFileGivesAndWritesTheFiles) {
  msf::test::TempDir dir;
  std::ofstream(dir.file("c.yaml")) << "tsdf_integrator:\n  lambda: 5\n";
  auto r = msf::test::runTool("msf_config", "-config " + dir.file("c.yaml"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  msf::PipelineConfig expected;
  expected.integrator.lambda = 5;
  std::ostringstream text;
  expected.print(text);
  EXPECT_EQ(r.out, text.str());
  r = msf::test::runTool("msf_config", "-paper");
  std::ostringstream paper;
  msf::PipelineConfig::paper().print(paper);
  EXPECT_EQ(r.out, paper.str());
  // -write: the repository's files, each through a temporary and a rename.
  std::filesystem::create_directories(dir.file("repo/config"));
  std::filesystem::create_directories(dir.file("repo/docs"));
  r = msf::test::runTool("msf_config", "-write " + dir.file("repo"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const std::string& name : msf::shippedConfigNames())
    EXPECT_EQ(readFile(dir.file("repo/config/" + name + ".yaml")), msf::shippedConfigText(name)) << name;
  EXPECT_EQ(readFile(dir.file("repo/docs/configuration.md")), msf::configurationReference());
  r = msf::test::runTool("msf_config", "-write " + dir.file("nowhere"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("nowhere/config"), std::string::npos) << r.err;
}

} // namespace
