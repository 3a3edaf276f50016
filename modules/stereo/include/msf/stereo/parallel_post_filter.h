// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once

namespace msf {

/// The stereo post-processing — SemiGlobalMatcher's speckle filter (after OpenCV's 3x3
/// median) and the stereo confidence's distance to the nearest hole — runs our routines on
/// row bands in parallel (filterSpecklesParallel, l1DistanceTransform) by default.
/// Disabled (false), it runs the serial OpenCV functions they replace, which give the same
/// results, so that a benchmark or a test compares both in one process. Process-wide.
void setParallelPostFilterEnabled(bool enabled);
bool parallelPostFilterEnabled();

} // namespace msf
