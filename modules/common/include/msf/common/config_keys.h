// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cstddef>
#include <iosfwd>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

/// Configuration keys declared once. A stage's Config struct has its defaults as in-class
/// initializers, its section name, and one function that names each key with its range (or
/// allowed words) and its one-line meaning with units:
///
///   struct RingSplitConfig {
///     static constexpr const char* kSection = "rings";
///     static constexpr const char* kAbout = "the ring hold-out of evaluation protocol 2";
///     int modulo = 4;
///     template <class Keys> void keys(Keys& k) {
///       k("modulo", modulo, atLeast(2), "rings with id % modulo == heldout_remainder are held out");
///     }
///     void validate() const; // checkKeyRanges(*this), then the checks between keys
///   };
///
/// Reading (ConfigFile::read, msf/common/config.h), range checks, printing and the
/// documentation all visit that one list. A visitor is called as
///   k(name, bool&, meaning)
///   k(name, int& | unsigned& | float& | double& | std::vector<double>&, Range, meaning)
///   k(name, std::string&, {"word", ...}, meaning)
///   k(name, Enum&, const Choice<Enum> (&)[N], meaning)
///   k.removed(name, why)   a key that was removed: refused with `why` when a file holds it
namespace msf {

/// The values a number key takes: from min to max, each end closed, open or absent.
struct Range {
  double min = -std::numeric_limits<double>::infinity();
  double max = std::numeric_limits<double>::infinity();
  bool min_open = false, max_open = false;

  /// False for NaN.
  bool contains(double value) const;
  /// "1..11", ">= 0", "> 0", "<= 40", "(0, 1]", "[0, 1)"; "" for any number.
  std::string text() const;
};
/// [min, max]
constexpr Range between(double min, double max) { return {min, max}; }
/// >= min
constexpr Range atLeast(double min) { return {min}; }
/// > min
constexpr Range above(double min) { return {min, std::numeric_limits<double>::infinity(), true}; }
/// Any finite number.
constexpr Range anyNumber() { return {}; }

/// One word of an enum key and the value it stands for.
template <class E>
struct Choice {
  const char* word;
  E value;
};

/// The word of `value` in `choices` ("?" when it has none).
template <class E, std::size_t N>
const char* wordOf(const Choice<E> (&choices)[N], E value) {
  for (const Choice<E>& c : choices)
    if (c.value == value)
      return c.word;
  return "?";
}

/// The value of `word` in `choices`, nullopt when it is none of them.
template <class E, std::size_t N>
std::optional<E> choiceOf(const Choice<E> (&choices)[N], std::string_view word) {
  for (const Choice<E>& c : choices)
    if (word == c.word)
      return c.value;
  return std::nullopt;
}

/// "a | b | c"
std::string wordList(const char* const* words, std::size_t n);
template <class E, std::size_t N>
std::string wordList(const Choice<E> (&choices)[N]) {
  const char* words[N];
  for (std::size_t i = 0; i < N; ++i)
    words[i] = choices[i].word;
  return wordList(words, N);
}

/// A value as a config file holds it, so that a reader (ours, PyYAML) reads back the very same
/// value: numbers in the fewest digits that do (0.1f as 0.1, not 0.100000001), real numbers
/// with a decimal point before any exponent (1.0e-05: YAML 1.1 reads 1e-05 as text), .inf and
/// .nan, booleans as true / false, sequences as [0, 5, 0.25].
std::string configValue(bool value);
std::string configValue(int value);
std::string configValue(unsigned value);
std::string configValue(float value);
std::string configValue(double value);
std::string configValue(const std::vector<double>& values);

/// One key as the documentation and the printed file show it.
struct KeyText {
  std::string name;    ///< the key in its section
  std::string value;   ///< configValue of the value
  std::string range;   ///< Range::text, the words "a | b", "" for a boolean
  std::string meaning; ///< one line, with units
};

namespace detail {

/// Lists every key with its value's text.
class KeyLister {
public:
  void operator()(const char* name, bool value, const char* meaning);
  void operator()(const char* name, int value, const Range& range, const char* meaning);
  void operator()(const char* name, unsigned value, const Range& range, const char* meaning);
  void operator()(const char* name, float value, const Range& range, const char* meaning);
  void operator()(const char* name, double value, const Range& range, const char* meaning);
  void operator()(const char* name, const std::vector<double>& value, const Range& range, const char* meaning);
  template <std::size_t N>
  void operator()(const char* name, const std::string& value, const char* const (&words)[N], const char* meaning) {
    keys.push_back({name, value, wordList(words, N), meaning});
  }
  template <class E, std::size_t N>
  void operator()(const char* name, E value, const Choice<E> (&choices)[N], const char* meaning) {
    keys.push_back({name, wordOf(choices, value), wordList(choices), meaning});
  }
  void removed(const char*, const char*) {}

  std::vector<KeyText> keys;
};

/// Throws ConfigError naming `section.key` for the first value outside its range or words.
class KeyRangeCheck {
public:
  explicit KeyRangeCheck(const char* section) : section_(section) {}
  void operator()(const char*, bool, const char*) {}
  void operator()(const char* name, int value, const Range& range, const char*);
  void operator()(const char* name, unsigned value, const Range& range, const char*);
  void operator()(const char* name, float value, const Range& range, const char*);
  void operator()(const char* name, double value, const Range& range, const char*);
  void operator()(const char* name, const std::vector<double>& value, const Range& range, const char*);
  template <std::size_t N>
  void operator()(const char* name, const std::string& value, const char* const (&words)[N], const char*) {
    for (const char* word : words)
      if (value == word)
        return;
    fail(name, "must be " + wordList(words, N) + ", not '" + value + "'");
  }
  template <class E, std::size_t N>
  void operator()(const char* name, E value, const Choice<E> (&choices)[N], const char*) {
    if (std::string_view(wordOf(choices, value)) == "?")
      fail(name, "must be " + wordList(choices) + ", not a value without a word");
  }
  void removed(const char*, const char*) {}

private:
  [[noreturn]] void fail(const char* name, const std::string& why) const;
  void check(const char* name, double value, const Range& range, const std::string& text) const;
  const char* section_;
};

} // namespace detail

/// Every key of `config` in its declared order, with its value.
template <class Config>
std::vector<KeyText> listKeys(const Config& config) {
  Config copy = config; // keys() is one function for reading and writing; this visitor only reads
  detail::KeyLister lister;
  copy.keys(lister);
  return lister.keys;
}

/// Throws ConfigError naming `section.key` (ConfigError "stereo.block_size_px must be in
/// 1..11, not 12") for the first value of `config` outside its range or words: the first step
/// of every Config's validate().
template <class Config>
void checkKeyRanges(const Config& config) {
  Config copy = config;
  detail::KeyRangeCheck check(Config::kSection);
  copy.keys(check);
}

/// `text` as YAML comment lines ("# ...") after `indent`, wrapped at 100 columns.
void printComment(std::ostream& out, const std::string& indent, const std::string& text);

/// A section as a config file holds it: "section:", then "  key: value" for each key; with
/// `comments`, each key's meaning and [range] on the lines above it.
void printSection(std::ostream& out, const std::string& section, const std::vector<KeyText>& keys,
                  bool comments = false);

/// Every key of `config` under its section, as a config file holds it.
template <class Config>
void printConfig(std::ostream& out, const Config& config) {
  printSection(out, Config::kSection, listKeys(config));
}

} // namespace msf
