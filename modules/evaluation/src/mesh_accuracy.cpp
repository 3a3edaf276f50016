// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/common/statistics.h>
#include <msf/evaluation/mesh_accuracy.h>

#include <opencv2/core/utility.hpp>
#include <pcl/conversions.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <string>
#include <unordered_map>

namespace msf {

namespace {

/// Closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5).
Eigen::Vector3f closestOnTriangle(const Eigen::Vector3f& p, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                                  const Eigen::Vector3f& c) {
  const Eigen::Vector3f ab = b - a, ac = c - a, ap = p - a;
  const float d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.f && d2 <= 0.f)
    return a;
  const Eigen::Vector3f bp = p - b;
  const float d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.f && d4 <= d3)
    return b;
  const float vc = d1 * d4 - d3 * d2;
  if (vc <= 0.f && d1 >= 0.f && d3 <= 0.f)
    return a + ab * (d1 / (d1 - d3));
  const Eigen::Vector3f cp = p - c;
  const float d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.f && d5 <= d6)
    return c;
  const float vb = d5 * d2 - d1 * d6;
  if (vb <= 0.f && d2 >= 0.f && d6 <= 0.f)
    return a + ac * (d2 / (d2 - d6));
  const float va = d3 * d6 - d5 * d4;
  if (va <= 0.f && (d4 - d3) >= 0.f && (d5 - d6) >= 0.f)
    return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
  const float denom = 1.f / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

void meshArrays(const pcl::PolygonMesh& mesh, std::vector<Eigen::Vector3f>& vertices,
                std::vector<std::array<std::uint32_t, 3>>& triangles) {
  pcl::PointCloud<pcl::PointXYZ> cloud;
  // PCL indexes data[0] of an empty cloud (UBSan: reference binding to null pointer).
  if (!mesh.cloud.data.empty())
    pcl::fromPCLPointCloud2(mesh.cloud, cloud);
  vertices.resize(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i)
    vertices[i] = cloud[i].getVector3fMap();
  triangles.clear();
  for (const auto& polygon : mesh.polygons)
    for (std::size_t k = 2; k < polygon.vertices.size(); ++k)
      triangles.push_back({static_cast<std::uint32_t>(polygon.vertices[0]),
                           static_cast<std::uint32_t>(polygon.vertices[k - 1]),
                           static_cast<std::uint32_t>(polygon.vertices[k])});
}

} // namespace

SurfaceDistance::SurfaceDistance(std::vector<Eigen::Vector3f> vertices,
                                 std::vector<std::array<std::uint32_t, 3>> triangles, float cell_size_m)
    : vertices_(std::move(vertices)), triangles_(std::move(triangles)), cell_size_(cell_size_m) {
  if (!(cell_size_ > 0.f))
    throw InvalidInputError("surface distance grid cell must be > 0 m");
  if (triangles_.empty())
    throw InvalidInputError("surface has no triangle");
  for (const auto& t : triangles_)
    for (std::uint32_t i : t)
      if (i >= vertices_.size())
        throw InvalidInputError("surface triangle refers to vertex " + std::to_string(i) + " of " +
                                std::to_string(vertices_.size()));
  buildGrid();
}

SurfaceDistance::SurfaceDistance(const pcl::PolygonMesh& mesh, float cell_size_m) : cell_size_(cell_size_m) {
  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  meshArrays(mesh, vertices, triangles);
  *this = SurfaceDistance(std::move(vertices), std::move(triangles), cell_size_m);
}

SurfaceDistance::Cell SurfaceDistance::cellOf(const Eigen::Vector3f& p) const {
  return (p / cell_size_).array().floor().cast<int>();
}

void SurfaceDistance::buildGrid() {
  for (std::uint32_t t = 0; t < triangles_.size(); ++t) {
    const auto& tri = triangles_[t];
    Eigen::Vector3f lo = vertices_[tri[0]], hi = lo;
    for (int k = 1; k < 3; ++k) {
      lo = lo.cwiseMin(vertices_[tri[k]]);
      hi = hi.cwiseMax(vertices_[tri[k]]);
    }
    if (!lo.allFinite() || !hi.allFinite())
      continue;
    const Cell a = cellOf(lo), b = cellOf(hi);
    for (int x = a.x(); x <= b.x(); ++x)
      for (int y = a.y(); y <= b.y(); ++y)
        for (int z = a.z(); z <= b.z(); ++z)
          grid_[Cell(x, y, z)].push_back(t);
  }
}

