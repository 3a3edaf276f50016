// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/range_image/slice_interpolation.h>

namespace msf {

SliceInterpolant parseSliceInterpolant(const std::string& name) {
  if (const auto interpolant = choiceOf(kSliceInterpolants, name))
    return *interpolant;
  throw ConfigError("slice interpolant '" + name + "' is not " + wordList(kSliceInterpolants));
}

const char* toString(SliceInterpolant interpolant) { return wordOf(kSliceInterpolants, interpolant); }

void interpolateSlice(const float* in, std::ptrdiff_t stride, int n, const SliceParams& params, float* out,
                      std::uint8_t* gap) {
  std::ptrdiff_t last = -1; // index of the previous sample
  float z_last = 0.f;
  for (std::ptrdiff_t i = 0; i < n; ++i) {
    const float z = in[i * stride];
    if (!(z > 0.f)) { // NaN is empty too
      out[i * stride] = 0.f;
      gap[i * stride] = 0;
      continue;
    }
    out[i * stride] = z;
    gap[i * stride] = 0;
    const int empty = static_cast<int>(i - last - 1);
    if (last >= 0 && empty > 0 && empty <= params.max_gap_px && !isDepthJump(z_last, z, params))
      bridgeValues(z_last, z, empty, params, [&](int k, float value) {
        out[(last + k) * stride] = value;
        gap[(last + k) * stride] = gapCode(empty);
      });
    last = i;
    z_last = z;
  }
}

} // namespace msf
