// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Configuration files read with yaml-cpp through keys declared once (config_keys.h, config.h).
#include <msf/common/config.h>
#include <msf/common/exceptions.h>
#include <msf/common/yaml_check.h>
#include <msf/common/yaml_file.h>

#include "test_support.h"

#include <fstream>
#include <sstream>

namespace {

enum class Shape { Round, Square };
constexpr msf::Choice<Shape> kShapes[] = {{"round", Shape::Round}, {"square", Shape::Square}};

/// A stage's configuration with a key of every kind.
struct StageConfig {
  static constexpr const char* kSection = "stage";
  int gap_px = 3;
  unsigned seed = 1;
  float ratio = 0.5f;
  double scale_m = 2.0;
  bool on = false;
  std::string name = "cubic";
  Shape shape = Shape::Round;
  std::vector<double> values{1, 2};

  template <class Keys>
  void keys(Keys& k) {
    k("gap_px", gap_px, msf::between(0, 100), "a gap, px");
    k("seed", seed, msf::anyNumber(), "a seed");
    k("ratio", ratio, msf::Range{0, 1, true, false}, "a share");
    k("scale_m", scale_m, msf::above(0), "a scale, m");
    k("on", on, "a switch");
    k("name", name, {"cubic", "linear"}, "a word");
    k("shape", shape, kShapes, "a choice");
    k("values", values, msf::atLeast(0), "numbers");
    k.removed("old_key", "it is gap_px now");
  }
  void validate() const {
    msf::checkKeyRanges(*this);
    if (gap_px == 13)
      throw msf::ConfigError("stage.gap_px must not be 13");
  }
};

void writeText(const std::string& path, const std::string& text) { std::ofstream(path, std::ios::binary) << text; }

/// The section `stage` of a config file of `text`.
StageConfig readStage(const std::string& text) {
  return msf::ConfigFile::fromText(text, "c.yaml").get<StageConfig>();
}

std::string printed(const StageConfig& config) {
  std::ostringstream out;
  msf::printConfig(out, config);
  return out.str();
}

TEST(Config, ReadsEveryKindOfKeyAndKeepsTheDefaultsOfTheOthers) {
  const StageConfig c = readStage("stage:\n  gap_px: 7\n  ratio: 0.25\n  name: linear\n  on: true\n");
  EXPECT_EQ(c.gap_px, 7);
  EXPECT_FLOAT_EQ(c.ratio, 0.25f);
  EXPECT_EQ(c.name, "linear");
  EXPECT_TRUE(c.on);
  EXPECT_EQ(c.seed, 1u);
  EXPECT_EQ(c.scale_m, 2.0);
  EXPECT_EQ(c.shape, Shape::Round);
  EXPECT_EQ(c.values, (std::vector<double>{1, 2}));
  // Another section only, or no file: the defaults.
  EXPECT_EQ(printed(readStage("other:\n  x: 1\n")), printed(StageConfig{}));
  EXPECT_EQ(printed(msf::ConfigFile().get<StageConfig>()), printed(StageConfig{}));
}

TEST(Config, ReadsPlainYamlAsPeopleAndPyYamlWriteItAndOpenCvFiles) {
  // PyYAML's dump (block sequence, 1.0e-05, True, quoted words), a flow map, OpenCV's directive, CR LF.
  const StageConfig dumped = readStage("---\nstage:\n  gap_px: 4.0\n  on: True\n  name: 'linear'\n  scale_m: "
                                       "1.0e-05\n  seed: 4294967295\n  shape: \"square\"\n  values:\n  - 0\n  - 2.5\n"
                                       "  - 1e3\n");
  EXPECT_EQ(dumped.gap_px, 4);
  EXPECT_TRUE(dumped.on);
  EXPECT_EQ(dumped.name, "linear");
  EXPECT_EQ(dumped.scale_m, 1e-5);
  EXPECT_EQ(dumped.seed, 4294967295u);
  EXPECT_EQ(dumped.shape, Shape::Square);
  EXPECT_EQ(dumped.values, (std::vector<double>{0, 2.5, 1000}));
  const StageConfig flow = readStage("stage: {gap_px: 9, on: off, ratio: .5}  # a comment after a value\n");
  EXPECT_EQ(flow.gap_px, 9);
  EXPECT_FALSE(flow.on);
  EXPECT_FLOAT_EQ(flow.ratio, 0.5f);
  const StageConfig opencv = readStage("%YAML:1.0\r\n---\r\n# c\r\nstage:\r\n  gap_px: 8\r\n  on: yes\r\n");
  EXPECT_EQ(opencv.gap_px, 8);
  EXPECT_TRUE(opencv.on);
  EXPECT_EQ(readStage("%YAML 1.1\n---\nstage:\n  on: 1\n").on, true);
  // Anchors and aliases: a value written once and referred to.
  const StageConfig aliased = readStage("other: {scale: &s 7}\nstage:\n  gap_px: *s\n  values: &v [3, 4]\n");
  EXPECT_EQ(aliased.gap_px, 7);
  EXPECT_EQ(aliased.values, (std::vector<double>{3, 4}));
}

TEST(Config, EveryBadValueIsAnErrorNamingTheFileTheLineAndTheKey) {
  const std::pair<std::string, std::string> cases[] = {
      {"gap_px: 2.5", "stage.gap_px must be a whole number in 0..100, not 2.5"},
      {"gap_px: 4294967297", "stage.gap_px must be a whole number in 0..100, not 4294967297"},
      {"seed: 4294967296", "stage.seed must be a whole number in 0..4294967295, not 4294967296"},
      {"seed: -1", "stage.seed must be a whole number in 0..4294967295, not -1"},
      {"gap_px: '5'", "stage.gap_px must be a whole number in 0..100, not '5'"},
      {"gap_px: 010", "stage.gap_px must be a whole number in 0..100, not 010"},
      {"gap_px: [1]", "stage.gap_px must be a whole number in 0..100, not a sequence"},
      {"gap_px:", "stage.gap_px has no value"},
      {"on: maybe", "stage.on must be true or false, not 'maybe'"},
      {"on: 2", "stage.on must be true or false, not 2"},
      {"name: spline", "stage.name must be cubic | linear, not 'spline'"},
      {"shape: oval", "stage.shape must be round | square, not 'oval'"},
      {"values: 4", "stage.values must be a sequence of numbers ([1, 2.5]), not 4"},
      {"values: [1, a]", "stage.values must be a finite number >= 0, not 'a'"},
      {"values: [1, -2]", "stage.values must be a finite number >= 0, not -2"},
      {"ratio: 0", "stage.ratio must be a finite number in (0, 1], not 0"},
      {"ratio: .nan", "stage.ratio must be a finite number in (0, 1], not .nan"},
      {"scale_m: .inf", "stage.scale_m must be a finite number > 0, not .inf"},
      {"scale_m: 1e400", "stage.scale_m must be a finite number > 0, not 1e400"},
      {"ratio: 1e39", "stage.ratio must be a finite number in (0, 1], not 1e39"},
      {"old_key: 1", "stage.old_key was removed: it is gap_px now"},
      {"gap: 9", "'stage.gap' is not a key of section 'stage' (its keys: gap_px, seed, ratio, scale_m, on, name, "
                 "shape, values, old_key)"},
      {"gap_px: 13", "stage.gap_px must not be 13"}, // validate(), located by the key it names
  };
  for (const auto& [line, why] : cases) {
    const std::string e = msf::test::errorOf([&] { readStage("# a config\nstage:\n  # a key below\n  " + line + "\n"); });
    EXPECT_EQ(e.rfind("config 'c.yaml' line 4: " + why, 0), 0u) << line << "\n" << e;
  }
  // A number of five million digits: refused at once, shortened in the message.
  const std::string e = msf::test::errorOf([&] { readStage("stage:\n  gap_px: " + std::string(5000000, '7') + "\n"); });
  EXPECT_NE(e.find("stage.gap_px must be a whole number in 0..100, not 7777777777"), std::string::npos) << e;
  EXPECT_NE(e.find("... (5000000 characters)"), std::string::npos) << e;
  EXPECT_LT(e.size(), 200u);
}

TEST(Config, AFileThatIsNoConfigurationIsAClearError) {
  msf::test::TempDir dir;
  const std::pair<std::string, std::string> cases[] = {
      {"", "config '@' is empty: a config file holds sections of keys"},
      {"# only a comment\n\n", "config '@' is empty"},
      {"- a\n- b\n", "config '@' line 1: a config file is a map of sections"},
      {"just words\n", "config '@' line 1: a config file is a map of sections"},
      {"stage: 3\n", "config '@' line 1: section 'stage' must hold keys (key: value), one per line"},
      {"stage: [1]\n", "config '@' line 1: section 'stage' must hold keys"},
      {"a:\n  k: 1\n---\nb:\n  k: 2\n", "config '@' holds 2 YAML documents"},
      {"stage:\n  gap_px: [1, 2\n", "config '@' is not valid YAML: line 3, column 1: end of sequence flow not found"},
      {" k: 4\na: -\n", "config '@' is not valid YAML: line 2"}, // OpenCV's parser looped forever on it
      {std::string("stage:\n  gap_px: 1\n\0stage:\n", 27), "config '@' is not a text file: a NUL byte on line 3"},
      {std::string(33000, '[') + std::string(33000, ']'), "config '@' is not valid YAML: line 1"},
  };
  for (const auto& [text, why] : cases) {
    writeText(dir.file("c.yaml"), text);
    const std::string e = msf::test::errorOf([&] { msf::ConfigFile config(dir.file("c.yaml")); });
    std::string expected = why;
    expected.replace(expected.find('@'), 1, dir.file("c.yaml"));
    EXPECT_EQ(e.rfind(expected, 0), 0u) << text.substr(0, 40) << "\n" << e;
  }
  EXPECT_THROW(msf::ConfigFile("/nonexistent.yaml"), msf::IOError);
  EXPECT_THROW(msf::ConfigFile(dir.path()), msf::IOError); // a folder
}

TEST(Config, DeepNestingIsCaughtByYamlCppsDepthGuardNotTheStack) {
  // 33,000 levels (a 66 KB file) overflowed the stack in OpenCV's parser; yaml-cpp stops at its
  // depth guard whatever the form of nesting, and the file is named.
  const int levels = 33000;
  const std::string forms[] = {std::string(levels, '[') + std::string(levels, ']'),
                               [&] {
                                 std::string s;
                                 for (int i = 0; i < levels; ++i)
                                   s += "{a: ";
                                 return s + "1" + std::string(levels, '}');
                               }(),
                               [&] {
                                 std::string s;
                                 for (int i = 0; i < levels; ++i)
                                   s += "- ";
                                 return s + "x";
                               }(),
                               "stage:\n  values: " + std::string(levels, '[') + std::string(levels, ']')};
  for (const std::string& text : forms) {
    try {
      msf::ConfigFile::fromText(text, "deep.yaml");
      ADD_FAILURE() << "accepted " << text.substr(0, 20);
    } catch (const msf::IOError& e) {
      EXPECT_NE(std::string(e.what()).find("config 'deep.yaml' is not valid YAML: line "), std::string::npos)
          << e.what();
      EXPECT_NE(std::string(e.what()).find("levels deep (yaml-cpp's limit)"), std::string::npos) << e.what();
    }
  }
}

TEST(Config, ALargeFileIsRefusedBeforeItIsParsed) {
  msf::test::TempDir dir;
  writeText(dir.file("c.yaml"), "stage:\n  gap_px: 1\n" + std::string(msf::kMaxYamlFileBytes, '#'));
  const std::string e = msf::test::errorOf([&] { msf::ConfigFile config(dir.file("c.yaml")); });
  EXPECT_NE(e.find("is larger than 16 MiB"), std::string::npos) << e;
}

TEST(Config, RepeatedSectionOrKeyIsAnErrorWithBothLines) {
  EXPECT_EQ(msf::test::errorOf([] {
              msf::ConfigFile::fromText("stage:\n  gap_px: 7\nother:\n  a: 1\nstage:\n  gap_px: 9\n", "c.yaml");
            }),
            "config 'c.yaml' line 5: section 'stage' appears twice (lines 1 and 5)");
  EXPECT_EQ(msf::test::errorOf(
                [] { msf::ConfigFile::fromText("stage:\n  gap_px: 7\n  ratio: 1\n  gap_px: 9\n", "c.yaml"); }),
            "config 'c.yaml' line 4: 'stage.gap_px' appears twice (lines 2 and 4)");
  // The same key in two sections is fine.
  EXPECT_NO_THROW(msf::ConfigFile::fromText("a:\n  gap_px: 1\nb:\n  gap_px: 2\n", "c.yaml"));
}

TEST(Config, ASectionNotKnownIsRefusedNamingTheKnownOnes) {
  const msf::ConfigFile file = msf::ConfigFile::fromText("stage:\n  gap_px: 1\nstages:\n  gap_px: 2\n", "c.yaml");
  EXPECT_EQ(msf::test::errorOf([&] { file.requireKnownSections({"stage", "other"}); }),
            "config 'c.yaml' line 3: 'stages' is not a section of the configuration (its sections: stage, other)");
  EXPECT_NO_THROW(file.requireKnownSections({"stages", "stage"}));
  EXPECT_EQ(file.sections(), (std::vector<std::string>{"stage", "stages"}));
}

TEST(Config, PrintedValuesReadBackToTheSameConfiguration) {
  StageConfig c;
  c.gap_px = 42;
  c.seed = 4000000000u;
  c.ratio = 0.1f;
  c.scale_m = 1e-5;
  c.on = true;
  c.name = "linear";
  c.shape = Shape::Square;
  c.values = {0, 0.25, 1e20};
  const std::string text = printed(c);
  EXPECT_EQ(text, "stage:\n  gap_px: 42\n  seed: 4000000000\n  ratio: 0.1\n  scale_m: 1.0e-05\n  on: true\n  name: "
                  "linear\n  shape: square\n  values: [0, 0.25, 1.0e+20]\n");
  EXPECT_EQ(printed(readStage(text)), text);
  // With comments: each key's meaning and range above it.
  std::ostringstream commented;
  msf::printSection(commented, "stage", msf::listKeys(c), true);
  EXPECT_NE(commented.str().find("  # a share [(0, 1]]\n  ratio: 0.1\n"), std::string::npos) << commented.str();
  EXPECT_NE(commented.str().find("  # a word [cubic | linear]\n  name: linear\n"), std::string::npos);
  EXPECT_NE(commented.str().find("  # a switch\n  on: true\n"), std::string::npos);
}

TEST(Config, ConfigValueIsTheShortestTextThatYamlReadsAsTheSameNumber) {
  EXPECT_EQ(msf::configValue(0.1f), "0.1");
  EXPECT_EQ(msf::configValue(0.123456789f), "0.12345679");
  EXPECT_EQ(msf::configValue(5.0), "5.0");
  EXPECT_EQ(msf::configValue(1e4f), "10000.0");
  EXPECT_EQ(msf::configValue(1e-5), "1.0e-05");
  EXPECT_EQ(msf::configValue(2.5e-7), "2.5e-07");
  EXPECT_EQ(msf::configValue(-1e300), "-1.0e+300");
  EXPECT_EQ(msf::configValue(std::numeric_limits<double>::infinity()), ".inf");
  EXPECT_EQ(msf::configValue(-1), "-1");
  EXPECT_EQ(msf::configValue(false), "false");
  EXPECT_EQ(msf::configValue(std::vector<double>{0, 5, 0.5}), "[0, 5, 0.5]");
}

TEST(Config, RangesCheckAndDescribeThemselves) {
  EXPECT_EQ(msf::between(1, 11).text(), "1..11");
  EXPECT_EQ(msf::atLeast(0).text(), ">= 0");
  EXPECT_EQ(msf::above(0.5).text(), "> 0.5");
  EXPECT_EQ((msf::Range{0, 1, false, true}).text(), "[0, 1)");
  EXPECT_EQ(msf::anyNumber().text(), "");
  EXPECT_TRUE(msf::between(1, 11).contains(11));
  EXPECT_FALSE((msf::Range{0, 1, true, false}).contains(0));
  EXPECT_FALSE(msf::anyNumber().contains(std::nan("")));
  StageConfig c;
  c.gap_px = 101;
  EXPECT_EQ(msf::test::errorOf([&] { c.validate(); }), "stage.gap_px must be in 0..100, not 101");
  c = StageConfig{};
  c.scale_m = -1;
  EXPECT_EQ(msf::test::errorOf([&] { c.validate(); }), "stage.scale_m must be > 0, not -1.0");
  c = StageConfig{};
  c.name = "spline";
  EXPECT_EQ(msf::test::errorOf([&] { c.validate(); }), "stage.name must be cubic | linear, not 'spline'");
  c = StageConfig{};
  c.values = {1, std::nan("")};
  EXPECT_EQ(msf::test::errorOf([&] { c.validate(); }), "stage.values must be >= 0, not .nan (in [1, .nan])");
}

TEST(YamlFile, ScalarsAreTypedAsPyYamlTypesThem) {
  const YAML::Node node = msf::parseYamlText(
      "[5, -2.5, 1.0e-05, 1e-5, .5, .inf, -.inf, .nan, 010, '5', true, Off, yes, word, 0x10, 1_000]", "s.yaml", "test");
  EXPECT_EQ(msf::yamlInteger(node[0]), 5);
  EXPECT_EQ(msf::yamlReal(node[1]), -2.5);
  EXPECT_EQ(msf::yamlReal(node[2]), 1e-5);
  EXPECT_EQ(msf::yamlReal(node[3]), 1e-5); // YAML 1.2 reads it as a number (PyYAML as text)
  EXPECT_EQ(msf::yamlReal(node[4]), 0.5);
  EXPECT_EQ(msf::yamlReal(node[5]), HUGE_VAL);
  EXPECT_EQ(msf::yamlReal(node[6]), -HUGE_VAL);
  EXPECT_TRUE(std::isnan(*msf::yamlReal(node[7])));
  for (const int i : {8, 9, 13, 14, 15}) {
    EXPECT_FALSE(msf::yamlInteger(node[i])) << i;
    EXPECT_FALSE(msf::yamlReal(node[i])) << i;
  }
  EXPECT_EQ(msf::yamlBool(node[10]), true);
  EXPECT_EQ(msf::yamlBool(node[11]), false);
  EXPECT_EQ(msf::yamlBool(node[12]), true);
  EXPECT_FALSE(msf::yamlBool(node[13]));
  EXPECT_FALSE(msf::yamlInteger(node[1]));
  EXPECT_EQ(msf::yamlQuoted(node[13]), "'word'");
  EXPECT_EQ(msf::yamlQuoted(node[1]), "-2.5");
  EXPECT_EQ(msf::yamlLine(node[3]), "line 1");
  const auto repeated = msf::findRepeatedKey(msf::parseYamlText("a: 1\nb: 2\na: 3\n", "r.yaml", "test"));
  ASSERT_TRUE(repeated);
  EXPECT_EQ(repeated->key, "a");
  EXPECT_EQ(repeated->first_line, 1);
  EXPECT_EQ(repeated->second_line, 3);
}

TEST(YamlCheck, AnIndentedTopLevelIsRefusedBeforeOpenCvReadsIt) {
  // OpenCV 4.6's YAML parser loops forever on these (fuzz/fuzz_calibration's timeout finding,
  // reduced): calibration files are still read with it.
  msf::test::TempDir dir;
  const std::pair<const char*, const char*> hostile[] = {
      {"%YAML:1.0\n k: 4\na: -\n", "line 2: the top level is indented by 1 character"},
      {"%YAML:1.0\n---\n# c\n\n   k: 4\na: -5\n", "line 5: the top level is indented by 3 characters"},
      {"%YAML:1.0\n--- k: 4\na: -\n", "line 2: content on the '---' line"},
  };
  for (const auto& [text, why] : hostile) {
    writeText(dir.file("c.yaml"), text);
    const std::string e =
        msf::test::errorOf([&] { msf::requireYamlTopLevelAtColumnZero(dir.file("c.yaml"), "calibration"); });
    EXPECT_NE(e.find("calibration '" + dir.file("c.yaml") + "' is not valid YAML: " + why), std::string::npos) << e;
  }
  // Directives, ---, comments (indented too), blank and CR LF lines before a top level at column 0.
  writeText(dir.file("c.yaml"), "%YAML:1.0\r\n---\r\n  # c\r\n\r\nstage:\r\n  gap_px: 7\r\n");
  EXPECT_EQ(msf::test::errorOf([&] { msf::requireYamlTopLevelAtColumnZero(dir.file("c.yaml"), "calibration"); }),
            "(no error)");
}

} // namespace
