// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The project's text says what is true today: the README stays a short front door, and no
// tracked file carries an issue number or a label of the round of work that wrote it (git
// keeps that history).
#include "test_support.h"

#include <cctype>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

namespace {

const std::size_t kReadmeMaxLines = 150;

std::vector<std::string> linesOf(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::vector<std::string> lines;
  for (std::string line; std::getline(in, line);)
    lines.push_back(line);
  return lines;
}

/// The project's tracked files (git ls-files); empty with `why` set when git cannot list them.
std::vector<std::string> trackedFiles(std::string& why) {
  const msf::test::CommandResult r =
      msf::test::runCommand("git -C '" + msf::test::sourceDir() + "' ls-files -z");
  std::vector<std::string> files;
  if (r.exit_code != 0) {
    why = "git ls-files failed: " + r.err;
    return files;
  }
  std::istringstream list(r.out);
  for (std::string file; std::getline(list, file, '\0');)
    if (!file.empty())
      files.push_back(file);
  return files;
}

// An issue reference: the word issue (or issues) then a number, or a bare '#' and number after a
// space, bracket or comma (not a colour, an anchor, "$#" or a preprocessor line).
const std::regex kIssueReference(R"(\b(issues?) #?[0-9]+\b|(^|[\s(\[,])#[0-9]{1,5}\b)",
                                 std::regex::icase);
// A label of a round of work: the word session, round or stop then a number, also in an anchor;
// a count such as msf_batch's "N of M" rounds, or a figure per round, is not one.
const std::regex kWorkLabel(R"(\b(sessions?|round|stop)[ -]#?[0-9]+\b(?!\.[0-9]| of |/))", std::regex::icase);

/// Cheap first look, so that the regular expressions run on the few lines that may match.
bool mayMatch(std::string line) {
  for (char& c : line)
    c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  for (const char* word : {"ssion", "ound", "top", "ssue", "#"})
    if (line.find(word) != std::string::npos)
      return true;
  return false;
}

TEST(ProjectText, ReadmeIsAShortFrontDoor) {
  const std::vector<std::string> lines = linesOf(msf::test::sourceDir() + "/README.md");
  ASSERT_FALSE(lines.empty()) << "README.md not found in " << msf::test::sourceDir();
  EXPECT_LE(lines.size(), kReadmeMaxLines)
      << "README.md has " << lines.size() << " lines: move detail to docs/ or CONTRIBUTING.md";
}

TEST(ProjectText, PatternsFindIssueNumbersAndWorkLabelsOnly) {
  for (const char* text : {"issue 19", "see Issue #4's target", "issues 15 and 16", "fixed in #37",
                           "(#12)"})
    EXPECT_TRUE(std::regex_search(text, kIssueReference)) << text;
  for (const char* text : {"colour #1f77b4", "[a](#five-paths)", "$#", "#line 12 \"x\"", "the issue's targets",
                           "#include <a.h>", "x#3"})
    EXPECT_FALSE(std::regex_search(text, kIssueReference)) << text;
  for (const std::string& text : {std::string("session") + " 19", std::string("(Session") + " 15)",
                                  std::string("sessions") + " 13 and 17", std::string("round") + " 3",
                                  std::string("stop") + " 45", std::string("#five-paths-session") + "-17"})
    EXPECT_TRUE(std::regex_search(text, kWorkLabel)) << text;
  for (const char* text : {"(round 2 of 3)", "round 1/5", "11 rounds in turn", "sessions", "a stop",
                           "one session", "nonstop 4", "per round 0.88"})
    EXPECT_FALSE(std::regex_search(text, kWorkLabel)) << text;
}

TEST(ProjectText, NoFileCarriesAnIssueNumberOrAWorkLabel) {
  std::string why;
  const std::vector<std::string> files = trackedFiles(why);
  if (files.empty()) {
    if (msf::test::underCi())
      FAIL() << why << "; CI=true runs from a git clone";
    GTEST_SKIP() << "not a git checkout: " << why;
  }
  std::ostringstream found;
  std::size_t count = 0;
  for (const std::string& file : files) {
    if (file == "tests/common/test_project_text.cpp") // its own patterns and examples
      continue;
    const std::vector<std::string> lines = linesOf(msf::test::sourceDir() + "/" + file);
    for (std::size_t i = 0; i < lines.size(); ++i) {
      const std::string& line = lines[i];
      if (line.find('\0') != std::string::npos)
        break; // a binary file
      if (!mayMatch(line))
        continue;
      std::smatch m;
      if (std::regex_search(line, m, kIssueReference) || std::regex_search(line, m, kWorkLabel)) {
        found << "\n  " << file << ":" << i + 1 << ": \"" << m.str() << "\" in: " << line.substr(0, 160);
        ++count;
      }
    }
  }
  EXPECT_EQ(count, 0u) << "issue numbers or round-of-work labels (say what is true today; git "
                          "keeps the history):"
                       << found.str();
}

} // namespace
