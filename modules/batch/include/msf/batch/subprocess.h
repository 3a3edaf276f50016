// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <string>
#include <sys/types.h>
#include <vector>

namespace msf {

/// A program run as a child process, its standard output and error appended to a log file
/// (standard input /dev/null): what a batch task runs, and what the local runner runs side by
/// side. `argv[0]` is looked up on PATH when it has no slash.
class Subprocess {
public:
  /// Starts `argv` with its output appended to `log` (created when missing). Throws IOError
  /// naming the log when it cannot be opened, or the program when it cannot be run.
  Subprocess(const std::vector<std::string>& argv, const std::string& log);
  /// Waits for a child that is still running (a destructor cannot leave a zombie).
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  pid_t pid() const { return pid_; }
  /// Waits for the end: the exit code, or 128 + the signal that ended it.
  int wait();
  /// Without waiting: true, with the status as wait() gives it, once the process has ended.
  bool finished(int& status);

private:
  pid_t pid_ = -1;
  bool done_ = false;
  int status_ = 0;
};

/// What a command printed and how it ended (exit code, or 128 + signal).
struct CommandOutput {
  int status = -1;
  std::string out, err;
};

/// Runs `argv` to its end, capturing its standard output and error. Throws IOError naming the
/// program when it cannot be run.
CommandOutput captureCommand(const std::vector<std::string>& argv);

/// `argv` as a shell would read it back (each word quoted where needed), for logs and scripts.
std::string shellQuote(const std::vector<std::string>& argv);
std::string shellQuote(const std::string& word);

} // namespace msf
