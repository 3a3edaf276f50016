// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>

#include <opencv2/core/mat.hpp>

#include <string>

namespace msf {

/// The classical baseline: IP-Basic, Ku, Harakeh and Waslander, "In Defense of Classical
/// Image Processing: Fast Depth Completion on the CPU" (CRV 2018), written here with OpenCV
/// morphology step for step as the authors' fill_in_fast and fill_in_multiscale.
enum class IpBasicVariant { Fast, Multiscale };
enum class IpBasicBlur { None, Gaussian, Bilateral };
inline constexpr Choice<IpBasicVariant> kIpBasicVariants[] = {{"fast", IpBasicVariant::Fast},
                                                              {"multiscale", IpBasicVariant::Multiscale}};
inline constexpr Choice<IpBasicBlur> kIpBasicBlurs[] = {
    {"none", IpBasicBlur::None}, {"gaussian", IpBasicBlur::Gaussian}, {"bilateral", IpBasicBlur::Bilateral}};

/// "fast" / "multiscale"; "none" / "gaussian" / "bilateral"; ConfigError otherwise.
IpBasicVariant parseIpBasicVariant(const std::string& name);
IpBasicBlur parseIpBasicBlur(const std::string& name);
const char* toString(IpBasicVariant variant);
const char* toString(IpBasicBlur blur);

/// Section `ip_basic` of a config file; the defaults are the authors' recommended settings.
struct IpBasicConfig {
  static constexpr const char* kSection = "ip_basic";
  static constexpr const char* kAbout =
      "IP-Basic (Ku et al. 2018), the classical baseline: msf_interpolate -method ipbasic and msf_holdout";
  IpBasicVariant variant = IpBasicVariant::Multiscale;
  float max_depth_m = 100.f;
  bool extrapolate = false;
  IpBasicBlur blur = IpBasicBlur::Bilateral;

  template <class Keys>
  void keys(Keys& k) {
    k("variant", variant, kIpBasicVariants, "the authors' fill_in_fast or fill_in_multiscale");
    k("max_depth_m", max_depth_m, above(1), "inversion offset: depth d is processed as max_depth_m - d, m");
    k("extrapolate", extrapolate, "extend the top pixel of each column to the image's top");
    k("blur", blur, kIpBasicBlurs, "the blur after the fill");
  }
  void validate() const;
};

/// Dense depth (CV_32FC1, 0 = none) from a sparse projection (CV_32FC1, 0 or NaN = none).
/// Depths beyond max_depth_m - 0.1 are dropped, as in the original.
cv::Mat ipBasic(const cv::Mat& sparse, const IpBasicConfig& config);

} // namespace msf
