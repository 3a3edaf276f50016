// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/common/tool.h>

#include "test_support.h"

#include <cerrno>
#include <filesystem>
#include <functional>
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

TEST(AtomicFile, FilesInListsAFoldersFilesOfTheGivenExtensionsInNameOrder) {
  msf::test::TempDir dir;
  for (const char* name : {"2.bin", "1.PCD", "0.txt", "10.bin"})
    std::ofstream(dir.file(name)) << "x";
  std::filesystem::create_directories(dir.file("3.bin")); // a folder, not a file
  const std::vector<std::string> found = msf::filesIn(dir.file(""), {".bin", ".pcd"}, "scan folder");
  EXPECT_EQ(found, (std::vector<std::string>{dir.file("1.PCD"), dir.file("10.bin"), dir.file("2.bin")}));
  for (const std::string& bad : {dir.file("nowhere"), dir.file("3.bin")}) {
    try {
      msf::filesIn(bad, {".png"}, "estimate folder");
      ADD_FAILURE() << bad << " was accepted";
    } catch (const msf::IOError& e) {
      EXPECT_NE(std::string(e.what()).find("estimate folder '" + bad + "'"), std::string::npos) << e.what();
    }
  }
  try {
    msf::filesIn(dir.file(""), {".png", ".jpg"}, "image folder");
    ADD_FAILURE() << "a folder without .png or .jpg was accepted";
  } catch (const msf::IOError& e) {
    EXPECT_NE(std::string(e.what()).find("has no .png or .jpg file"), std::string::npos) << e.what();
  }
}

TEST(Statistics, MedianAndPercentile) {
  EXPECT_DOUBLE_EQ(msf::median({3, 1, 2}), 2.0);
  EXPECT_DOUBLE_EQ(msf::median({4, 1, 2, 3}), 2.5);
  EXPECT_DOUBLE_EQ(msf::percentile({0, 10}, 95), 9.5);
  EXPECT_DOUBLE_EQ(msf::median({}), 0.0);
}

/// argv of `args` for the parser (the strings outlive the call).
struct Argv {
  explicit Argv(std::vector<std::string> a) : args(std::move(a)) {
    for (auto& s : args)
      pointers.push_back(s.data());
  }
  int argc() const { return static_cast<int>(pointers.size()); }
  char** argv() { return pointers.data(); }
  std::vector<std::string> args;
  std::vector<char*> pointers;
};

