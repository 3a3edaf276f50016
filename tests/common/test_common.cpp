#include <msf/common/atomic_file.h>
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/tool.h>

#include "test_support.h"

#include <fstream>

namespace {

void writeText(const std::string& path, const std::string& text) { std::ofstream(path) << text; }

TEST(AtomicFile, WritesThroughATemporaryAndRenames) {
  msf::test::TempDir dir;
  const std::string target = dir.file("out.txt");
  msf::writeAtomically(target, [](const std::string& tmp) {
    EXPECT_EQ(msf::fileExtension(tmp), ".txt");
    writeText(tmp, "hello");
  });
  std::ifstream in(target);
  std::string content;
  in >> content;
  EXPECT_EQ(content, "hello");
  EXPECT_EQ(msf::test::countEntries(dir.path()), 1u);
}

TEST(AtomicFile, AFailingWriterLeavesNothing) {
  msf::test::TempDir dir;
  EXPECT_THROW(msf::writeAtomically(dir.file("out.txt"),
                                    [](const std::string& tmp) {
                                      writeText(tmp, "partial");
                                      throw msf::IOError("disk full");
                                    }),
               msf::IOError);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u);
}

TEST(AtomicFile, MissingFolderIsNamed) {
  try {
    msf::writeAtomically("/nonexistent_msf_dir/out.txt", [](const std::string&) {});
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent_msf_dir"), std::string::npos) << e.what();
  }
}

TEST(AtomicFile, WriterThatProducesNoFileIsAnError) {
  msf::test::TempDir dir;
  EXPECT_THROW(msf::writeAtomically(dir.file("out.txt"), [](const std::string&) {}), msf::IOError);
  EXPECT_EQ(msf::test::countEntries(dir.path()), 0u);
}

TEST(AtomicFile, OutputFolderIsCreatedOnlyUnderAnExistingParent) {
  msf::test::TempDir dir;
  msf::ensureOutputDirectory(dir.file("out"));
  EXPECT_TRUE(msf::test::fileExists(dir.file("out")));
  msf::ensureOutputDirectory(dir.file("out")); // already there: fine
  try {
    msf::ensureOutputDirectory(dir.file("missing/out"));
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find(dir.file("missing")), std::string::npos) << e.what();
  }
  std::ofstream(dir.file("file")) << "x";
  EXPECT_THROW(msf::ensureOutputDirectory(dir.file("file")), msf::IOError);
}

TEST(Config, ReadsKeysOfASectionAndKeepsDefaults) {
  msf::test::TempDir dir;
  writeText(dir.file("c.yaml"), "%YAML:1.0\nstage:\n  gap_px: 7\n  ratio: 0.25\n  name: cubic\n  on: true\n");
  const msf::ConfigFile config(dir.file("c.yaml"));
  const cv::FileNode stage = config.section("stage");
  int gap = 3, untouched = 42;
  double ratio = 0;
  std::string name;
  bool on = false;
  msf::readKey(stage, "gap_px", gap);
  msf::readKey(stage, "ratio", ratio);
  msf::readKey(stage, "name", name);
  msf::readKey(stage, "on", on);
  msf::readKey(stage, "absent", untouched);
  EXPECT_EQ(gap, 7);
  EXPECT_DOUBLE_EQ(ratio, 0.25);
  EXPECT_EQ(name, "cubic");
  EXPECT_TRUE(on);
  EXPECT_EQ(untouched, 42);
  EXPECT_TRUE(config.section("other").empty());
}

TEST(Config, WrongTypeNamesTheKey) {
  msf::test::TempDir dir;
  writeText(dir.file("c.yaml"), "%YAML:1.0\nstage:\n  gap_px: 2.5\n  name: 3\n");
  const msf::ConfigFile config(dir.file("c.yaml"));
  int gap = 0;
  try {
    msf::readKey(config.section("stage"), "gap_px", gap);
    FAIL() << "expected ConfigError";
  } catch (const msf::ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("stage.gap_px"), std::string::npos) << e.what();
  }
  std::string name;
  EXPECT_THROW(msf::readKey(config.section("stage"), "name", name), msf::ConfigError);
}

TEST(Config, RepeatedSectionOrKeyIsAnError) {
  msf::test::TempDir dir;
  const auto expectRepeated = [&](const std::string& text, const std::string& name) {
    writeText(dir.file("c.yaml"), "%YAML:1.0\n" + text);
    try {
      msf::ConfigFile config(dir.file("c.yaml"));
      FAIL() << "no error for " << name;
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("'" + name + "' appears twice"), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find("c.yaml"), std::string::npos) << e.what();
    }
  };
  expectRepeated("stage:\n  gap_px: 7\nother:\n  a: 1\nstage:\n  gap_px: 9\n", "stage");
  expectRepeated("stage:\n  gap_px: 7\n  ratio: 1\n  gap_px: 9\n", "stage.gap_px");
  // The same key in two sections is fine.
  writeText(dir.file("c.yaml"), "%YAML:1.0\na:\n  gap_px: 1\nb:\n  gap_px: 2\n");
  EXPECT_NO_THROW(msf::ConfigFile(dir.file("c.yaml")));
}

