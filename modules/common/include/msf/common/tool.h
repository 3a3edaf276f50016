// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstddef>
#include <functional>
#include <map>
#include <string>
#include <vector>

/// Small helpers shared by the msf_* command-line tools (tools/*.cpp), which otherwise
/// follow PCL's tools: the help's layout, a strict option parser, TicToc done lines.
namespace msf::tool {

/// Runs `body`; any exception becomes "<name>: error: <message>" on stderr and exit code 1.
int run(const char* name, const std::function<int()>& body);

/// True when -h, --help or -help is among the arguments.
bool wantsHelp(int argc, char** argv);
/// True when --version or -version is among the arguments.
bool wantsVersion(int argc, char** argv);
/// "<name> (msfusion) <version>, commit <commit>": what --version prints, and the help's last line.
std::string versionLine(const std::string& name);

/// A tool's command line, each option declared once: its name, whether it takes a value,
/// its help and where its value goes. The help, the check that every option given is
/// declared and the parsing all come from these declarations.
///
///   std::string calib;
///   int camera = 0;
///   bool ascii = false;
///   msf::tool::CommandLine cli("msf_project", "<scan.bin> <out.pcd> -calib PATH [options]", "Projects a scan.");
///   cli.value("-calib", "PATH", calib, "calibration file")
///       .value("-camera", "N", camera, "rectified camera 0..3 (default {default})")
///       .flag("-ascii", ascii, "write ASCII");
///   return cli.run(argc, argv, 2, [&](const msf::tool::Arguments& files) { ...; return 0; });
///
/// A target's value when it is declared is the option's default: "{default}" in the help
/// becomes it. Numbers are read strictly (PCL reads "abc" or "2x" as 0 or 2): a value that is
/// not wholly a number (a whole one for int) throws InvalidInputError naming the option and
/// the value. Options are applied in the order they are declared, not in the order given, so
/// that a -config declared first (a callback that reads the file) is overridden by the options
/// declared after it. An option given twice with two values is an error (PCL's parser keeps
/// the first, a shell's habit is the last: either would surprise someone), and so are two
/// names of one setting (-calib and -rig) given different values.
/// Unknown options are errors: PCL's parser ignores them, and a typo should not silently do
/// the default. "-5" or "-0.3" are values, not options.
using Arguments = std::vector<std::string>;

class CommandLine {
public:
  /// `usage`: what follows the program's name in "Syntax is: <program> ..." (more forms on
  /// lines of their own); `about`: what the tool does, printed before the options.
  CommandLine(std::string name, std::string usage, std::string about);

  /// An option with a value (-option METAVAR): into `target`, or through `apply`.
  CommandLine& value(const std::string& option, const std::string& metavar, std::string& target,
                     const std::string& help);
  CommandLine& value(const std::string& option, const std::string& metavar, int& target, const std::string& help);
  CommandLine& value(const std::string& option, const std::string& metavar, float& target, const std::string& help);
  CommandLine& value(const std::string& option, const std::string& metavar, double& target, const std::string& help);
  CommandLine& value(const std::string& option, const std::string& metavar,
                     std::function<void(const std::string&)> apply, const std::string& help);
  /// A flag (-option): `target` becomes true when it is given.
  CommandLine& flag(const std::string& option, bool& target, const std::string& help);
  /// A paragraph of the help after the options.
  CommandLine& note(const std::string& text);
  /// Declares -overwrite into `target`, for a tool that writes files the user names: what
  /// requireNewOutputs() is told.
  CommandLine& overwriteOption(bool& target);

  /// "Syntax is: ..." on stderr, the rest on stdout (PCL's print_error and print_info), the
  /// texts wrapped to 100 columns; a line break in a text is kept, with its indentation.
  void printHelp(const char* program) const;

  /// Checks the options (unknown ones, a value missing at the end), applies them and returns
  /// the positional arguments.
  Arguments parse(int argc, char** argv);
  /// After parse(): whether `option` was given.
  bool given(const std::string& option) const;
  /// The names of the flags, in the order declared.
  std::vector<std::string> flags() const;

  /// A tool's main: versionLine() and exit code 0 on --version (wantsVersion), the help and
  /// exit code 0 on -h (wantsHelp), the help and 1 with fewer than
  /// `min_arguments` arguments, else parse() and `body` with the positional arguments under
  /// run(), whose exceptions become "<name>: error: ..." and 1.
  int run(int argc, char** argv, int min_arguments, const std::function<int(const Arguments&)>& body);

private:
  struct Option {
    std::string name, metavar, help; // no metavar: a flag
    std::function<void(const std::string&)> apply;
    const void* target = nullptr; // the setting it writes, when known: two names of one setting share it
  };
  /// Throws InvalidInputError when two options of one target were given different values.
  void requireOneValuePerSetting(const std::map<std::string, std::string>& values) const;
  CommandLine& add(const std::string& option, const std::string& metavar, std::function<void(const std::string&)> apply,
                   const std::string& help, const std::string& default_text, const void* target = nullptr);

  std::string name_, usage_, about_;
  std::vector<Option> options_;
  std::vector<std::string> notes_;
  std::vector<std::string> given_;
};

/// Before any work: throws IOError naming the first of `outputs` ("" is skipped) that is a
/// folder, that exists while `overwrite` (-overwrite) is false (so that nothing of the user's
/// is written over), or whose folder is missing or not writable (requireWritableFolder).
void requireNewOutputs(const std::vector<std::string>& outputs, bool overwrite);

/// Prints PCL's done line with what was counted: "[done, 12.3 ms : 465750 points]".
void printDone(double milliseconds, std::size_t count, const char* counted);

} // namespace msf::tool
