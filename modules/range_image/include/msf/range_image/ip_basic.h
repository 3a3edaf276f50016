// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <iosfwd>
#include <opencv2/core/mat.hpp>
#include <opencv2/core/persistence.hpp>

#include <string>

namespace msf {

/// The classical baseline: IP-Basic, Ku, Harakeh and Waslander, "In Defense of Classical
/// Image Processing: Fast Depth Completion on the CPU" (CRV 2018), written here with OpenCV
/// morphology step for step as the authors' fill_in_fast and fill_in_multiscale.
enum class IpBasicVariant { Fast, Multiscale };
enum class IpBasicBlur { None, Gaussian, Bilateral };

/// "fast" / "multiscale"; "none" / "gaussian" / "bilateral"; ConfigError otherwise.
IpBasicVariant parseIpBasicVariant(const std::string& name);
IpBasicBlur parseIpBasicBlur(const std::string& name);
const char* toString(IpBasicVariant variant);
const char* toString(IpBasicBlur blur);

/// Section `ip_basic` of the YAML config; defaults are the authors' recommended settings.
struct IpBasicConfig {
  IpBasicVariant variant = IpBasicVariant::Multiscale;
  float max_depth_m = 100.f;   ///< inversion offset: depth d is processed as max_depth - d
  bool extrapolate = false;    ///< extend the top pixel of each column to the image top
  IpBasicBlur blur = IpBasicBlur::Bilateral;

  /// The section as YAML, every key (configValue).
  void print(std::ostream& out) const;
  void read(const cv::FileNode& node);
  void validate() const;
};

/// Dense depth (CV_32FC1, 0 = none) from a sparse projection (CV_32FC1, 0 or NaN = none).
/// Depths beyond max_depth_m - 0.1 are dropped, as in the original.
cv::Mat ipBasic(const cv::Mat& sparse, const IpBasicConfig& config);

} // namespace msf
