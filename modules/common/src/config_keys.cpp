// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/config_keys.h>
#include <msf/common/exceptions.h>

#include <charconv>
#include <cmath>
#include <ostream>

namespace msf {

namespace {

/// The fewest digits that read back to `value`, as std::to_chars writes them (1e-05, 0.25, 5).
template <typename Real>
std::string shortest(Real value) {
  if (std::isnan(value))
    return ".nan";
  if (std::isinf(value))
    return value < 0 ? "-.inf" : ".inf";
  char buffer[64];
  const auto result = std::to_chars(buffer, buffer + sizeof buffer, value);
  return std::string(buffer, result.ptr);
}

/// A real number as YAML 1.1 (PyYAML) reads one: a decimal point in the mantissa, 5.0 and
/// 1.0e-05 rather than the integer 5 and the text 1e-05.
template <typename Real>
std::string realText(Real value) {
  std::string text = shortest(value);
  if (!std::isfinite(value))
    return text;
  const std::size_t exponent = text.find('e');
  const std::size_t mantissa_end = exponent == std::string::npos ? text.size() : exponent;
  if (text.find('.') == std::string::npos)
    text.insert(mantissa_end, ".0");
  return text;
}

} // namespace

bool Range::contains(double value) const {
  if (std::isnan(value))
    return false;
  const bool above_min = min_open ? value > min : value >= min;
  const bool below_max = max_open ? value < max : value <= max;
  return above_min && below_max;
}

std::string Range::text() const {
  const bool low = std::isfinite(min), high = std::isfinite(max);
  if (low && high) {
    if (!min_open && !max_open)
      return shortest(min) + ".." + shortest(max);
    return (min_open ? "(" : "[") + shortest(min) + ", " + shortest(max) + (max_open ? ")" : "]");
  }
  if (low)
    return (min_open ? "> " : ">= ") + shortest(min);
  if (high)
    return (max_open ? "< " : "<= ") + shortest(max);
  return "";
}

std::string wordList(const char* const* words, std::size_t n) {
  std::string text;
  for (std::size_t i = 0; i < n; ++i)
    text += (i ? " | " : "") + std::string(words[i]);
  return text;
}

std::string configValue(bool value) { return value ? "true" : "false"; }

std::string configValue(int value) { return std::to_string(value); }

std::string configValue(unsigned value) { return std::to_string(value); }

std::string configValue(float value) { return realText(value); }

std::string configValue(double value) { return realText(value); }

std::string configValue(const std::vector<double>& values) {
  // Whole numbers as integers, as people write a list of levels: [0, 5, 10].
  std::string text = "[";
  for (std::size_t i = 0; i < values.size(); ++i) {
    const double v = values[i];
    text += (i ? ", " : "") + (std::isfinite(v) && v == std::trunc(v) && std::fabs(v) < 1e15 ? shortest(v) : realText(v));
  }
  return text + "]";
}

namespace detail {

void KeyLister::operator()(const char* name, bool value, const char* meaning) {
  keys.push_back({name, configValue(value), "", meaning});
}

void KeyLister::operator()(const char* name, int value, const Range& range, const char* meaning) {
  keys.push_back({name, configValue(value), range.text(), meaning});
}

void KeyLister::operator()(const char* name, unsigned value, const Range& range, const char* meaning) {
  keys.push_back({name, configValue(value), range.text(), meaning});
}

void KeyLister::operator()(const char* name, float value, const Range& range, const char* meaning) {
  keys.push_back({name, configValue(value), range.text(), meaning});
}

void KeyLister::operator()(const char* name, double value, const Range& range, const char* meaning) {
  keys.push_back({name, configValue(value), range.text(), meaning});
}

void KeyLister::operator()(const char* name, const std::vector<double>& value, const Range& range,
                           const char* meaning) {
  keys.push_back({name, configValue(value), range.text().empty() ? "" : "each " + range.text(), meaning});
}

void KeyRangeCheck::fail(const char* name, const std::string& why) const {
  throw ConfigError(std::string(section_) + "." + name + " " + why);
}

void KeyRangeCheck::check(const char* name, double value, const Range& range, const std::string& text) const {
  if (range.contains(value) && std::isfinite(value))
    return;
  const std::string bounds = range.text();
  const bool interval = std::isfinite(range.min) && std::isfinite(range.max);
  fail(name, "must be " + std::string(bounds.empty() ? "a finite number" : (interval ? "in " : "") + bounds) +
                 ", not " + text);
}

void KeyRangeCheck::operator()(const char* name, int value, const Range& range, const char*) {
  check(name, value, range, configValue(value));
}

void KeyRangeCheck::operator()(const char* name, unsigned value, const Range& range, const char*) {
  check(name, value, range, configValue(value));
}

void KeyRangeCheck::operator()(const char* name, float value, const Range& range, const char*) {
  check(name, value, range, configValue(value));
}

void KeyRangeCheck::operator()(const char* name, double value, const Range& range, const char*) {
  check(name, value, range, configValue(value));
}

void KeyRangeCheck::operator()(const char* name, const std::vector<double>& value, const Range& range, const char*) {
  for (const double v : value)
    check(name, v, range, configValue(v) + " (in " + configValue(value) + ")");
}

} // namespace detail

void printComment(std::ostream& out, const std::string& indent, const std::string& text) {
  constexpr std::size_t kWidth = 100;
  std::string line;
  std::size_t at = 0;
  while (at < text.size()) {
    const std::size_t space = text.find(' ', at);
    const std::string word = text.substr(at, space == std::string::npos ? std::string::npos : space - at);
    at = space == std::string::npos ? text.size() : space + 1;
    if (!line.empty() && indent.size() + 2 + line.size() + 1 + word.size() > kWidth) {
      out << indent << "# " << line << "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  out << indent << "# " << line << "\n";
}

void printSection(std::ostream& out, const std::string& section, const std::vector<KeyText>& keys, bool comments) {
  out << section << ":\n";
  for (const KeyText& key : keys) {
    if (comments)
      printComment(out, "  ", key.meaning + (key.range.empty() ? "" : " [" + key.range + "]"));
    out << "  " << key.name << ": " << key.value << "\n";
  }
}

} // namespace msf
