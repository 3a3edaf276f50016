// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/exceptions.h>
#include <msf/common/huge_page_images.h>
#include <msf/common/message_text.h>
#include <msf/common/tool.h>
#include <msf/common/version.h>

#include <pcl/console/print.h>

#include <algorithm>
#include <cerrno>
#include <climits>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <exception>
#include <filesystem>
#include <limits>
#include <map>
#include <sstream>
#include <type_traits>

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

bool wantsVersion(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "--version") || !std::strcmp(argv[i], "-version"))
      return true;
  return false;
}

std::string versionLine(const std::string& name) {
  return name + " (msfusion) " + versionString() + ", commit " + gitCommit();
}

bool wantsHelp(int argc, char** argv) {
  for (int i = 1; i < argc; ++i)
    if (!std::strcmp(argv[i], "-h") || !std::strcmp(argv[i], "--help") || !std::strcmp(argv[i], "-help"))
      return true;
  return false;
}

namespace {

[[noreturn]] void notANumber(const std::string& option, const std::string& text, const char* kind) {
  throw InvalidInputError(option + " needs " + kind + ", not " + quoted(text));
}

template <typename T>
T parseNumber(const std::string& option, const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  if constexpr (std::is_same_v<T, int>) {
    const long v = std::strtol(begin, &end, 10);
    if (end == begin || *end != '\0')
      notANumber(option, text, "a whole number");
    // A value past int's range is refused, not wrapped or clamped.
    if (errno == ERANGE || v < INT_MIN || v > INT_MAX)
      throw InvalidInputError(option + " must be a whole number in " + std::to_string(INT_MIN) + " .. " +
                              std::to_string(INT_MAX) + ", not " + quoted(text));
    return static_cast<int>(v);
  } else {
    const double v = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || (!std::isfinite(v) && errno != ERANGE)) // "nan", "inf" as such
      notANumber(option, text, "a number");
    // Overflow gives inf and underflow a subnormal or 0 with ERANGE: neither is the value given.
    if (errno == ERANGE || std::abs(v) > std::numeric_limits<T>::max())
      throw InvalidInputError(option + " needs a finite number within the range of a " +
                              (std::is_same_v<T, float> ? "float" : "double") + ", not " + quoted(text));
    return static_cast<T>(v);
  }
}

template <typename T>
std::function<void(const std::string&)> numberInto(const std::string& option, T& target) {
  return [option, &target](const std::string& text) { target = parseNumber<T>(option, text); };
}

template <typename T>
std::string defaultText(const T& value) {
  std::ostringstream s;
  s << value; // 6 significant digits, as %g
  return s.str();
}

bool isOption(const char* arg) {
  // "-5" or "-0.3" are values, not options.
  return arg[0] == '-' && arg[1] != '\0' && !(arg[1] >= '0' && arg[1] <= '9') && arg[1] != '.';
}

constexpr std::size_t kWidth = 100; // columns of the help
constexpr std::size_t kLabelWidth = 22; // longer "-option METAVAR" put their help on the next line

/// `text` wrapped to kWidth columns, every line indented by `indent` spaces. A line break in
/// it is kept; a line that fits is kept as written (a table keeps its columns), and a longer
/// one continues under its first word, or under the text after its first run of two spaces
/// (a table's second column).
std::string wrap(const std::string& text, std::size_t indent) {
  std::string out;
  std::istringstream lines(text);
  std::string line;
  while (std::getline(lines, line)) {
    const std::size_t lead = std::min(line.find_first_not_of(' '), line.size());
    if (lead == line.size()) {
      out += "\n";
      continue;
    }
    std::string margin(indent + lead, ' ');
    if (margin.size() + line.size() - lead <= kWidth) {
      out += margin + line.substr(lead) + "\n";
      continue;
    }
    std::size_t body = lead;
    const std::size_t gap = line.find("  ", lead);
    if (gap != std::string::npos && line.find_first_not_of(' ', gap) != std::string::npos)
      body = line.find_first_not_of(' ', gap);
    std::string current = line.substr(lead, body - lead); // the first column as written
    bool has_word = false;
    std::istringstream words(line.substr(body));
    std::string word;
    while (words >> word) {
      if (has_word && margin.size() + current.size() + 1 + word.size() > kWidth) {
        out += margin + current + "\n";
        margin.assign(indent + body, ' ');
        current.clear();
        has_word = false;
      }
      current += (has_word ? " " : "") + word;
      has_word = true;
    }
    out += margin + current + "\n";
  }
  return out;
}

} // namespace

CommandLine::CommandLine(std::string name, std::string usage, std::string about)
    : name_(std::move(name)), usage_(std::move(usage)), about_(std::move(about)) {}

CommandLine& CommandLine::add(const std::string& option, const std::string& metavar,
                              std::function<void(const std::string&)> apply, const std::string& help,
                              const std::string& default_text, const void* target) {
  std::string text = help;
  for (std::size_t at; (at = text.find("{default}")) != std::string::npos;)
    text.replace(at, 9, default_text);
  options_.push_back({option, metavar, text, std::move(apply), target});
  return *this;
}

CommandLine& CommandLine::value(const std::string& option, const std::string& metavar, std::string& target,
                                const std::string& help) {
  return add(option, metavar, [&target](const std::string& text) { target = text; }, help, target, &target);
}
CommandLine& CommandLine::value(const std::string& option, const std::string& metavar, int& target,
                                const std::string& help) {
  return add(option, metavar, numberInto(option, target), help, defaultText(target), &target);
}
CommandLine& CommandLine::value(const std::string& option, const std::string& metavar, float& target,
                                const std::string& help) {
  return add(option, metavar, numberInto(option, target), help, defaultText(target), &target);
}
CommandLine& CommandLine::value(const std::string& option, const std::string& metavar, double& target,
                                const std::string& help) {
  return add(option, metavar, numberInto(option, target), help, defaultText(target), &target);
}
CommandLine& CommandLine::value(const std::string& option, const std::string& metavar,
                                std::function<void(const std::string&)> apply, const std::string& help) {
  return add(option, metavar, std::move(apply), help, "");
}
CommandLine& CommandLine::flag(const std::string& option, bool& target, const std::string& help) {
  return add(option, "", [&target](const std::string&) { target = true; }, help, target ? "on" : "off");
}

