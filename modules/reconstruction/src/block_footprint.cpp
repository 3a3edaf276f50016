// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/reconstruction/block_footprint.h>
#include <msf/reconstruction/tsdf_block.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace msf {

namespace {
constexpr int kSide = TsdfBlock::kSide;
constexpr double kMaxCoordinateM = 1e7;        // block indices stay well inside an int
constexpr double kMaxColumnsPerView = 1 << 24; // ~a second's work for one view

/// A half-space n . p <= d.
struct Plane {
  Eigen::Vector3d n;
  double d;
};

/// The view's frustum in the world, as six half-spaces: x / z between the left and right pixel
/// edges, y / z between the top and bottom ones, z between near and far (camera frame).
std::array<Plane, 6> frustumPlanes(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, double near_m,
                                   double far_m) {
  const double left = (-0.5 - camera.cx) / camera.fx, right = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double top = (-0.5 - camera.cy) / camera.fy, bottom = (camera.height - 0.5 - camera.cy) / camera.fy;
  const std::array<Plane, 6> in_camera{{{Eigen::Vector3d(-1, 0, left), 0.0},
                                        {Eigen::Vector3d(1, 0, -right), 0.0},
                                        {Eigen::Vector3d(0, -1, top), 0.0},
                                        {Eigen::Vector3d(0, 1, -bottom), 0.0},
                                        {Eigen::Vector3d(0, 0, -1), -near_m},
                                        {Eigen::Vector3d(0, 0, 1), far_m}}};
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d t = T_world_cam.translation();
  std::array<Plane, 6> planes;
  for (std::size_t i = 0; i < planes.size(); ++i) {
    planes[i].n = R * in_camera[i].n;
    planes[i].d = in_camera[i].d + planes[i].n.dot(t);
  }
  return planes;
}

/// The world bounding box [lo, hi] of the view's frustum.
void frustumBox(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, double near_m, double far_m,
                Eigen::Vector3d& lo, Eigen::Vector3d& hi) {
  const double left = (-0.5 - camera.cx) / camera.fx, right = (camera.width - 0.5 - camera.cx) / camera.fx;
  const double top = (-0.5 - camera.cy) / camera.fy, bottom = (camera.height - 0.5 - camera.cy) / camera.fy;
  lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const double z : {near_m, far_m})
    for (const double x : {left * z, right * z})
      for (const double y : {top * z, bottom * z}) {
        const Eigen::Vector3d p = T_world_cam * Eigen::Vector3d(x, y, z);
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
}

/// The blocks of column (bi, bj) (axes i, j) along axis k, within [first, last], that meet every
/// plane; first > last when none does. A block meets the frustum unless it lies wholly outside
/// one plane: for a box of centre c and half side h, n . c - h |n|_1 > d. The half side is grown
/// by a voxel: a ray's cells are found in single precision. Box of block b along an axis:
/// [(kSide b - 1/2) vs, (kSide b + kSide - 1/2) vs], centre (kSide b + kSide / 2 - 1/2) vs.
void clipColumn(const std::array<Plane, 6>& planes, double vs, int k, int i, int j, int bi, int bj, int& first,
                int& last) {
  const double half = 0.5 * kSide * vs + vs;
  auto centre = [&](int b) { return (kSide * b + 0.5 * kSide - 0.5) * vs; };
  for (const Plane& p : planes) {
    // n_k c_k <= rhs, with c_k = (kSide bk + kSide / 2 - 1/2) vs.
    const double rhs = p.d + half * p.n.lpNorm<1>() - p.n[i] * centre(bi) - p.n[j] * centre(bj);
    const double nk = p.n[k];
    if (std::abs(nk) < 1e-12) {
      if (rhs < 0.0)
        first = last + 1;
      continue;
    }
    // Clamped both ways before the cast: a plane nearly parallel to the axis gives a bound of
    // either sign far beyond an int.
    const double bound = std::clamp((rhs / (nk * vs) - 0.5 * kSide + 0.5) / kSide, -1e9, 1e9);
    if (nk > 0.0)
      last = std::min(last, static_cast<int>(std::floor(bound)));
    else
      first = std::max(first, static_cast<int>(std::ceil(bound)));
    if (first > last)
      return;
  }
}
} // namespace

BlockFootprint::BlockFootprint(double voxel_size_m) : voxel_size_(voxel_size_m) {
  if (!(voxel_size_m > 0.0) || !std::isfinite(voxel_size_m))
    throw InvalidInputError("BlockFootprint: the voxel size must be > 0, got " + std::to_string(voxel_size_m));
}

int BlockFootprint::blockOf(double p) const {
  // As the integrator's sub-block keys: block floor((p / vs + 1/2) / kSide).
  return static_cast<int>(std::floor(std::clamp((p / voxel_size_ + 0.5) / kSide, -1e9, 1e9)));
}

