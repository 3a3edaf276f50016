// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <stdexcept>
#include <string>
#include <utility>

namespace msf {

/// Base of every exception the library throws; the message names the file, key or value at fault.
class Error : public std::runtime_error {
public:
  using std::runtime_error::runtime_error;
};

/// A file that cannot be read or written, or whose content is malformed. When the system says
/// why (a missing file, one that exists), path() names the file and code() is the errno value
/// (ENOENT, EEXIST, ...); the Python door raises it as the matching built-in OSError subclass.
class IOError : public Error {
public:
  using Error::Error;
  IOError(const std::string& message, std::string path, int code)
      : Error(message), path_(std::move(path)), code_(code) {}
  /// The file at fault, "" when the error is not one file's.
  const std::string& path() const { return path_; }
  /// The errno value of the condition, 0 when there is none (malformed content, say).
  int code() const { return code_; }

private:
  std::string path_;
  int code_ = 0;
};

/// A calibration that is missing a key or has a matrix of the wrong size.
class CalibrationError : public Error {
public:
  using Error::Error;
};

/// A configuration key with a wrong type or an out-of-range value.
class ConfigError : public Error {
public:
  using Error::Error;
};

/// Input data a stage cannot work on: an unorganized cloud where an organized one is
/// needed, clouds of different sizes, an empty cloud, NaN where a value is required.
class InvalidInputError : public Error {
public:
  using Error::Error;
};

} // namespace msf