CommandLine& CommandLine::note(const std::string& text) {
  notes_.push_back(text);
  return *this;
}

CommandLine& CommandLine::overwriteOption(bool& target) {
  return flag("-overwrite", target, "replace output files that exist (without it, they are refused before the run)");
}

void CommandLine::printHelp(const char* program) const {
  std::istringstream forms(usage_);
  std::string form;
  for (bool first = true; std::getline(forms, form); first = false)
    pcl::console::print_error("%s %s %s\n", first ? "Syntax is:" : "       or:", program, form.c_str());
  pcl::console::print_info("%s", wrap(about_, 2).c_str());
  if (!options_.empty()) {
    pcl::console::print_info("  where options are:\n");
    std::size_t label_width = 0;
    for (const Option& o : options_) {
      const std::size_t label = o.name.size() + (o.metavar.empty() ? 0 : 1 + o.metavar.size());
      if (label <= kLabelWidth)
        label_width = std::max(label_width, label);
    }
    const std::size_t column = 4 + label_width + 2;
    for (const Option& o : options_) {
      std::string label = "    " + o.name + (o.metavar.empty() ? "" : " " + o.metavar);
      std::string help = wrap(o.help, column);
      if (label.size() + 2 <= column && help.size() > column)
        help.replace(0, label.size(), label);
      else
        help = label + "\n" + help;
      pcl::console::print_info("%s", help.c_str());
    }
  }
  for (const std::string& note : notes_)
    pcl::console::print_info("%s", wrap(note, 2).c_str());
  pcl::console::print_info("%s\n", versionLine(name_).c_str());
}

Arguments CommandLine::parse(int argc, char** argv) {
  Arguments positional;
  std::map<std::string, std::string> values;
  given_.clear();
  for (int i = 1; i < argc; ++i) {
    if (!isOption(argv[i])) {
      positional.emplace_back(argv[i]);
      continue;
    }
    const auto o = std::find_if(options_.begin(), options_.end(), [&](const Option& d) { return d.name == argv[i]; });
    if (o == options_.end())
      throw InvalidInputError(std::string("unknown option '") + argv[i] + "' (see -h)");
    std::string text;
    if (!o->metavar.empty()) {
      if (i + 1 >= argc)
        throw InvalidInputError(std::string("option '") + argv[i] + "' needs a value");
      text = argv[++i];
    }
    const auto [given, first] = values.emplace(o->name, text);
    if (!first && given->second != text)
      throw InvalidInputError("option '" + o->name + "' is given twice, '" + given->second + "' and '" +
                              text + "': give it once");
  }
  requireOneValuePerSetting(values);
  for (const Option& o : options_) {
    const auto v = values.find(o.name);
    if (v == values.end())
      continue;
    given_.push_back(o.name);
    o.apply(v->second);
  }
  return positional;
}

void CommandLine::requireOneValuePerSetting(const std::map<std::string, std::string>& values) const {
  std::map<const void*, std::pair<std::string, std::string>> by_setting; // target -> option, value
  for (const Option& o : options_) {
    const auto v = values.find(o.name);
    if (!o.target || v == values.end())
      continue;
    const auto [other, first] = by_setting.emplace(o.target, std::pair(o.name, v->second));
    if (!first && other->second.second != v->second)
      throw InvalidInputError("options '" + other->second.first + "' and '" + o.name + "' set one thing, given '" +
                              other->second.second + "' and '" + v->second + "': give one of them");
  }
}

bool CommandLine::given(const std::string& option) const {
  return std::find(given_.begin(), given_.end(), option) != given_.end();
}

std::vector<std::string> CommandLine::flags() const {
  std::vector<std::string> names;
  for (const Option& o : options_)
    if (o.metavar.empty())
      names.push_back(o.name);
  return names;
}

int CommandLine::run(int argc, char** argv, int min_arguments, const std::function<int(const Arguments&)>& body) {
  if (wantsVersion(argc, argv) && !wantsHelp(argc, argv)) {
    std::printf("%s\n", versionLine(name_).c_str());
    return 0;
  }
  const bool help = wantsHelp(argc, argv);
  if (help || argc - 1 < min_arguments) {
    printHelp(argv[0]);
    return help ? 0 : 1;
  }
  useHugePagesForLargeImages();
  return tool::run(name_.c_str(), [&] { return body(parse(argc, argv)); });
}

void requireNewOutputs(const std::vector<std::string>& outputs, bool overwrite) {
  for (const std::string& path : outputs) {
    if (path.empty())
      continue;
    std::error_code ec;
    if (std::filesystem::is_directory(path, ec))
      throw IOError("output '" + path + "' is a folder, not a file");
    if (!overwrite && std::filesystem::exists(std::filesystem::symlink_status(path, ec)))
      throw IOError("output '" + path + "' exists; give -overwrite to replace it", path, EEXIST);
    requireWritableFolder(path);
  }
}

void printDone(double milliseconds, std::size_t count, const char* counted) {
  pcl::console::print_info("[done, ");
  pcl::console::print_value("%g", milliseconds);
  pcl::console::print_info(" ms : ");
  pcl::console::print_value("%zu", count);
  pcl::console::print_info(" %s]\n", counted);
}

} // namespace msf::tool
