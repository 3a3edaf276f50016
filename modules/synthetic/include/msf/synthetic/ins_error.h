// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/poses.h>
#include <msf/synthetic/synthetic_config.h>

namespace msf::synthetic {

/// The drive's true poses as a GPS-aided INS measures them: the heading (about the world's
/// vertical, camera 0's y) off by ins_heading_drift_deg_per_s times the time since frame 0,
/// and the position off by a smooth wander of RMS ins_position_error_m per axis (the vertical's
/// half), a sum of three sinusoids of periods 5 to 23 s with phases from the seed, as a
/// Kalman filter's GPS corrections move it. Both errors are zero at frame 0, whose pose stays
/// the world's origin.
PoseList insPoses(const PoseList& truth, const SyntheticConfig& config);

} // namespace msf::synthetic
