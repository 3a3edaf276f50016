// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>

#include <algorithm>

namespace msf {

namespace {
thread_local int t_budget = 0;
} // namespace

ThreadBudget::ThreadBudget(int threads) : previous_(t_budget) { t_budget = threads; }

ThreadBudget::~ThreadBudget() { t_budget = previous_; }

int ThreadBudget::current() { return t_budget; }

void parallelFor(const cv::Range& range, const cv::ParallelLoopBody& body, double nstripes) {
  if (t_budget == 1 || range.end - range.start <= 1) {
    if (range.end > range.start)
      body(range);
    return;
  }
  // With a budget of n, at most n stripes: OpenCV runs a stripe on one thread at a time.
  if (t_budget > 1)
    nstripes = nstripes > 0 ? std::min(nstripes, static_cast<double>(t_budget)) : t_budget;
  cv::parallel_for_(range, body, nstripes);
}

void parallelFor(const cv::Range& range, std::function<void(const cv::Range&)> body, double nstripes) {
  parallelFor(range, cv::ParallelLoopBodyLambdaWrapper(std::move(body)), nstripes);
}

} // namespace msf
