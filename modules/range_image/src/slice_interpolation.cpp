#include <msf/common/exceptions.h>
#include <msf/range_image/slice_interpolation.h>

namespace msf {

SliceInterpolant parseSliceInterpolant(const std::string& name) {
  if (name == "compound")
    return SliceInterpolant::Compound;
  if (name == "linear")
    return SliceInterpolant::Linear;
  if (name == "cubic")
    return SliceInterpolant::Cubic;
  throw ConfigError("slice interpolant '" + name + "' is not compound, linear or cubic");
}

const char* toString(SliceInterpolant interpolant) {
  switch (interpolant) {
  case SliceInterpolant::Linear:
    return "linear";
  case SliceInterpolant::Cubic:
    return "cubic";
  default:
    return "compound";
  }
}

namespace {

/// Writes the `empty` pixels strictly between two samples z0 (at i0) and z1.
inline void bridge(float z0, float z1, std::ptrdiff_t i0, int empty, std::ptrdiff_t stride, const SliceParams& p,
                   float* out, std::uint8_t* gap) {
  const bool cubic = p.interpolant == SliceInterpolant::Cubic ||
                     (p.interpolant == SliceInterpolant::Compound && empty <= p.short_gap_px);
  const float a = p.inverse_depth ? 1.f / z0 : z0;
  const float delta = (p.inverse_depth ? 1.f / z1 : z1) - a;
  const float step = 1.f / static_cast<float>(empty + 1);
  const std::uint8_t g = static_cast<std::uint8_t>(empty < 255 ? empty : 255);
  for (int k = 1; k <= empty; ++k) {
    const float t = static_cast<float>(k) * step;
    const float w = cubic ? t * t * (p.cubic_beta - p.cubic_alpha * t) : t;
    const float value = a + delta * w;
    const std::ptrdiff_t i = (i0 + k) * stride;
    out[i] = p.inverse_depth ? 1.f / value : value;
    gap[i] = g;
  }
}

} // namespace

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
      bridge(z_last, z, last, empty, stride, params, out, gap);
    last = i;
    z_last = z;
  }
}

} // namespace msf