float SurfaceDistance::distance(const Eigen::Vector3f& p, float max_distance_m, std::uint32_t* nearest) const {
  float best2 = max_distance_m * max_distance_m;
  std::uint32_t best = kNoTriangle;
  auto scan = [&](const Cell& cell) {
    const auto it = grid_.find(cell);
    if (it == grid_.end())
      return;
    for (std::uint32_t t : it->second) {
      const auto& tri = triangles_[t];
      const float d2 = (closestOnTriangle(p, vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]) - p).squaredNorm();
      if (d2 < best2) {
        best2 = d2;
        best = t;
      }
    }
  };
  // The point's own cell first: near the surface it bounds the search, and the other cells
  // are visited only when their box is nearer than the best distance so far.
  const Cell home = cellOf(p);
  scan(home);
  const Cell a = cellOf(p - Eigen::Vector3f::Constant(max_distance_m));
  const Cell b = cellOf(p + Eigen::Vector3f::Constant(max_distance_m));
  for (int x = a.x(); x <= b.x(); ++x)
    for (int y = a.y(); y <= b.y(); ++y)
      for (int z = a.z(); z <= b.z(); ++z) {
        const Cell cell(x, y, z);
        if (cell == home)
          continue;
        const Eigen::Vector3f lo = cell.cast<float>() * cell_size_, hi = lo.array() + cell_size_;
        const float box2 = (p.cwiseMax(lo).cwiseMin(hi) - p).squaredNorm();
        if (box2 < best2)
          scan(cell);
      }
  if (nearest)
    *nearest = best;
  return std::sqrt(best2);
}

float SurfaceDistance::highestWithin(const Eigen::Vector3f& p, float radius_m, const std::vector<float>& values,
                                     float none) const {
  if (values.size() != triangles_.size())
    throw InvalidInputError("surface distance: " + std::to_string(values.size()) + " values for " +
                            std::to_string(triangles_.size()) + " triangles");
  float best = none;
  const float radius2 = radius_m * radius_m;
  const Cell a = cellOf(p - Eigen::Vector3f::Constant(radius_m));
  const Cell b = cellOf(p + Eigen::Vector3f::Constant(radius_m));
  for (int x = a.x(); x <= b.x(); ++x)
    for (int y = a.y(); y <= b.y(); ++y)
      for (int z = a.z(); z <= b.z(); ++z) {
        const auto it = grid_.find(Cell(x, y, z));
        if (it == grid_.end())
          continue;
        for (std::uint32_t t : it->second) {
          if (!(values[t] > best))
            continue; // cannot raise the answer: no distance needed
          const auto& tri = triangles_[t];
          if ((closestOnTriangle(p, vertices_[tri[0]], vertices_[tri[1]], vertices_[tri[2]]) - p).squaredNorm() < radius2)
            best = values[t];
        }
      }
  return best;
}

WeightCurve::WeightCurve(std::vector<float> sample_levels, const std::vector<float>& vertex_levels,
                         const std::vector<double>& vertex_distances)
    : sample_levels_(std::move(sample_levels)) {
  if (vertex_levels.size() != vertex_distances.size())
    throw InvalidInputError("weight curve: " + std::to_string(vertex_distances.size()) + " distances for " +
                            std::to_string(vertex_levels.size()) + " vertices");
  std::sort(sample_levels_.begin(), sample_levels_.end(), std::greater<float>());
  std::vector<std::size_t> order(vertex_levels.size());
  for (std::size_t i = 0; i < order.size(); ++i)
    order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return vertex_levels[a] > vertex_levels[b]; });
  vertex_levels_.reserve(order.size());
  distance_sums_.assign(1, 0.0);
  for (std::size_t i : order) {
    vertex_levels_.push_back(vertex_levels[i]);
    distance_sums_.push_back(distance_sums_.back() + vertex_distances[i]);
  }
}

WeightLevel WeightCurve::atWeight(double min_weight) const {
  // Counts of the descending levels at or above the bar.
  auto atOrAbove = [min_weight](const std::vector<float>& levels) {
    return static_cast<std::size_t>(std::partition_point(levels.begin(), levels.end(), [&](float l) {
                                      return l >= min_weight;
                                    }) - levels.begin());
  };
  WeightLevel level;
  level.min_weight = min_weight;
  level.vertices = atOrAbove(vertex_levels_);
  level.accuracy_mean_m = level.vertices ? distance_sums_[level.vertices] / static_cast<double>(level.vertices) : 0.0;
  level.completeness = sample_levels_.empty()
                           ? 0.0
                           : static_cast<double>(atOrAbove(sample_levels_)) / static_cast<double>(sample_levels_.size());
  return level;
}

