// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/batch/subprocess.h>
#include <msf/common/exceptions.h>

#include <cerrno>
#include <cstring>
#include <fcntl.h>
#include <poll.h>
#include <sys/wait.h>
#include <unistd.h>

namespace msf {

namespace {

int statusOf(int raw) { return WIFEXITED(raw) ? WEXITSTATUS(raw) : WIFSIGNALED(raw) ? 128 + WTERMSIG(raw) : 1; }

std::vector<char*> cArguments(const std::vector<std::string>& argv) {
  std::vector<char*> args;
  for (const std::string& a : argv)
    args.push_back(const_cast<char*>(a.c_str()));
  args.push_back(nullptr);
  return args;
}

/// Forks `argv` with its standard output and error on `out` and `err`. The exec's failure
/// comes back through a close-on-exec pipe, so that a program that cannot be run is an error
/// here rather than a child's exit code.
pid_t spawn(const std::vector<std::string>& argv, int out, int err) {
  if (argv.empty())
    throw IOError("no program to run");
  int report[2];
  if (::pipe2(report, O_CLOEXEC) != 0)
    throw IOError(std::string("cannot run '") + argv[0] + "': " + std::strerror(errno));
  std::vector<char*> args = cArguments(argv);
  const pid_t pid = ::fork();
  if (pid < 0) {
    ::close(report[0]);
    ::close(report[1]);
    throw IOError(std::string("cannot run '") + argv[0] + "': " + std::strerror(errno));
  }
  if (pid == 0) {
    const int in = ::open("/dev/null", O_RDONLY);
    ::dup2(in, STDIN_FILENO);
    ::dup2(out, STDOUT_FILENO);
    ::dup2(err, STDERR_FILENO);
    ::execvp(args[0], args.data());
    const int e = errno;
    (void)!::write(report[1], &e, sizeof e);
    ::_exit(127);
  }
  ::close(report[1]);
  int e = 0;
  const ssize_t got = ::read(report[0], &e, sizeof e);
  ::close(report[0]);
  if (got == static_cast<ssize_t>(sizeof e)) {
    int raw = 0;
    ::waitpid(pid, &raw, 0);
    throw IOError("cannot run '" + argv[0] + "': " + std::strerror(e));
  }
  return pid;
}

} // namespace

Subprocess::Subprocess(const std::vector<std::string>& argv, const std::string& log) {
  const int fd = ::open(log.c_str(), O_WRONLY | O_CREAT | O_APPEND | O_CLOEXEC, 0644);
  if (fd < 0)
    throw IOError("cannot open log '" + log + "': " + std::strerror(errno));
  try {
    pid_ = spawn(argv, fd, fd);
  } catch (...) {
    ::close(fd);
    throw;
  }
  ::close(fd);
}

Subprocess::~Subprocess() {
  if (pid_ > 0 && !done_)
    wait();
}

int Subprocess::wait() {
  while (!done_) {
    int raw = 0;
    const pid_t r = ::waitpid(pid_, &raw, 0);
    if (r == pid_) {
      done_ = true;
      status_ = statusOf(raw);
    } else if (r < 0 && errno != EINTR) {
      done_ = true;
      status_ = 1;
    }
  }
  return status_;
}

bool Subprocess::finished(int& status) {
  if (!done_) {
    int raw = 0;
    const pid_t r = ::waitpid(pid_, &raw, WNOHANG);
    if (r == pid_) {
      done_ = true;
      status_ = statusOf(raw);
    } else if (r < 0 && errno != EINTR) {
      done_ = true;
      status_ = 1;
    }
  }
  status = status_;
  return done_;
}

CommandOutput captureCommand(const std::vector<std::string>& argv) {
  int out[2], err[2];
  if (::pipe2(out, O_CLOEXEC) != 0)
    throw IOError("cannot run '" + (argv.empty() ? std::string() : argv[0]) + "': " + std::strerror(errno));
  if (::pipe2(err, O_CLOEXEC) != 0) {
    ::close(out[0]);
    ::close(out[1]);
    throw IOError("cannot run '" + (argv.empty() ? std::string() : argv[0]) + "': " + std::strerror(errno));
  }
  pid_t pid = -1;
  try {
    pid = spawn(argv, out[1], err[1]);
  } catch (...) {
    for (int fd : {out[0], out[1], err[0], err[1]})
      ::close(fd);
    throw;
  }
  ::close(out[1]);
  ::close(err[1]);
  CommandOutput result;
  pollfd fds[2] = {{out[0], POLLIN, 0}, {err[0], POLLIN, 0}};
  std::string* sinks[2] = {&result.out, &result.err};
  int open_pipes = 2;
  char buffer[4096];
  while (open_pipes > 0) {
    if (::poll(fds, 2, -1) < 0 && errno != EINTR)
      break;
    for (int k = 0; k < 2; ++k) {
      if (fds[k].fd < 0 || !(fds[k].revents & (POLLIN | POLLHUP | POLLERR)))
        continue;
      const ssize_t n = ::read(fds[k].fd, buffer, sizeof buffer);
      if (n > 0) {
        sinks[k]->append(buffer, static_cast<std::size_t>(n));
      } else if (n == 0 || errno != EINTR) {
        ::close(fds[k].fd);
        fds[k].fd = -1;
        --open_pipes;
      }
    }
  }
  int raw = 0;
  while (::waitpid(pid, &raw, 0) < 0 && errno == EINTR) {
  }
  result.status = statusOf(raw);
  return result;
}

std::string shellQuote(const std::string& word) {
  if (!word.empty() && word.find_first_not_of("abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-+=/.,:%@") ==
                           std::string::npos)
    return word;
  std::string quoted = "'";
  for (const char c : word)
    quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string shellQuote(const std::vector<std::string>& argv) {
  std::string line;
  for (const std::string& a : argv)
    line += (line.empty() ? "" : " ") + shellQuote(a);
  return line;
}

} // namespace msf
