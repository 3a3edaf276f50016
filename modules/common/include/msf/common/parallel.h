// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/utility.hpp>

#include <functional>

namespace msf {

/// The threads the parallel loops of the calling thread may use, for as long as the object
/// lives (a scope): 0 = all of OpenCV's pool, 1 = none but the calling thread, n = at most n
/// at a time. An engine sets it on each of its threads, so that a program that shares the
/// machine (a ROS node, a Python program) keeps the rest. Nested scopes restore the outer
/// budget when they end.
class ThreadBudget {
public:
  explicit ThreadBudget(int threads);
  ~ThreadBudget();
  ThreadBudget(const ThreadBudget&) = delete;
  ThreadBudget& operator=(const ThreadBudget&) = delete;

  /// The calling thread's budget (0 when no scope is open).
  static int current();

private:
  int previous_;
};

/// cv::parallel_for_ within the calling thread's ThreadBudget: the body sees disjoint
/// sub-ranges that cover `range`, as many at a time as the budget allows; `nstripes` as
/// OpenCV's (-1: its choice), capped by the budget. The library's loops over pixels, voxels
/// and blocks go through it.
void parallelFor(const cv::Range& range, const cv::ParallelLoopBody& body, double nstripes = -1.0);
/// The same for a function of a sub-range.
void parallelFor(const cv::Range& range, std::function<void(const cv::Range&)> body, double nstripes = -1.0);

} // namespace msf
