// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The check that a tool run by a test printed no sanitizer report (runCommand, runTool,
// bad_inputs.sh), tested on the real reports of msf_sanitizer_report_helper: a program built
// with -fsanitize=address,undefined in every build (tests/CMakeLists.txt) that overflows an int,
// writes past a heap block or leaks one.
#include "test_support.h"

#include <gtest/gtest-spi.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <string>

namespace {

#ifdef MSF_SANITIZER_REPORT_HELPER
const std::string kHelper = MSF_SANITIZER_REPORT_HELPER;
#define MSF_REQUIRE_HELPER() (void)0
#else
const std::string kHelper;
#define MSF_REQUIRE_HELPER() GTEST_SKIP() << "the compiler does not link -fsanitize=address,undefined"
#endif

/// What runCommand did and the failures it reported, caught rather than failing this test.
struct Caught {
  msf::test::CommandResult r;
  std::string failures; ///< their messages, one after the other
  int count = 0;
};

Caught runCatching(const std::string& command_line) {
  testing::TestPartResultArray results;
  Caught caught;
  {
    testing::ScopedFakeTestPartResultReporter catcher(
        testing::ScopedFakeTestPartResultReporter::INTERCEPT_ONLY_CURRENT_THREAD, &results);
    caught.r = msf::test::runCommand(command_line);
  }
  caught.count = results.size();
  for (int i = 0; i < results.size(); ++i)
    caught.failures += results.GetTestPartResult(i).message();
  return caught;
}

// The options of `make test-sanitize` may be in the environment (abort_on_error=1, halt_on_error=1):
// each case sets its own. halt_on_error=0: UBSan prints its report and the program carries on.
const std::string kEnv = "ASAN_OPTIONS=detect_leaks=1 UBSAN_OPTIONS=halt_on_error=0:print_stacktrace=1 ";

TEST(SanitizerReports, AnUndefinedBehaviourReportFailsTheTestEvenWhenTheToolExitsZero) {
  MSF_REQUIRE_HELPER();
  // UBSan prints its report and the program carries on to exit 0, which a test that expects
  // success accepts by its exit code alone.
  const auto [r, failures, count] = runCatching(kEnv + kHelper + " ubsan");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  ASSERT_NE(r.err.find("runtime error: signed integer overflow"), std::string::npos) << r.err;
  EXPECT_EQ(count, 1) << failures;
  EXPECT_NE(failures.find("a sanitizer report in the output of `"), std::string::npos) << failures;
  EXPECT_NE(failures.find("sanitizer_report_helper.cpp:"), std::string::npos) << "the report's first line is quoted: "
                                                                                << failures;
  EXPECT_NE(failures.find("runtime error: signed integer overflow: 2147483647 + 2"), std::string::npos) << failures;
}

TEST(SanitizerReports, AnAddressSanitizerReportFailsTheTestWhateverTheExitCode) {
  MSF_REQUIRE_HELPER();
  // ASan's own exit code is 1, as a tool's clear error.
  const auto [r, failures, count] = runCatching(kEnv + kHelper + " heap-overflow");
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(count, 1) << failures;
  EXPECT_NE(failures.find("ERROR: AddressSanitizer: heap-buffer-overflow"), std::string::npos) << failures;
  // Quoted from its first line, not the whole report.
  EXPECT_EQ(failures.find("msf_sanitizer_report_helper: heap-overflow"), std::string::npos) << failures;
  EXPECT_LE(std::count(failures.begin(), failures.end(), '\n'), 14) << failures;
}

TEST(SanitizerReports, ALeakReportFailsTheTest) {
  MSF_REQUIRE_HELPER();
  const auto [r, failures, count] = runCatching(kEnv + kHelper + " leak");
  ASSERT_NE(r.err.find("LeakSanitizer"), std::string::npos) << "LSan did not run here: " << r.err;
  EXPECT_EQ(count, 1) << failures;
  EXPECT_NE(failures.find("ERROR: LeakSanitizer: detected memory leaks"), std::string::npos) << failures;
}

TEST(SanitizerReports, AProgramWithoutAReportPasses) {
  MSF_REQUIRE_HELPER();
  const auto [r, failures, count] = runCatching(kEnv + kHelper + " clean");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(count, 0) << failures;
  // A tool's own error that mentions the words is not a report.
  EXPECT_EQ(msf::test::sanitizerReport("msf_info: error: 'runtime error:.pcd' does not exist\n"
                                       "AddressSanitizer is not in this build\n"),
            "");
}

TEST(SanitizerReports, TheMatrixScriptFindsTheSameReports) {
  MSF_REQUIRE_HELPER();
  msf::test::TempDir dir;
  const std::string script = "bash " + msf::test::sourceDir() + "/tests/robustness/bad_inputs.sh --sanitizer-report ";
  for (const std::string mode : {"ubsan", "heap-overflow", "leak", "clean"}) {
    const std::string err = dir.file(mode + ".err");
    std::system((kEnv + kHelper + " " + mode + " >/dev/null 2>" + err).c_str());
    std::ifstream in(err);
    const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const auto r = msf::test::runCommand(script + err);
    const std::string expected = msf::test::sanitizerReport(text);
    EXPECT_EQ(r.exit_code, expected.empty() ? 0 : 1) << mode << ": " << r.out << r.err;
    EXPECT_EQ(r.out, expected) << mode << ": the script and runCommand quote the same lines";
    if (mode != "clean") {
      EXPECT_FALSE(expected.empty()) << mode << ": " << text;
    }
  }
}

} // namespace