WeightLevel WeightCurve::atCompleteness(double completeness) const {
  // The k-th highest sample level keeps at least k samples complete.
  const double needed = std::ceil(completeness * static_cast<double>(sample_levels_.size()) - 1e-9);
  const std::size_t k = static_cast<std::size_t>(std::max(1.0, needed));
  if (sample_levels_.empty() || k > sample_levels_.size() || sample_levels_[k - 1] < 0.f)
    return atWeight(0.0);
  return atWeight(sample_levels_[k - 1]);
}

namespace {

/// A class index for no true triangle (none within reach, or no classes).
constexpr std::uint8_t kOff = 255;

/// By weight: a triangle stays while its lightest vertex passes the bar, a vertex while its
/// surest triangle does.
void weightLevels(const std::vector<std::array<std::uint32_t, 3>>& triangles, const std::vector<float>& weights,
                  std::vector<float>& triangle_levels, std::vector<float>& vertex_levels) {
  vertex_levels.assign(weights.size(), -1.f);
  triangle_levels.reserve(triangles.size());
  for (const auto& t : triangles) {
    const float level = std::min({weights[t[0]], weights[t[1]], weights[t[2]]});
    triangle_levels.push_back(level);
    for (std::uint32_t i : t)
      vertex_levels[i] = std::max(vertex_levels[i], level);
  }
}

/// The class of the true triangle `t`, kOff for none.
std::uint8_t classOf(const std::vector<std::uint8_t>& triangle_class, std::uint32_t t) {
  return t == SurfaceDistance::kNoTriangle ? kOff : triangle_class[t];
}

/// Each true triangle's class: its first vertex's. Throws when the classes do not fit `truth`.
std::vector<std::uint8_t> trueTriangleClasses(const pcl::PolygonMesh& truth, const SurfaceDistance& to_truth,
                                              const SurfaceClasses& classes) {
  const std::size_t truth_vertices = truth.cloud.width * truth.cloud.height;
  if (classes.vertex_class.size() != truth_vertices)
    throw InvalidInputError("mesh evaluation: " + std::to_string(classes.vertex_class.size()) +
                            " classes for the true surface's " + std::to_string(truth_vertices) + " vertices");
  for (std::uint8_t c : classes.vertex_class)
    if (c >= classes.names.size())
      throw InvalidInputError("mesh evaluation: class " + std::to_string(c) + " of " +
                              std::to_string(classes.names.size()) + " names");
  std::vector<std::uint8_t> triangle_class(to_truth.numTriangles());
  for (std::uint32_t t = 0; t < triangle_class.size(); ++t)
    triangle_class[t] = classes.vertex_class[to_truth.triangle(t)[0]];
  return triangle_class;
}

/// The class of each sample, the samples taken every `truth_step` of `seen_truth`. A sample
/// lies on the truth, or within the tessellation's few centimetres of a curved solid's: its
/// class is the nearest triangle's within `on_surface`.
std::vector<std::uint8_t> sampleClasses(const SurfaceDistance& to_truth,
                                        const std::vector<std::uint8_t>& triangle_class,
                                        const std::vector<Eigen::Vector3f>& seen_truth, std::size_t truth_step,
                                        std::size_t samples, float on_surface) {
  std::vector<std::uint8_t> sample_class(samples);
  parallelFor(cv::Range(0, static_cast<int>(samples)), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      std::uint32_t nearest = SurfaceDistance::kNoTriangle;
      to_truth.distance(seen_truth[static_cast<std::size_t>(i) * truth_step], on_surface, &nearest);
      sample_class[i] = classOf(triangle_class, nearest);
    }
  });
  return sample_class;
}

/// The mean and median of the vertices' distances to the truth, and the share within the threshold.
void setAccuracy(const std::vector<double>& distances, double threshold_m, MeshAccuracy& result) {
  result.vertices = distances.size();
  double sum = 0;
  std::size_t near = 0;
  for (double d : distances) {
    sum += d;
    near += d <= threshold_m;
  }
  result.accuracy_mean_m = distances.empty() ? 0.0 : sum / static_cast<double>(distances.size());
  result.accuracy_median_m = median(distances);
  result.precision = distances.empty() ? 0.0 : static_cast<double>(near) / static_cast<double>(distances.size());
}

