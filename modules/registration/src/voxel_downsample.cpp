// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/registration/voxel_table.h>

#include <algorithm>
#include <cstdint>
#include <string>
#include <tuple>

namespace msf {

PointMoments PointMoments::rotated(const Eigen::Matrix3d& R) const {
  PointMoments m;
  m.count = count;
  m.sum = R * sum;
  // As a plain 3x3 matrix: a product with a selfadjointView takes Eigen's general
  // (dynamic-size) matrix product, dozens of times slower for one 3x3.
  const Eigen::Matrix3d full = outer.selfadjointView<Eigen::Upper>();
  m.outer.noalias() = R * full * R.transpose();
  return m;
}

PointList voxelDownsample(const PointList& points, double voxel_size, std::vector<PointMoments>* moments) {
  PointList kept;
  VoxelDownsampler().downsample(points, voxel_size, kept, moments);
  return kept;
}

namespace {

void checkVoxelSize(double voxel_size) {
  if (!(voxel_size > 0.0))
    throw InvalidInputError("voxel downsampling: voxel size must be > 0, got " + std::to_string(voxel_size));
}

void prepare(std::size_t n, VoxelTable& seen, PointList& kept, std::vector<PointMoments>* moments) {
  seen.clear();
  seen.reserve(n / 4);
  kept.clear();
  kept.reserve(n / 4);
  if (moments) {
    moments->clear();
    moments->reserve(kept.capacity());
  }
}

/// The downsampling of points 0 .. n - 1, `next(i, p)` giving point i in p, or false to skip
/// it. Returns the points not skipped.
template <bool kMoments, typename Next>
std::size_t downsampleImpl(std::size_t n, const Next& next, double inv, VoxelTable& seen, PointList& kept,
                           std::vector<PointMoments>* moments) {
  // A scan comes ring by ring (or firing by firing): most points fall in the voxel of the
  // point before them, which is then known without a look-up in the table, and their moments
  // are summed in registers (the run) before they are added to the voxel's.
  std::uint64_t last_key = ~std::uint64_t(0); // no voxel's
  int k = 0;
  std::size_t used = 0;
  Eigen::Vector3d origin = Eigen::Vector3d::Zero(); // the kept point of voxel k
  int run = 0;
  double sx = 0, sy = 0, sz = 0, xx = 0, xy = 0, xz = 0, yy = 0, yz = 0, zz = 0;
  auto flush = [&] {
    if (run == 0)
      return;
    PointMoments& m = (*moments)[static_cast<std::size_t>(k)];
    m.count += run;
    m.sum += Eigen::Vector3d(sx, sy, sz);
    m.outer(0, 0) += xx, m.outer(0, 1) += xy, m.outer(0, 2) += xz; // the upper triangle
    m.outer(1, 1) += yy, m.outer(1, 2) += yz, m.outer(2, 2) += zz;
    run = 0;
    sx = sy = sz = xx = xy = xz = yy = yz = zz = 0.0;
  };
  // In chunks: the points of a chunk and their voxels first, with the table's slots of the
  // voxels that change fetched ahead (the look-ups of a chunk then wait for memory together,
  // not one after the other), then the chunk's points one by one.
  constexpr std::size_t kChunk = 64;
  Eigen::Vector3d chunk[kChunk];
  std::uint64_t keys[kChunk];
  std::uint64_t ahead_key = last_key;
  for (std::size_t start = 0; start < n; start += kChunk) {
    const std::size_t end = std::min(n, start + kChunk);
    std::size_t m = 0;
    for (std::size_t i = start; i < end; ++i) {
      if (!next(i, chunk[m]))
        continue;
      keys[m] = voxelKey(voxelOf(chunk[m], inv));
      if (keys[m] != ahead_key) {
        seen.prefetch(keys[m]);
        ahead_key = keys[m];
      }
      ++m;
    }
    used += m;
    for (std::size_t j = 0; j < m; ++j) {
      const Eigen::Vector3d& p = chunk[j];
      const std::uint64_t key = keys[j];
      if (key != last_key) {
        if (kMoments)
          flush();
        bool inserted = false;
        std::tie(k, inserted) = seen.insert(key, static_cast<int>(kept.size()));
        last_key = key;
        if (inserted) {
          kept.push_back(p);
          if (kMoments)
            moments->emplace_back();
        }
        origin = kept[static_cast<std::size_t>(k)];
      }
      if (kMoments) {
        const double dx = p.x() - origin.x(), dy = p.y() - origin.y(), dz = p.z() - origin.z();
        ++run;
        sx += dx, sy += dy, sz += dz;
        xx += dx * dx, xy += dx * dy, xz += dx * dz;
        yy += dy * dy, yz += dy * dz, zz += dz * dz;
      }
    }
  }
  if (kMoments)
    flush();
  return used;
}

template <typename Next>
std::size_t downsampleAll(std::size_t n, const Next& next, double inv, VoxelTable& seen, PointList& kept,
                          std::vector<PointMoments>* moments) {
  return moments ? downsampleImpl<true>(n, next, inv, seen, kept, moments)
                 : downsampleImpl<false>(n, next, inv, seen, kept, moments);
}

} // namespace

void VoxelDownsampler::downsample(const PointList& points, double voxel_size, PointList& kept,
                                  std::vector<PointMoments>* moments) {
  checkVoxelSize(voxel_size);
  prepare(points.size(), seen_, kept, moments);
  downsampleAll(
      points.size(),
      [&](std::size_t i, Eigen::Vector3d& p) {
        p = points[i];
        return true;
      },
      1.0 / voxel_size, seen_, kept, moments);
}

std::size_t VoxelDownsampler::downsampleScan(const PointList& scan, double min_range, double max_range,
                                             const SweepDeskew* deskew, double voxel_size, PointList& kept,
                                             std::vector<PointMoments>* moments) {
  checkVoxelSize(voxel_size);
  prepare(scan.size(), seen_, kept, moments);
  const double min2 = min_range * min_range, max2 = max_range * max_range;
  auto inRange = [&](const Eigen::Vector3d& q) {
    const double r2 = q.squaredNorm();
    return r2 >= min2 && r2 <= max2 && q.allFinite();
  };
  const double inv = 1.0 / voxel_size;
  if (deskew)
    return downsampleAll(
        scan.size(),
        [&](std::size_t i, Eigen::Vector3d& p) {
          if (!inRange(scan[i]))
            return false;
          p = (*deskew)(scan[i]);
          return true;
        },
        inv, seen_, kept, moments);
  return downsampleAll(
      scan.size(),
      [&](std::size_t i, Eigen::Vector3d& p) {
        if (!inRange(scan[i]))
          return false;
        p = scan[i];
        return true;
      },
      inv, seen_, kept, moments);
}

} // namespace msf
