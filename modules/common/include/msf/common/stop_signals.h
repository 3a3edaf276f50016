// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <atomic>
#include <string>
#include <vector>

namespace msf::tool {

/// Makes SIGINT, SIGTERM, SIGHUP (a closed terminal) and SIGPIPE (`| head`) requests to stop
/// instead of deaths, so that a tool ends its work cleanly: no partial output, no temporary
/// left. The k-th signal prints messages[k-1] on stderr (the last one for later signals);
/// the tool polls stopRequests() at the points where it can stop. After the first request
/// SIGPIPE is ignored: writes to a reader that went fail with EPIPE instead of each being
/// another request (a `| head` that exits, or a `| tee` that a Ctrl-C ended with the tool).
/// Throws IOError when a handler cannot be installed.
void installStopSignals(const std::vector<std::string>& messages);

/// How many stop signals have come since installStopSignals.
int stopRequests();
/// True once a stop signal has come: what a loop that takes a stop flag polls.
const std::atomic<bool>& stopFlag();

} // namespace msf::tool
