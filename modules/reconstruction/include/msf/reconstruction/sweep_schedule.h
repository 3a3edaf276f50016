// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <memory>

namespace msf {

/// When TsdfIntegrator's Gauss-Seidel sweeps over eq. 7 stop each frame. Chosen by the config's
/// `tsdf_integrator.solve` (makeSweepSchedule) or given to the integrator
/// (TsdfIntegrator::setSweepSchedule).
class SweepSchedule {
public:
  using ConstPtr = std::shared_ptr<const SweepSchedule>;
  virtual ~SweepSchedule() = default;
  /// The most sweeps a frame runs (0: eq. 7 is not solved).
  virtual int maxSweeps() const = 0;
  /// True when a sweep that moved no voxel more than `largest_change` (metres) ends the solve.
  virtual bool converged(float largest_change) const = 0;
  /// True when the solve always runs maxSweeps(), so that only the last sweep records the
  /// voxels' signs.
  virtual bool runsEverySweep() const = 0;
};

/// A fixed number of sweeps a frame, warm-started from the last frame's solution, so that the
/// solution is refined over frames.
class FixedSweeps : public SweepSchedule {
public:
  explicit FixedSweeps(int sweeps) : sweeps_(sweeps) {}
  int maxSweeps() const override { return sweeps_; }
  bool converged(float) const override { return false; }
  bool runsEverySweep() const override { return true; }

private:
  int sweeps_;
};

/// Sweeps until none moves a voxel more than a tolerance: the minimizer of eq. 7 itself, as the
/// paper writes it, within at most `max_sweeps`.
class SweepsToArgmin : public SweepSchedule {
public:
  SweepsToArgmin(double tolerance_m, int max_sweeps)
      : tolerance_(static_cast<float>(tolerance_m)), max_sweeps_(max_sweeps) {}
  int maxSweeps() const override { return max_sweeps_; }
  bool converged(float largest_change) const override { return largest_change <= tolerance_; }
  bool runsEverySweep() const override { return false; }

private:
  float tolerance_;
  int max_sweeps_;
};

} // namespace msf