/// Accuracy and completeness per class of `names`, then kOffSurface's: the vertices' distances
/// by their class, the samples' coverage by theirs.
std::vector<ClassAccuracy> accuracyByClass(const std::vector<std::string>& names,
                                           const std::vector<std::uint8_t>& vertex_class,
                                           const std::vector<double>& distances,
                                           const std::vector<std::uint8_t>& sample_class,
                                           const std::vector<std::uint8_t>& is_covered) {
  const std::size_t n = names.size();
  std::vector<ClassAccuracy> split(n + 1), by_class;
  std::vector<double> sums(n + 1, 0.0);
  std::vector<std::size_t> hits(n + 1, 0);
  for (std::size_t c = 0; c < n; ++c)
    split[c].name = names[c];
  split[n].name = ClassAccuracy::kOffSurface;
  const auto slot = [n](std::uint8_t c) { return c == kOff ? n : static_cast<std::size_t>(c); };
  for (std::size_t i = 0; i < distances.size(); ++i) {
    ++split[slot(vertex_class[i])].vertices;
    sums[slot(vertex_class[i])] += distances[i];
  }
  for (std::size_t i = 0; i < sample_class.size(); ++i) {
    ++split[slot(sample_class[i])].truth_samples;
    hits[slot(sample_class[i])] += is_covered[i];
  }
  for (std::size_t c = 0; c <= n; ++c) {
    ClassAccuracy& a = split[c];
    a.accuracy_mean_m = a.vertices ? sums[c] / static_cast<double>(a.vertices) : 0.0;
    a.contribution_m = distances.empty() ? 0.0 : sums[c] / static_cast<double>(distances.size());
    a.completeness = a.truth_samples ? static_cast<double>(hits[c]) / static_cast<double>(a.truth_samples) : 0.0;
    if (a.vertices > 0 || a.truth_samples > 0 || c < n)
      by_class.push_back(a);
  }
  return by_class;
}

/// Completeness in 10 m bands of the distance to the nearest view, of the samples taken every
/// `truth_step` of `view_distance_m` (at least one sample).
std::vector<CompletenessBand> completenessByViewDistance(const std::vector<float>& view_distance_m,
                                                         std::size_t truth_step,
                                                         const std::vector<std::uint8_t>& is_covered) {
  constexpr double kBand = 10.0;
  const float farthest = *std::max_element(view_distance_m.begin(), view_distance_m.end());
  const int bands = std::max(1, static_cast<int>(std::ceil(farthest / kBand)));
  std::vector<std::size_t> n(bands), hit(bands);
  for (std::size_t i = 0; i < is_covered.size(); ++i) {
    const int b = std::clamp(static_cast<int>(std::ceil(view_distance_m[i * truth_step] / kBand)) - 1, 0, bands - 1);
    ++n[b];
    hit[b] += is_covered[i];
  }
  std::vector<CompletenessBand> by_band;
  for (int b = 0; b < bands; ++b)
    by_band.push_back({kBand * b, kBand * (b + 1), n[b], n[b] ? static_cast<double>(hit[b]) / static_cast<double>(n[b])
                                                               : 0.0});
  return by_band;
}

} // namespace