void BlockFootprint::addView(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam, double near_m,
                             double far_m) {
  if (!camera.valid())
    throw InvalidInputError("BlockFootprint::addView: the camera is not valid (fx, fy > 0, a size)");
  if (!(near_m >= 0.0 && far_m > near_m && std::isfinite(far_m)))
    throw InvalidInputError("BlockFootprint::addView: need 0 <= near < far, finite; got " + std::to_string(near_m) +
                            " and " + std::to_string(far_m));
  const std::array<Plane, 6> planes = frustumPlanes(camera, T_world_cam, near_m, far_m);
  // The blocks of the frustum's bounding box, a block wider each side.
  Eigen::Vector3d lo, hi;
  frustumBox(camera, T_world_cam, near_m, far_m, lo, hi);
  if (axis_ < 0)
    (hi - lo).maxCoeff(&axis_); // runs along the longest extent: fewest columns
  const int k = axis_, i = (k + 1) % 3, j = (k + 2) % 3;
  std::array<int, 3> first{}, last{};
  for (int a = 0; a < 3; ++a) {
    if (!(std::abs(lo[a]) < kMaxCoordinateM && std::abs(hi[a]) < kMaxCoordinateM))
      throw InvalidInputError("BlockFootprint::addView: the view reaches " + std::to_string(std::max(std::abs(lo[a]), std::abs(hi[a]))) +
                              " m from the origin, beyond " + std::to_string(kMaxCoordinateM) + " m");
    first[a] = blockOf(lo[a]) - 1;
    last[a] = blockOf(hi[a]) + 1;
  }
  const double columns = (double(last[i]) - first[i] + 1) * (double(last[j]) - first[j] + 1);
  if (columns > kMaxColumnsPerView) {
    // Too fine to enumerate in good time (millimetre voxels, a kilometre's depth): the blocks of
    // the view's bounding box, which hold its blocks, are counted instead.
    unlisted_ += std::min(columns * (double(last[k]) - first[k] + 1), 1e15);
    return;
  }
  for (int bi = first[i]; bi <= last[i]; ++bi)
    for (int bj = first[j]; bj <= last[j]; ++bj) {
      int run_first = first[k], run_last = last[k];
      clipColumn(planes, voxel_size_, k, i, j, bi, bj, run_first, run_last);
      if (run_first <= run_last)
        addRun(columnKey(bi, bj), run_first, run_last);
    }
}

void BlockFootprint::addRun(std::uint64_t column, int first, int last) {
  Runs& runs = columns_[column];
  // Merge with every run it overlaps or touches; count only the blocks it adds.
  std::size_t covered = 0;
  auto it = runs.begin();
  while (it != runs.end() && it->second < first - 1)
    ++it;
  auto end = it;
  int merged_first = first, merged_last = last;
  while (end != runs.end() && end->first <= last + 1) {
    const int a = std::max(end->first, first), b = std::min(end->second, last);
    if (a <= b)
      covered += static_cast<std::size_t>(b - a + 1);
    merged_first = std::min(merged_first, end->first);
    merged_last = std::max(merged_last, end->second);
    ++end;
  }
  blocks_ += static_cast<std::size_t>(last - first + 1) - covered;
  it = runs.erase(it, end);
  runs.insert(it, {merged_first, merged_last});
}

bool BlockFootprint::contains(const Eigen::Vector3i& block) const {
  if (axis_ < 0)
    return false;
  const int k = axis_, i = (k + 1) % 3, j = (k + 2) % 3;
  const auto found = columns_.find(columnKey(block[i], block[j]));
  if (found == columns_.end())
    return false;
  for (const auto& run : found->second)
    if (run.first <= block[k] && block[k] <= run.second)
      return true;
  return false;
}

std::size_t BlockFootprint::blocks() const { return blocks_ + static_cast<std::size_t>(unlisted_); }

std::size_t BlockFootprint::blocksWithin(const Eigen::Vector3d& c, double radius_m) const {
  if (axis_ < 0 || !(radius_m >= 0.0))
    return static_cast<std::size_t>(unlisted_);
  const double vs = voxel_size_, half = 0.5 * kSide * vs;
  const int k = axis_, i = (k + 1) % 3, j = (k + 2) % 3;
  auto centre = [&](int b) { return (kSide * b + 0.5 * kSide - 0.5) * vs; };
  // How far a box of centre x and half side `half` is from coordinate p along one axis.
  auto gap = [&](double x, double p) { return std::max(0.0, std::abs(x - p) - half); };
  std::size_t n = 0;
  auto count = [&](int bi, int bj, const Runs& runs) {
    const double gi = gap(centre(bi), c[i]), gj = gap(centre(bj), c[j]);
    const double rest = radius_m * radius_m - gi * gi - gj * gj;
    if (rest < 0.0)
      return;
    // Blocks along k whose box meets [c_k - L, c_k + L], L the ball's half chord: their
    // centres within L + half of c_k.
    const double reach = std::sqrt(rest) + half;
    auto block = [&](double p) { return std::clamp((p / vs - 0.5 * kSide + 0.5) / kSide, -1e9, 1e9); };
    const int from = static_cast<int>(std::ceil(block(c[k] - reach)));
    const int to = static_cast<int>(std::floor(block(c[k] + reach)));
    for (const auto& run : runs) {
      const int a = std::max(run.first, from), b = std::min(run.second, to);
      if (a <= b)
        n += static_cast<std::size_t>(b - a + 1);
    }
  };
  const int ri = blockOf(c[i] - radius_m) - 1, rj = blockOf(c[j] - radius_m) - 1;
  const int si = blockOf(c[i] + radius_m) + 1, sj = blockOf(c[j] + radius_m) + 1;
  const double ball_columns = (double(si) - ri + 1) * (double(sj) - rj + 1);
  if (ball_columns < static_cast<double>(columns_.size())) {
    for (int bi = ri; bi <= si; ++bi)
      for (int bj = rj; bj <= sj; ++bj) {
        const auto found = columns_.find(columnKey(bi, bj));
        if (found != columns_.end())
          count(bi, bj, found->second);
      }
  } else {
    for (const auto& [key, runs] : columns_)
      count(static_cast<std::int32_t>(key >> 32), static_cast<std::int32_t>(key & 0xffffffffu), runs);
  }
  return n + static_cast<std::size_t>(unlisted_);
}

} // namespace msf
