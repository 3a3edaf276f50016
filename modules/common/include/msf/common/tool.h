#pragma once
#include <cstddef>
#include <functional>
#include <string>
#include <vector>

/// Small helpers shared by the msf_* command-line tools (tools/*.cpp), which otherwise
/// follow PCL's tools: printHelp, parse_argument (here strict: parseArgument), TicToc done lines.
namespace msf::tool {

/// Runs `body`; any exception becomes "<name>: error: <message>" on stderr and exit code 1.
int run(const char* name, const std::function<int()>& body);

/// True when -h, --help or -help is among the arguments.
bool wantsHelp(int argc, char** argv);

/// A tool's main: `print_help` and exit code 0 on -h (wantsHelp), `print_help` and 1 with
/// fewer than `min_argc` arguments (the program's name counts), else `body` under run().
int runWithHelp(int argc, char** argv, const char* name, int min_argc, void (*print_help)(const char*),
                const std::function<int()>& body);

/// Throws msf::InvalidInputError naming the first argument that starts with '-' and is
/// neither in `value_options` (which consume the next argument) nor in `switches`.
/// PCL's parser ignores unknown options; a typo should not silently do the default.
void checkOptions(int argc, char** argv, const std::vector<std::string>& value_options,
                  const std::vector<std::string>& switches);

/// pcl::console::parse_argument, strictly: the value after `option` into `value`; returns
/// the option's index, or -1 when it is absent. PCL reads "abc" or "2x" as 0 or 2; here a
/// value that is not wholly a number (a whole one for int) throws InvalidInputError naming
/// the option and the value.
int parseArgument(int argc, char** argv, const char* option, std::string& value);
int parseArgument(int argc, char** argv, const char* option, int& value);
int parseArgument(int argc, char** argv, const char* option, float& value);
int parseArgument(int argc, char** argv, const char* option, double& value);

/// Positional (non-option) arguments, skipping the values of `value_options`.
std::vector<std::string> positionalArguments(int argc, char** argv,
                                             const std::vector<std::string>& value_options);

/// Prints PCL's done line: "[done, 12.3 ms : 465750 points]".
void printDone(double milliseconds, std::size_t points);

} // namespace msf::tool
