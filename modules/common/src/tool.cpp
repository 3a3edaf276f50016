#include <msf/common/exceptions.h>
#include <msf/common/tool.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdlib>
#include <type_traits>
#include <cstdio>
#include <cstring>
#include <exception>

namespace msf::tool {

int run(const char* name, const std::function<int()>& body) {
  try {
    return body();
  } catch (const std::exception& e) {
    // End a progress line ("Loading x ") that the failure cut short.
    std::fputc('\n', stdout);
    std::fflush(stdout);
    std::fprintf(stderr, "%s: error: %s\n", name, e.what());
  } catch (...) {
    std::fprintf(stderr, "%s: error: unknown exception\n", name);
  }
  return 1;
}

bool wantsHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-help"))
      return true;
  return false;
}

int runWithHelp(int argc, char** argv, const char* name, int min_argc, void (*print_help)(const char*),
                const std::function<int()>& body) {
  const bool help = wantsHelp(argc, argv);
  if (help || argc < min_argc) {
    print_help(argv[0]);
    return help ? 0 : 1;
  }
  return run(name, body);
}

namespace {
/// Index of the value after the first `option`, or -1.
int valueIndex(int argc, char** argv, const char* option) {
  for (int i = 1; i + 1 < argc; ++i)
    if (!std::strcmp(argv[i], option))
      return i + 1;
  return -1;
}

[[noreturn]] void notANumber(const char* option, const char* text, const char* kind) {
  throw InvalidInputError(std::string(option) + " needs " + kind + ", not '" + text + "'");
}

template <typename T>
int parseNumber(int argc, char** argv, const char* option, T& value) {
  const int i = valueIndex(argc, argv, option);
  if (i < 0)
    return -1;
  const char* text = argv[i];
  char* end = nullptr;
  errno = 0;
  if constexpr (std::is_same_v<T, int>) {
    const long v = std::strtol(text, &end, 10);
    if (end == text || *end != '\0' || errno == ERANGE || v < INT_MIN || v > INT_MAX)
      notANumber(option, text, "a whole number");
    value = static_cast<int>(v);
  } else {
    const double v = std::strtod(text, &end);
    if (end == text || *end != '\0' || errno == ERANGE || !std::isfinite(v))
      notANumber(option, text, "a number");
    value = static_cast<T>(v);
  }
  return i - 1;
}
} // namespace

int parseArgument(int argc, char** argv, const char* option, std::string& value) {
  const int i = valueIndex(argc, argv, option);
  if (i < 0)
    return -1;
  value = argv[i];
  return i - 1;
}
int parseArgument(int argc, char** argv, const char* option, int& value) {
  return parseNumber(argc, argv, option, value);
}
int parseArgument(int argc, char** argv, const char* option, float& value) {
  return parseNumber(argc, argv, option, value);
}
int parseArgument(int argc, char** argv, const char* option, double& value) {
  return parseNumber(argc, argv, option, value);
}

namespace {
bool contains(const std::vector<std::string>& list, const char* arg) {
  return std::find(list.begin(), list.end(), std::string(arg)) != list.end();
}
bool isOption(const char* arg) {
  // "-5" or "-0.3" are values, not options.
  return arg[0] == '-' && arg[1] != '\0' && !(arg[1] >= '0' && arg[1] <= '9') && arg[1] != '.';
}
} // namespace

void checkOptions(int argc, char** argv, const std::vector<std::string>& value_options,
                  const std::vector<std::string>& switches) {
  for (int i = 1; i < argc; ++i) {
    if (!isOption(argv[i]))
      continue;
    if (contains(value_options, argv[i])) {
      if (i + 1 >= argc)
        throw InvalidInputError(std::string("option '") + argv[i] + "' needs a value");
      ++i;
    } else if (!contains(switches, argv[i])) {
      throw InvalidInputError(std::string("unknown option '") + argv[i] + "' (see -h)");
    }
  }
}

std::vector<std::string> positionalArguments(int argc, char** argv,
                                             const std::vector<std::string>& value_options) {
  std::vector<std::string> out;
  for (int i = 1; i < argc; ++i) {
    if (isOption(argv[i])) {
      if (contains(value_options, argv[i]))
        ++i;
      continue;
    }
    out.emplace_back(argv[i]);
  }
  return out;
}

void printDone(double milliseconds, std::size_t points) {
  pcl::console::print_info("[done, ");
  pcl::console::print_value("%g", milliseconds);
  pcl::console::print_info(" ms : ");
  pcl::console::print_value("%zu", points);
  pcl::console::print_info(" points]\n");
}

} // namespace msf::tool