MeshAccuracy evaluateMesh(const pcl::PolygonMesh& mesh, const pcl::PolygonMesh& truth,
                          const std::vector<Eigen::Vector3f>& seen_truth, double threshold_m, double cap_m,
                          std::size_t max_samples, const std::vector<float>* view_distance_m,
                          const std::vector<float>* vertex_weights, const SurfaceClasses* truth_classes) {
  if (view_distance_m && view_distance_m->size() != seen_truth.size())
    throw InvalidInputError("mesh evaluation: " + std::to_string(view_distance_m->size()) + " view distances for " +
                            std::to_string(seen_truth.size()) + " samples of the seen surface");
  if (mesh.polygons.empty())
    throw InvalidInputError("the reconstructed mesh has no triangle");
  if (truth.polygons.empty())
    throw InvalidInputError("the true surface has no triangle");
  const float cap = static_cast<float>(cap_m), threshold = static_cast<float>(threshold_m);
  MeshAccuracy result;
  result.threshold_m = threshold_m;
  result.cap_m = cap_m;

  std::vector<Eigen::Vector3f> vertices;
  std::vector<std::array<std::uint32_t, 3>> triangles;
  meshArrays(mesh, vertices, triangles);
  if (vertex_weights && vertex_weights->size() != vertices.size())
    throw InvalidInputError("mesh evaluation: " + std::to_string(vertex_weights->size()) + " vertex weights for " +
                            std::to_string(vertices.size()) + " vertices");
  std::vector<float> triangle_levels, vertex_levels;
  if (vertex_weights)
    weightLevels(triangles, *vertex_weights, triangle_levels, vertex_levels);
  const SurfaceDistance to_truth(truth, std::max(cap, 0.25f));
  // Each true triangle's class: vertices and samples take their nearest's, kOff for none.
  const std::vector<std::uint8_t> triangle_class =
      truth_classes ? trueTriangleClasses(truth, to_truth, *truth_classes) : std::vector<std::uint8_t>();
  // A regular stride over large inputs: deterministic, and the statistics barely move.
  const std::size_t vertex_step = std::max<std::size_t>(1, (vertices.size() + max_samples - 1) / max_samples);
  std::vector<double> distances((vertices.size() + vertex_step - 1) / vertex_step);
  std::vector<std::uint8_t> vertex_class(truth_classes ? distances.size() : 0);
  parallelFor(cv::Range(0, static_cast<int>(distances.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      std::uint32_t nearest = SurfaceDistance::kNoTriangle;
      distances[i] = to_truth.distance(vertices[static_cast<std::size_t>(i) * vertex_step], cap,
                                       truth_classes ? &nearest : nullptr);
      if (truth_classes)
        vertex_class[i] = classOf(triangle_class, nearest);
    }
  });
  setAccuracy(distances, threshold_m, result);

  const SurfaceDistance to_mesh(std::move(vertices), std::move(triangles), std::max(threshold, 0.1f));
  const std::size_t truth_step = std::max<std::size_t>(1, (seen_truth.size() + max_samples - 1) / max_samples);
  const std::size_t samples = (seen_truth.size() + truth_step - 1) / truth_step;
  std::vector<std::uint8_t> is_covered(samples);
  std::vector<float> sample_levels(vertex_weights ? samples : 0);
  parallelFor(cv::Range(0, static_cast<int>(samples)), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      const Eigen::Vector3f& p = seen_truth[static_cast<std::size_t>(i) * truth_step];
      if (vertex_weights) {
        sample_levels[i] = to_mesh.highestWithin(p, threshold, triangle_levels, -1.f);
        is_covered[i] = sample_levels[i] >= 0.f;
      } else {
        is_covered[i] = to_mesh.distance(p, threshold) < threshold;
      }
    }
  });
  if (vertex_weights) {
    std::vector<float> sampled_levels(distances.size());
    for (std::size_t i = 0; i < sampled_levels.size(); ++i)
      sampled_levels[i] = vertex_levels[i * vertex_step];
    result.by_weight = WeightCurve(std::move(sample_levels), sampled_levels, distances);
  }
  const std::size_t covered = static_cast<std::size_t>(std::count(is_covered.begin(), is_covered.end(), 1));
  if (truth_classes) {
    const std::vector<std::uint8_t> sample_class =
        sampleClasses(to_truth, triangle_class, seen_truth, truth_step, samples, std::max(threshold, 0.05f));
    result.by_class = accuracyByClass(truth_classes->names, vertex_class, distances, sample_class, is_covered);
  }
  result.truth_samples = samples;
  result.completeness = samples == 0 ? 0.0 : static_cast<double>(covered) / static_cast<double>(samples);
  if (view_distance_m && samples > 0)
    result.by_view_distance = completenessByViewDistance(*view_distance_m, truth_step, is_covered);
  return result;
}

std::vector<float> nearestViewDistance(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& depths,
                                       float cell_m) {
  if (points.size() != depths.size())
    throw InvalidInputError("nearest view distance: " + std::to_string(depths.size()) + " depths for " +
                            std::to_string(points.size()) + " points");
  if (!(cell_m > 0.f))
    throw InvalidInputError("nearest view distance: the cell must be > 0 m, not " + std::to_string(cell_m));
  std::unordered_map<Eigen::Vector3i, float, CellHash> nearest;
  nearest.reserve(points.size() / 4);
  const auto cell = [cell_m](const Eigen::Vector3f& p) { return (p / cell_m).array().floor().cast<int>().matrix().eval(); };
  for (std::size_t i = 0; i < points.size(); ++i) {
    auto [it, fresh] = nearest.try_emplace(cell(points[i]), depths[i]);
    if (!fresh)
      it->second = std::min(it->second, depths[i]);
  }
  std::vector<float> out(points.size());
  for (std::size_t i = 0; i < points.size(); ++i)
    out[i] = nearest.at(cell(points[i]));
  return out;
}

} // namespace msf