TEST(Tool, UnknownOptionIsRejectedAndValuesAreNotOptions) {
  double voxel = 0;
  bool ascii = false;
  msf::tool::CommandLine cli("msf_test", "<a> <b>", "Test.");
  cli.value("-voxel", "V", voxel, "voxel").flag("-ascii", ascii, "ascii");
  Argv args({"tool", "a.pcd", "-voxel", "-0.5", "-ascii", "b.pcd"});
  const auto positional = cli.parse(args.argc(), args.argv());
  ASSERT_EQ(positional.size(), 2u);
  EXPECT_EQ(positional[1], "b.pcd");
  EXPECT_DOUBLE_EQ(voxel, -0.5);
  EXPECT_TRUE(ascii);
  EXPECT_TRUE(cli.given("-voxel"));
  EXPECT_EQ(cli.flags(), std::vector<std::string>{"-ascii"});
  const auto rejected = [&](std::vector<std::string> a, const std::string& message) {
    Argv bad(std::move(a));
    try {
      cli.parse(bad.argc(), bad.argv());
      ADD_FAILURE() << message;
    } catch (const msf::InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  rejected({"tool", "a.pcd", "-voxl", "3"}, "unknown option '-voxl' (see -h)");
  rejected({"tool", "-voxel"}, "option '-voxel' needs a value");
}

TEST(Tool, NumbersAreReadStrictly) {
  int n = 0, untouched = 7;
  double x = 0;
  float xf = 0;
  std::string name;
  msf::tool::CommandLine cli("msf_test", "", "Test.");
  cli.value("-n", "N", n, "").value("-x", "X", x, "").value("-xf", "X", xf, "").value("-name", "S", name, "");
  cli.value("-absent", "N", untouched, "");
  Argv args({"tool", "-n", "42", "-x", "2.5e1", "-xf", "2.5e1", "-name", "cubic"});
  cli.parse(args.argc(), args.argv());
  EXPECT_EQ(n, 42);
  EXPECT_DOUBLE_EQ(x, 25.0);
  EXPECT_FLOAT_EQ(xf, 25.f);
  EXPECT_EQ(name, "cubic");
  EXPECT_EQ(untouched, 7);
  EXPECT_FALSE(cli.given("-absent"));
  const auto rejected = [&](const std::string& option, const std::string& value, const std::string& message) {
    Argv bad({"tool", option, value});
    try {
      cli.parse(bad.argc(), bad.argv());
      ADD_FAILURE() << option;
    } catch (const msf::InvalidInputError& e) {
      EXPECT_NE(std::string(e.what()).find(message), std::string::npos) << e.what();
    }
  };
  rejected("-x", "2x", "-x needs a number, not '2x'");
  rejected("-x", "", "-x needs a number, not ''");
  rejected("-x", "inf", "-x needs a number, not 'inf'");
  rejected("-n", "2.5e1", "-n needs a whole number, not '2.5e1'");
  rejected("-n", "cubic", "-n needs a whole number, not 'cubic'");
  // Past int's range: refused as such, not wrapped; a value of 5 million digits is named by its length.
  rejected("-n", "99999999999", "-n must be a whole number in -2147483648 .. 2147483647, not '99999999999'");
  rejected("-n", "-99999999999", "-n must be a whole number in -2147483648 .. 2147483647");
  rejected("-n", std::string(5000000, '9'), "-n must be a whole number in -2147483648 .. 2147483647, not "
                                            "'999999999999999999999999...' (5000000 characters)");
  rejected("-x", "1e999", "-x needs a finite number within the range of a double, not '1e999'");
  rejected("-xf", "1e39", "-xf needs a finite number within the range of a float, not '1e39'");
  rejected("-x", std::string(5000000, 'a'), "-x needs a number, not 'aaaaaaaaaaaaaaaaaaaaaaaa...' (5000000 characters)");
}

TEST(Tool, OptionsApplyInTheOrderDeclaredAndARepeatedOneIsRefused) {
  // A -config declared first is overridden by the options declared after it, wherever given.
  int level = 1;
  std::string order, calib;
  msf::tool::CommandLine cli("msf_test", "", "Test.");
  cli.value("-config", "FILE",
            [&](const std::string& v) {
              level = 10;
              order += "config " + v + ";";
            },
            "")
      .value("-level", "N", level, "")
      .value("-calib", "PATH", calib, "")
      .value("-rig", "FILE", calib, "the same as -calib");
  Argv args({"tool", "-level", "3", "-config", "c.yaml", "-level", "3", "-calib", "r.yaml", "-rig", "r.yaml"});
  cli.parse(args.argc(), args.argv()); // the same value twice, by one name or two: no doubt
  EXPECT_EQ(level, 3);
  EXPECT_EQ(order, "config c.yaml;");
  EXPECT_EQ(calib, "r.yaml");
  // Two values: the first would stay (PCL's habit), a shell user expects the last; neither is said.
  const auto refused = [&](std::vector<std::string> a) {
    Argv bad(std::move(a));
    return msf::test::errorOf([&] { cli.parse(bad.argc(), bad.argv()); });
  };
  EXPECT_NE(refused({"tool", "-level", "3", "-level", "4"}).find("option '-level' is given twice, '3' and '4': give "
                                                                 "it once"),
            std::string::npos);
  EXPECT_NE(refused({"tool", "-rig", "a.yaml", "-calib", "calib.txt"})
                .find("options '-calib' and '-rig' set one thing, given 'calib.txt' and 'a.yaml': give one of them"),
            std::string::npos);
}

TEST(Tool, TheHelpListsEveryOptionWithItsDefault) {
  int frames = 10;
  float voxel = 0.1f;
  bool loop = false;
  std::string long_help;
  for (int i = 0; i < 40; ++i)
    long_help += "word ";
  msf::tool::CommandLine cli("msf_test", "-o DIR [options]\n<in> [options]", "What it does.");
  cli.value("-frames", "N", frames, "number of frames (default {default})")
      .value("-voxel", "M", voxel, "voxel size in metres (default {default})")
      .flag("-loop", loop, long_help)
      .value("-a_very_long_option_name", "VALUE", frames, "help")
      .note("A note.");
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  cli.printHelp("msf_test");
  const std::string out = testing::internal::GetCapturedStdout(), err = testing::internal::GetCapturedStderr();
  EXPECT_NE(err.find("Syntax is: msf_test -o DIR [options]\n       or: msf_test <in> [options]\n"), std::string::npos)
      << err;
  EXPECT_NE(out.find("  What it does.\n  where options are:\n"), std::string::npos) << out;
  EXPECT_NE(out.find("    -frames N  number of frames (default 10)\n"), std::string::npos) << out;
  EXPECT_NE(out.find("    -voxel M   voxel size in metres (default 0.1)\n"), std::string::npos) << out;
  EXPECT_NE(out.find("    -a_very_long_option_name VALUE\n               help\n"), std::string::npos) << out;
  EXPECT_NE(out.find("  A note.\n"), std::string::npos) << out;
  for (std::size_t from = 0, to; (to = out.find('\n', from)) != std::string::npos; from = to + 1)
    EXPECT_LE(to - from, 100u) << out.substr(from, to - from); // the long help is wrapped
}

TEST(Tool, RunTurnsExceptionsIntoExitCodeOne) {
  EXPECT_EQ(msf::tool::run("msf_test", [] { return 0; }), 0);
  EXPECT_EQ(msf::tool::run("msf_test", []() -> int { throw msf::IOError("boom"); }), 1);
}

TEST(Tool, RunShowsTheHelpOrRunsTheBody) {
  msf::tool::CommandLine cli("msf_test", "<a> <b>", "Test.");
  int ran = 0;
  std::size_t positional = 0;
  const auto body = [&](const msf::tool::Arguments& files) { return positional = files.size(), ++ran, 7; };
  Argv help({"tool", "a.pcd", "-h"}), few({"tool"}), enough({"tool", "a.pcd", "b.pcd"});
  testing::internal::CaptureStdout();
  testing::internal::CaptureStderr();
  EXPECT_EQ(cli.run(help.argc(), help.argv(), 4, body), 0);
  EXPECT_EQ(cli.run(few.argc(), few.argv(), 2, body), 1);
  const std::string shown = testing::internal::GetCapturedStderr();
  testing::internal::GetCapturedStdout();
  EXPECT_NE(shown.find("Syntax is: tool <a> <b>"), std::string::npos) << shown;
  EXPECT_EQ(ran, 0);
  EXPECT_EQ(cli.run(enough.argc(), enough.argv(), 2, body), 7);
  EXPECT_EQ(ran, 1);
  EXPECT_EQ(positional, 2u);
  EXPECT_EQ(cli.run(enough.argc(), enough.argv(), 2,
                    [](const msf::tool::Arguments&) -> int { throw msf::IOError("boom"); }),
            1);
}

TEST(Tool, AnOutputFileThatExistsIsRefusedUnlessOverwriteIsGiven) {
  msf::test::TempDir dir;
  writeText(dir.file("mine.pcd"), "the user's");
  std::filesystem::create_directory(dir.file("folder.pcd"));
  bool overwrite = false;
  msf::tool::CommandLine cli("msf_test", "<out.pcd>", "Test.");
  cli.overwriteOption(overwrite);
  Argv plain({"tool", "x"}), forced({"tool", "x", "-overwrite"});
  cli.parse(plain.argc(), plain.argv());
  msf::tool::requireNewOutputs({"", dir.file("new.pcd")}, overwrite); // absent or not asked for: fine
  try {
    msf::tool::requireNewOutputs({dir.file("new.pcd"), dir.file("mine.pcd")}, overwrite);
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    EXPECT_EQ(std::string(e.what()), "output '" + dir.file("mine.pcd") + "' exists; give -overwrite to replace it");
    EXPECT_EQ(e.path(), dir.file("mine.pcd"));
    EXPECT_EQ(e.code(), EEXIST);
  }
  cli.parse(forced.argc(), forced.argv());
  ASSERT_TRUE(overwrite);
  msf::tool::requireNewOutputs({dir.file("mine.pcd")}, overwrite);
  EXPECT_THROW(msf::tool::requireNewOutputs({dir.file("folder.pcd")}, overwrite), msf::IOError);
  try {
    msf::tool::requireNewOutputs({dir.file("missing/out.pcd")}, overwrite); // before the work, not after
    FAIL() << "expected IOError";
  } catch (const msf::IOError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find("output folder '" + dir.file("missing") + "' does not exist"), std::string::npos) << message;
    EXPECT_EQ(e.path(), dir.file("missing"));
    EXPECT_EQ(e.code(), ENOENT);
  }
  std::ifstream in(dir.file("mine.pcd"));
  std::string first;
  in >> first;
  EXPECT_EQ(first, "the");
}

/// A missing file, a folder where a file should be, a file where a folder should be: each an
/// IOError that names the path and gives the errno a caller (the Python door) can tell apart.
TEST(Files, AMissingOrMisplacedPathGivesItsErrno) {
  msf::test::TempDir dir;
  writeText(dir.file("file.txt"), "text");
  const auto codeOf = [](const std::function<void()>& f, const std::string& path) {
    try {
      f();
    } catch (const msf::IOError& e) {
      EXPECT_EQ(e.path(), path) << e.what();
      return e.code();
    }
    return -1;
  };
  EXPECT_EQ(codeOf([&] { msf::requireFile(dir.file("none.txt"), "scan"); }, dir.file("none.txt")), ENOENT);
  EXPECT_EQ(codeOf([&] { msf::requireFile(dir.path(), "scan"); }, dir.path()), EISDIR);
  EXPECT_EQ(codeOf([&] { msf::requireDirectory(dir.file("none"), "sequence"); }, dir.file("none")), ENOENT);
  EXPECT_EQ(codeOf([&] { msf::requireDirectory(dir.file("file.txt"), "sequence"); }, dir.file("file.txt")), ENOTDIR);
  msf::requireFile(dir.file("file.txt"), "scan");
  msf::requireDirectory(dir.path(), "sequence");
  // An error of a file's content carries no errno.
  EXPECT_EQ(msf::IOError("cloud 'a.pcd' has no points").code(), 0);
}

} // namespace
