// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <memory>

namespace msf {

/// How TsdfIntegrator weighs a depth: a voxel's weight is the inverse variance of its signed
/// distance, in m^-2, so that a threshold on it is a precision. A weighting is chosen by the
/// config's `tsdf_integrator.weighting` (makeDepthWeighting) or given to the integrator as an
/// object of one's own (TsdfIntegrator::setWeighting), as VDBFusion takes a weighting function.
class DepthWeighting {
public:
  using ConstPtr = std::shared_ptr<const DepthWeighting>;
  virtual ~DepthWeighting() = default;
  /// The weight of a depth (m) that carries none of its own, m^-2.
  virtual float weight(float depth) const = 0;
  /// The least weight() of a depth up to `max_depth` m (0: no bound), which bounds how far a
  /// pixel's band reaches behind its surface.
  virtual double leastWeight(double max_depth) const = 0;
  /// True when a frame's own weight image (DepthFusion's 1 / sigma^2 per pixel) is taken where
  /// the frame has one, weight() where it has none.
  virtual bool takesFrameWeights() const { return false; }
};

/// Every depth has the same sigma.
class ConstantWeighting : public DepthWeighting {
public:
  explicit ConstantWeighting(double sigma_m) : sigma_(static_cast<float>(sigma_m)), sigma_m_(sigma_m) {}
  float weight(float) const override { return 1.f / (sigma_ * sigma_); }
  double leastWeight(double) const override { return 1.0 / (sigma_m_ * sigma_m_); }

private:
  float sigma_;
  double sigma_m_;
};

/// sigma = sigma_m * z / (1 m), for depth whose noise grows with range.
class InverseSquareWeighting : public DepthWeighting {
public:
  explicit InverseSquareWeighting(double sigma_m) : sigma_(static_cast<float>(sigma_m)), sigma_m_(sigma_m) {}
  float weight(float depth) const override { return 1.f / (sigma_ * sigma_ * depth * depth); }
  double leastWeight(double max_depth) const override {
    return 1.0 / (sigma_m_ * sigma_m_ * max_depth * max_depth);
  }

private:
  float sigma_;
  double sigma_m_;
};

/// The frame's weight image (the fusion's per-pixel inverse variance), ConstantWeighting's
/// where the frame has none; no bound below, as the fusion's weights have none.
class PerPixelWeighting : public DepthWeighting {
public:
  explicit PerPixelWeighting(double sigma_m) : constant_(sigma_m) {}
  float weight(float depth) const override { return constant_.weight(depth); }
  double leastWeight(double) const override { return 0.0; }
  bool takesFrameWeights() const override { return true; }

private:
  ConstantWeighting constant_;
};

} // namespace msf