TEST(Config, ReadsASequenceOfNumbers) {
  msf::test::TempDir dir;
  writeText(dir.file("c.yaml"), "%YAML:1.0\nstage:\n  values: [1, 2.5, -3]\n  one: 4\n  words: [a, b]\n");
  const msf::ConfigFile config(dir.file("c.yaml"));
  std::vector<double> values{9}, untouched{7};
  msf::readKey(config.section("stage"), "values", values);
  EXPECT_EQ(values, (std::vector<double>{1, 2.5, -3}));
  msf::readKey(config.section("stage"), "absent", untouched);
  EXPECT_EQ(untouched, std::vector<double>{7});
  for (const char* key : {"one", "words"}) {
    try {
      msf::readKey(config.section("stage"), key, values);
      FAIL() << key;
    } catch (const msf::ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("stage." + std::string(key) + "' must be a sequence of numbers"),
                std::string::npos)
          << e.what();
    }
  }
}

/// The error of rejectUnknownKeys for a file of `text` whose section `stage` was read for
/// the key gap_px ("" for none).
std::string unknownKeyError(const std::string& text) {
  msf::test::TempDir dir;
  writeText(dir.file("c.yaml"), "%YAML:1.0\n" + text);
  const msf::ConfigFile config(dir.file("c.yaml"));
  int gap = 0;
  msf::readKey(config.section("stage"), "gap_px", gap);
  try {
    config.rejectUnknownKeys();
  } catch (const msf::ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(Config, UnknownKeyOfASectionReadIsAnError) {
  const std::string what = unknownKeyError("stage:\n  gap_px: 7\n  gap: 9\nunread:\n  anything: 1\n");
  EXPECT_NE(what.find("'stage.gap' is not a key of section 'stage'"), std::string::npos) << what;
  EXPECT_NE(what.find("gap_px"), std::string::npos) << what; // the keys it has
  EXPECT_NE(what.find("c.yaml"), std::string::npos) << what;
  // Only the sections asked for are checked.
  EXPECT_EQ(unknownKeyError("stage:\n  gap_px: 7\nunread:\n  anything: 1\n"), "");
  EXPECT_NO_THROW(msf::ConfigFile().rejectUnknownKeys());
}

TEST(Config, SectionThatIsNotAMapIsAnError) {
  const std::string what = unknownKeyError("stage: 3\n");
  EXPECT_NE(what.find("section 'stage' must hold keys"), std::string::npos) << what;
}

TEST(Config, ProjectConfigFilesHaveNoRepeatedKeys) {
  for (const char* name : {"kitti.yaml", "synthetic.yaml"})
    EXPECT_NO_THROW(msf::ConfigFile(msf::test::sourceDir() + "/config/" + name)) << name;
}

TEST(Config, AnIndentedTopLevelIsRefusedBeforeOpenCvReadsIt) {
  // OpenCV 4.6's YAML parser loops forever on these (fuzz/fuzz_calibration's timeout finding,
  // reduced; msf_reconstruct -config hung the same way).
  msf::test::TempDir dir;
  const std::pair<const char*, const char*> hostile[] = {
      {"%YAML:1.0\n k: 4\na: -\n", "line 2: the top level is indented by 1 character"},
      {"%YAML:1.0\n---\n# c\n\n   k: 4\na: -5\n", "line 5: the top level is indented by 3 characters"},
      {"%YAML:1.0\n--- k: 4\na: -\n", "line 2: content on the '---' line"},
  };
  for (const auto& [text, why] : hostile) {
    writeText(dir.file("c.yaml"), text);
    const std::string e = msf::test::errorOf([&] { msf::ConfigFile config(dir.file("c.yaml")); });
    EXPECT_NE(e.find("config '" + dir.file("c.yaml") + "' is not valid YAML: " + why), std::string::npos) << e;
  }
  // Directives, ---, comments (indented too), blank and CR LF lines before a top level at column 0.
  writeText(dir.file("c.yaml"), "%YAML:1.0\r\n---\r\n  # c\r\n\r\nstage:\r\n  gap_px: 7\r\n");
  EXPECT_EQ(msf::test::errorOf([&] { msf::ConfigFile config(dir.file("c.yaml")); }), "(no error)");
}

TEST(Config, MissingFileIsAnError) { EXPECT_THROW(msf::ConfigFile("/nonexistent.yaml"), msf::IOError); }

TEST(Statistics, MedianAndPercentile) {
  EXPECT_DOUBLE_EQ(msf::median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(msf::median({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(msf::percentile({0, 10}, 95), 9.5);
  EXPECT_DOUBLE_EQ(msf::median({}), 0.0);
}

TEST(Tool, UnknownOptionIsRejectedAndValuesAreNotOptions) {
  const char* args[] = {"tool", "a.pcd", "-voxel", "-0.5", "-ascii", "b.pcd"};
  auto argv = const_cast<char**>(args);
  EXPECT_NO_THROW(msf::tool::checkOptions(6, argv, {"-voxel"}, {"-ascii"}));
  const auto positional = msf::tool::positionalArguments(6, argv, {"-voxel"});
  ASSERT_EQ(positional.size(), 2u);
  EXPECT_EQ(positional[1], "b.pcd");
  EXPECT_THROW(msf::tool::checkOptions(6, argv, {"-voxel"}, {}), msf::InvalidInputError);
  const char* missing[] = {"tool", "-voxel"};
  EXPECT_THROW(msf::tool::checkOptions(2, const_cast<char**>(missing), {"-voxel"}, {}), msf::InvalidInputError);
}

TEST(Tool, ParseArgumentReadsNumbersStrictly) {
  const char* args[] = {"tool", "-n", "42", "-x", "2.5e1", "-name", "cubic", "-bad", "2x", "-empty", ""};
  auto argv = const_cast<char**>(args);
  const int argc = 11;
  int n = 0;
  double x = 0;
  float xf = 0;
  std::string name;
  EXPECT_EQ(msf::tool::parseArgument(argc, argv, "-n", n), 1);
  EXPECT_EQ(n, 42);
  EXPECT_EQ(msf::tool::parseArgument(argc, argv, "-x", x), 3);
  EXPECT_DOUBLE_EQ(x, 25.0);
  msf::tool::parseArgument(argc, argv, "-x", xf);
  EXPECT_FLOAT_EQ(xf, 25.f);
  EXPECT_EQ(msf::tool::parseArgument(argc, argv, "-name", name), 5);
  EXPECT_EQ(name, "cubic");
  int untouched = 7;
  EXPECT_EQ(msf::tool::parseArgument(argc, argv, "-absent", untouched), -1);
  EXPECT_EQ(untouched, 7);
  const auto expectRejected = [&](const char* option, auto value, const std::string& message) {
    try {
      msf::tool::parseArgument(argc, argv, option, value);
      FAIL() << option;
    } catch (const msf::InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  expectRejected("-bad", 0.0, "-bad needs a number, not '2x'");
  expectRejected("-empty", 0.f, "-empty needs a number, not ''");
  expectRejected("-x", 0, "-x needs a whole number, not '2.5e1'");
  expectRejected("-name", 0, "-name needs a whole number, not 'cubic'");
  const char* big[] = {"tool", "-n", "99999999999", "-inf", "inf"};
  int b = 0;
  double d = 0;
  EXPECT_THROW(msf::tool::parseArgument(5, const_cast<char**>(big), "-n", b), msf::InvalidInputError);
  EXPECT_THROW(msf::tool::parseArgument(5, const_cast<char**>(big), "-inf", d), msf::InvalidInputError);
}

TEST(Tool, RunTurnsExceptionsIntoExitCodeOne) {
  EXPECT_EQ(msf::tool::run("msf_test", [] { return 0; }), 0);
  EXPECT_EQ(msf::tool::run("msf_test", []() -> int { throw msf::IOError("boom"); }), 1);
}

int help_calls = 0;
void countHelp(const char*) { ++help_calls; }

TEST(Tool, RunWithHelpShowsTheHelpOrRunsTheBody) {
  const char* help[] = {"tool", "a.pcd", "-h"};
  const char* few[] = {"tool"};
  const char* enough[] = {"tool", "a.pcd", "b.pcd"};
  int ran = 0;
  const auto body = [&] { return ++ran, 7; };
  help_calls = 0;
  EXPECT_EQ(msf::tool::runWithHelp(3, const_cast<char**>(help), "msf_test", 5, countHelp, body), 0);
  EXPECT_EQ(msf::tool::runWithHelp(1, const_cast<char**>(few), "msf_test", 3, countHelp, body), 1);
  EXPECT_EQ(help_calls, 2);
  EXPECT_EQ(ran, 0);
  EXPECT_EQ(msf::tool::runWithHelp(3, const_cast<char**>(enough), "msf_test", 3, countHelp, body), 7);
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(msf::tool::runWithHelp(3, const_cast<char**>(enough), "msf_test", 3, countHelp,
                                   []() -> int { throw msf::IOError("boom"); }),
            1);
  EXPECT_EQ(help_calls, 2);
}

} // namespace
