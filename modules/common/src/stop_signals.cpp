// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/common/stop_signals.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstring>
#include <signal.h>
#include <unistd.h>

namespace msf::tool {

namespace {

std::atomic<int> g_requests{0};
std::atomic<bool> g_stop{false};
static_assert(std::atomic<int>::is_always_lock_free && std::atomic<bool>::is_always_lock_free,
              "the signal handler needs lock-free atomics");
// The messages, kept for the life of the process: a handler may only read them.
std::vector<std::string>* g_messages = nullptr;

/// Discards SIGPIPE from now on (async-signal-safe): once a reader has gone, each write to it
/// raises one more, this handler's own message to a closed stderr included, and none of them is
/// a new request; the writes fail with EPIPE instead.
void ignoreBrokenPipes() {
  struct sigaction ignore {};
  ignore.sa_handler = SIG_IGN;
  sigemptyset(&ignore.sa_mask);
  ::sigaction(SIGPIPE, &ignore, nullptr);
}

void onStopSignal(int) {
  const int saved_errno = errno;
  ignoreBrokenPipes();
  const int n = ++g_requests;
  g_stop = true;
  if (g_messages && !g_messages->empty()) {
    const std::string& text = (*g_messages)[std::min<std::size_t>(n, g_messages->size()) - 1];
    // write(2) only: the one output that is safe in a signal handler; a closed stderr is no matter.
    if (::write(STDERR_FILENO, text.data(), text.size()) < 0) {
    }
  }
  errno = saved_errno;
}

} // namespace

void installStopSignals(const std::vector<std::string>& messages) {
  static std::vector<std::string> kept;
  kept.clear();
  for (const std::string& m : messages)
    kept.push_back("\n" + m + "\n");
  g_messages = &kept;
  struct sigaction action {};
  action.sa_handler = onStopSignal;
  sigemptyset(&action.sa_mask);
  action.sa_flags = SA_RESTART; // a write under way when a signal comes goes on
  for (int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGPIPE})
    if (::sigaction(signal_number, &action, nullptr) != 0)
      throw IOError(std::string("cannot install the handler of ") + ::strsignal(signal_number) + ": " +
                    std::strerror(errno));
}

int stopRequests() { return g_requests.load(); }

const std::atomic<bool>& stopFlag() { return g_stop; }

} // namespace msf::tool
