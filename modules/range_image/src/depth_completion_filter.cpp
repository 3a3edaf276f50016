// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// Explicit instantiations of the completion filters for the project's point types
// (PCL's precompile pattern); other types include the impl with MSF_NO_PRECOMPILE.
#include <msf/io/impl/pinhole_camera.hpp>
#include <msf/range_image/compound_interpolation.h>
#include <msf/range_image/impl/depth_completion_filter.hpp>
#include <msf/range_image/ip_basic_completion.h>
#include <msf/range_image/point_types.h>

#include <pcl/impl/pcl_base.hpp>

template class pcl::PCLBase<msf::PointXYZID>;

#define MSF_INSTANTIATE_COMPLETION(T)                                                                  \
  template class msf::DepthCompletionFilter<T>;                                                       \
  template class msf::CompoundInterpolation<T>;                                                       \
  template class msf::IpBasicCompletion<T>;
MSF_INSTANTIATE_COMPLETION(pcl::PointXYZ)
MSF_INSTANTIATE_COMPLETION(pcl::PointXYZI)
MSF_INSTANTIATE_COMPLETION(pcl::PointXYZRGB)
MSF_INSTANTIATE_COMPLETION(msf::PointXYZID)
