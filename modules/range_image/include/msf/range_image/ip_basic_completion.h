// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/range_image/depth_completion_filter.h>
#include <msf/range_image/ip_basic.h>

namespace msf {

/// IP-Basic (ipBasic) as a pcl::Filter on organized clouds, so the baseline runs
/// wherever CompoundInterpolation does (msf_interpolate -method ipbasic).
template <typename PointT>
class IpBasicCompletion : public DepthCompletionFilter<PointT> {
public:
  using Ptr = pcl::shared_ptr<IpBasicCompletion<PointT>>;
  using ConstPtr = pcl::shared_ptr<const IpBasicCompletion<PointT>>;

  IpBasicCompletion() { this->filter_name_ = "IpBasicCompletion"; }

  void setConfig(const IpBasicConfig& config) {
    config.validate();
    config_ = config;
  }
  const IpBasicConfig& getConfig() const { return config_; }
  void setVariant(IpBasicVariant variant) { config_.variant = variant; }
  IpBasicVariant getVariant() const { return config_.variant; }

protected:
  void completeDepth(const cv::Mat& sparse, cv::Mat& dense) override { dense = ipBasic(sparse, config_); }

  IpBasicConfig config_;
};

} // namespace msf
