// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <cmath>
#include <cstdint>

/// Counter-based random numbers: every random value is a pure function of a key
/// (seed, frame, camera or ring, pixel or point, purpose), so output does not depend on
/// thread scheduling and a seed reproduces a dataset byte for byte.
namespace msf::synthetic {

/// splitmix64's finalizer: a bijective 64-bit mix with good avalanche.
inline std::uint64_t mix64(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

/// hashKey's state after its first counters: keys that share them (an image's pixels, a
/// pixel's channels) hash only the rest. hashKey(a, b, c, d, e) ==
/// HashPrefix(a).then(b).then(c).then(d).then(e).value().
class HashPrefix {
public:
  explicit HashPrefix(std::uint64_t a) : h_(mix64(a + kGolden)), next_(2) {}
  HashPrefix then(std::uint64_t x) const { return {mix64(h_ ^ (x + next_ * kGolden)), next_ + 1}; }
  /// The hash of the counters given, the missing ones (up to five) zero.
  std::uint64_t value() const {
    std::uint64_t h = h_;
    for (std::uint64_t i = next_; i <= 5; ++i)
      h = mix64(h ^ (i * kGolden));
    return h;
  }

private:
  static constexpr std::uint64_t kGolden = 0x9e3779b97f4a7c15ULL;
  HashPrefix(std::uint64_t h, std::uint64_t next) : h_(h), next_(next) {}
  std::uint64_t h_, next_;
};

/// Hash of up to five counters; order matters.
inline std::uint64_t hashKey(std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0, std::uint64_t d = 0,
                             std::uint64_t e = 0) {
  return HashPrefix(a).then(b).then(c).then(d).then(e).value();
}

/// Uniform in [0, 1) from the top 53 bits.
inline double uniform01(std::uint64_t h) { return static_cast<double>(h >> 11) * 0x1.0p-53; }

/// Standard normal from one hash (Box-Muller on its two 32-bit halves).
inline double gaussian(std::uint64_t h) {
  const double u1 = (static_cast<double>(h >> 32) + 0.5) * 0x1.0p-32;
  const double u2 = (static_cast<double>(h & 0xffffffffULL) + 0.5) * 0x1.0p-32;
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

/// Approximately standard normal from one hash, cheaply: the sum of four 16-bit uniforms
/// (Irwin-Hall), scaled to unit variance; bounded at +-3.46. For image noise.
inline float gaussianFast(std::uint64_t h) {
  const auto sum = static_cast<float>((h & 0xffff) + ((h >> 16) & 0xffff) + ((h >> 32) & 0xffff) + (h >> 48));
  return (sum * (1.f / 65536.f) - 2.f) * 1.7320508f;
}

/// A sequential generator for building the scene (single-threaded, so a plain stream is
/// deterministic); std:: distributions are not, across standard libraries.
class SequentialRng {
public:
  explicit SequentialRng(std::uint64_t seed) : state_(mix64(seed ^ 0x5eedULL)) {}
  std::uint64_t next() { return mix64(state_ += 0x9e3779b97f4a7c15ULL); }
  double uniform() { return uniform01(next()); }
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }
  bool chance(double p) { return uniform() < p; }
  /// Integer in [0, n).
  int index(int n) { return static_cast<int>(uniform() * n) % n; }
  std::uint32_t seed32() { return static_cast<std::uint32_t>(next() >> 32); }

private:
  std::uint64_t state_;
};

} // namespace msf::synthetic
