// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <vector>

namespace msf {

/// Median of `values` (the mean of the two middle ones for an even count); 0 when empty.
double median(std::vector<double> values);

/// The p-th percentile (0..100) with linear interpolation between ranks; 0 when empty.
double percentile(std::vector<double> values, double p);

} // namespace msf
