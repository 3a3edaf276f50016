// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/stereo/parallel_post_filter.h>

#include <atomic>

namespace msf {

namespace {
std::atomic<bool> parallel_post_filter{true};
} // namespace

void setParallelPostFilterEnabled(bool enabled) { parallel_post_filter.store(enabled); }

bool parallelPostFilterEnabled() { return parallel_post_filter.load(); }

} // namespace msf
