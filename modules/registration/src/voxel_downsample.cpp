#include <msf/common/exceptions.h>
#include <msf/registration/voxel_downsample.h>
#include <msf/registration/voxel_table.h>

#include <string>

namespace msf {

PointMoments PointMoments::rotated(const Eigen::Matrix3d& R) const {
  PointMoments m;
  m.count = count;
  m.sum = R * sum;
  m.outer = R * outer.selfadjointView<Eigen::Upper>() * R.transpose();
  return m;
}

PointList voxelDownsample(const PointList& points, double voxel_size, std::vector<PointMoments>* moments) {
  if (!(voxel_size > 0.0))
    throw InvalidInputError("voxel downsampling: voxel size must be > 0, got " + std::to_string(voxel_size));
  const double inv = 1.0 / voxel_size;
  VoxelTable seen;
  seen.reserve(points.size() / 4);
  PointList kept;
  kept.reserve(points.size() / 4);
  if (moments)
    moments->clear();
  for (const Eigen::Vector3d& p : points) {
    const auto [k, inserted] = seen.insert(voxelKey(voxelOf(p, inv)), static_cast<int>(kept.size()));
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
  return kept;
}

} // namespace msf
