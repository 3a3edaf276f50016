#include <msf/common/exceptions.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/registration/voxel_table.h>

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

void VoxelDownsampler::downsample(const PointList& points, double voxel_size, PointList& kept,
                                  std::vector<PointMoments>* moments) {
  if (!(voxel_size > 0.0))
    throw InvalidInputError("voxel downsampling: voxel size must be > 0, got " + std::to_string(voxel_size));
  const double inv = 1.0 / voxel_size;
  seen_.clear();
  seen_.reserve(points.size() / 4);
  kept.clear();
  kept.reserve(points.size() / 4);
  if (moments) {
    moments->clear();
    moments->reserve(kept.capacity());
  }
  // A scan comes ring by ring (or firing by firing): most points fall in the voxel of the
  // point before them, which is then known without a look-up in the table.
  std::uint64_t last_key = ~std::uint64_t(0);  // no voxel's
  int k = 0;
  for (const Eigen::Vector3d& p : points) {
    const std::uint64_t key = voxelKey(voxelOf(p, inv));
    bool inserted = false;
    if (key != last_key) {
      std::tie(k, inserted) = seen_.insert(key, static_cast<int>(kept.size()));
      last_key = key;
    }
    if (inserted)
      kept.push_back(p);
    if (moments) {
      if (inserted)
        moments->emplace_back();
      PointMoments& m = (*moments)[static_cast<std::size_t>(k)];
      const Eigen::Vector3d d = p - kept[static_cast<std::size_t>(k)];
      ++m.count;
      m.sum += d;
      for (int r = 0; r < 3; ++r) // the upper triangle, by hand: Eigen's rankUpdate is a call per point
        for (int c = r; c < 3; ++c)
          m.outer(r, c) += d[r] * d[c];
    }
  }
}

} // namespace msf
