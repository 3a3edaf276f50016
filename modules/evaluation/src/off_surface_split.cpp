// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/off_surface_split.h>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <string>

namespace msf {

namespace {

std::vector<OffSurfaceSplit::Band> makeBands(const std::vector<double>& edges) {
  for (std::size_t i = 0; i < edges.size(); ++i)
    if (!std::isfinite(edges[i]) || (i > 0 && !(edges[i] > edges[i - 1])))
      throw InvalidInputError("off-surface split: the band edges must be finite and rise; edge " + std::to_string(i) +
                              " is " + std::to_string(edges[i]));
  std::vector<OffSurfaceSplit::Band> bands(edges.size() + 1);
  const double inf = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < bands.size(); ++i) {
    bands[i].lower_m = i == 0 ? -inf : edges[i - 1];
    bands[i].upper_m = i == edges.size() ? inf : edges[i];
  }
  return bands;
}

} // namespace

double OffSurfaceSplit::offShare() const { return area_m2 > 0 ? off_area_m2 / area_m2 : 0.0; }

double OffSurfaceSplit::shareOfOff(double area) const { return off_area_m2 > 0 ? area / off_area_m2 : 0.0; }

OffSurfaceSplit splitOffSurface(const TriangleMesh& mesh, const SurfaceDistance& truth,
                                const Eigen::Hyperplane<float, 3>& ground, const LidarSupport& support,
                                double distance_m, const std::vector<double>& band_edges_m) {
  if (!(distance_m > 0.0))
    throw InvalidInputError("off-surface split: the distance must be > 0 m, not " + std::to_string(distance_m));
  OffSurfaceSplit out;
  out.distance_m = distance_m;
  out.bands = makeBands(band_edges_m);
  const auto d = static_cast<float>(distance_m);
  for (const auto& t : mesh.triangles) {
    if (std::max({t[0], t[1], t[2]}) >= mesh.vertices.size())
      throw InvalidInputError("off-surface split: a triangle's vertex index is beyond the mesh's " +
                              std::to_string(mesh.vertices.size()) + " vertices");
    const Eigen::Vector3f &a = mesh.vertices[t[0]], &b = mesh.vertices[t[1]], &c = mesh.vertices[t[2]];
    const double area = 0.5 * static_cast<double>((b - a).cross(c - a).norm());
    out.area_m2 += area;
    const Eigen::Vector3f centroid = (a + b + c) / 3.f;
    if (!(truth.distance(centroid, 2.f * d) > d))
      continue;
    out.off_area_m2 += area;
    const double height = ground.signedDistance(centroid);
    auto band = std::find_if(out.bands.begin(), out.bands.end(), [&](const auto& x) { return height < x.upper_m; });
    if (band == out.bands.end()) // a NaN height: the highest band
      band = std::prev(out.bands.end());
    (support.supports(centroid) ? band->supported_m2 : band->unsupported_m2) += area;
  }
  return out;
}

} // namespace msf
