// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/spatial_hash.h>
#include <msf/io/surface_classes.h>

#include <Eigen/Core>
#include <pcl/PolygonMesh.h>

#include <array>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

namespace msf {

/// Exact distance from points to a triangle surface, through a uniform grid of cells that
/// lists the triangles overlapping each cell: a query looks only at the cells within its
/// search radius, so a large true scene costs little per point.
class SurfaceDistance {
public:
  /// Throws InvalidInputError when the mesh has no triangle or an index out of range.
  SurfaceDistance(std::vector<Eigen::Vector3f> vertices, std::vector<std::array<std::uint32_t, 3>> triangles,
                  float cell_size_m = 0.5f);
  /// From a pcl::PolygonMesh (fields x y z; polygons with 3 or more vertices are fanned).
  explicit SurfaceDistance(const pcl::PolygonMesh& mesh, float cell_size_m = 0.5f);

  /// Distance from p to the nearest triangle, or `max_distance_m` when none is nearer; with
  /// `nearest`, that triangle's index (kNoTriangle when none is nearer).
  float distance(const Eigen::Vector3f& p, float max_distance_m, std::uint32_t* nearest = nullptr) const;
  static constexpr std::uint32_t kNoTriangle = 0xffffffffu;
  /// The largest of `values` (one per triangle) over the triangles nearer to p than
  /// `radius_m`, or `none` when no triangle is that near.
  float highestWithin(const Eigen::Vector3f& p, float radius_m, const std::vector<float>& values, float none) const;

  std::size_t numTriangles() const { return triangles_.size(); }
  const std::array<std::uint32_t, 3>& triangle(std::uint32_t t) const { return triangles_[t]; }

private:
  using Cell = Eigen::Vector3i;
  struct CellEqual {
    bool operator()(const Cell& a, const Cell& b) const { return a == b; }
  };
  void buildGrid();
  Cell cellOf(const Eigen::Vector3f& p) const;

  std::vector<Eigen::Vector3f> vertices_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
  float cell_size_;
  std::unordered_map<Cell, std::vector<std::uint32_t>, CellHash, CellEqual> grid_;
};

/// Completeness of the seen true surface whose nearest view lies in (lower, upper] metres.
struct CompletenessBand {
  double lower_m = 0, upper_m = 0;
  std::size_t samples = 0;
  double completeness = 0; ///< 0 without samples
};

/// A mesh kept at a bar on its weights: the triangles whose three vertices weigh at least
/// `min_weight` (m^-2), scored as the whole mesh is.
struct WeightLevel {
  double min_weight = 0;
  std::size_t vertices = 0;     ///< evaluated vertices of the kept triangles
  double accuracy_mean_m = 0;   ///< 0 without vertices
  double completeness = 0;
};

/// Accuracy against completeness as the bar on a mesh's vertex weights (TriangleMesh::weights,
/// the inverse variance of the surface there) rises: what meshing only the surest surface
/// gives. A vertex stays while one of its triangles does; a sample of the true surface is
/// complete while a kept triangle lies within the threshold.
class WeightCurve {
public:
  WeightCurve() = default;
  /// Per sample of the seen true surface, the highest bar that keeps a triangle within the
  /// threshold of it (< 0: none at any bar); per evaluated vertex, the highest bar that keeps
  /// it and its distance to the truth (capped).
  WeightCurve(std::vector<float> sample_levels, const std::vector<float>& vertex_levels,
              const std::vector<double>& vertex_distances);

  bool empty() const { return sample_levels_.empty(); }
  /// The mesh kept at `min_weight` (0 keeps every triangle).
  WeightLevel atWeight(double min_weight) const;
  /// The mesh kept at the highest bar whose completeness is at least `completeness`: the
  /// surest surface that covers as much of the truth. The whole mesh when no bar reaches it.
  WeightLevel atCompleteness(double completeness) const;

private:
  std::vector<float> sample_levels_;  ///< descending
  std::vector<float> vertex_levels_;  ///< descending
  std::vector<double> distance_sums_; ///< of the vertices' distances in that order, from 0
};

/// The part of a mesh nearest one class of the true surface, and that class's completeness:
/// where the error of a mean comes from (trees, poles, buildings...).
struct ClassAccuracy {
  /// The class (SurfaceClasses::names); kOffSurface: vertices no true surface is within the
  /// cap of (ghosts, specks), each counted at the cap.
  std::string name;
  std::size_t vertices = 0;      ///< evaluated vertices whose nearest true surface is of the class
  double accuracy_mean_m = 0;    ///< their mean distance (capped); 0 without vertices
  double contribution_m = 0;     ///< their part of the mesh's accuracy_mean_m: the classes' sum is it
  std::size_t truth_samples = 0; ///< samples of the seen true surface on the class
  double completeness = 0;       ///< share of them within the threshold of the mesh; 0 without
  static constexpr const char* kOffSurface = "off_surface";
};

/// Mesh quality against the true surface (protocol 3, docs/design.md).
struct MeshAccuracy {
  std::size_t vertices = 0;            ///< vertices of the reconstructed mesh evaluated (sampled)
  double accuracy_mean_m = 0;          ///< mean distance of mesh vertices to the truth (capped)
  double accuracy_median_m = 0;
  double precision = 0;                ///< share of mesh vertices within `threshold_m` of the truth
  std::size_t truth_samples = 0;       ///< samples of the seen true surface
  double completeness = 0;             ///< share of them within `threshold_m` of the mesh
  double threshold_m = 0;
  double cap_m = 0;                    ///< distances are capped here for the mean
  /// Completeness by the distance the samples were seen from at the nearest (when given).
  std::vector<CompletenessBand> by_view_distance;
  /// Accuracy and completeness as the bar on the vertices' weights rises (when given).
  WeightCurve by_weight;
  /// Split by the class of the nearest true surface (when the truth's classes are given), in
  /// the order of their names, then kOffSurface.
  std::vector<ClassAccuracy> by_class;
};

/// For each of `points` (the seen true surface, from every frame), the least of `depths` (the
/// depth each was seen at) over the points in its cell of `cell_m`: the nearest distance any
/// frame saw that piece of surface from. Throws InvalidInputError for sizes that differ or a
/// cell that is not > 0.
std::vector<float> nearestViewDistance(const std::vector<Eigen::Vector3f>& points, const std::vector<float>& depths,
                                       float cell_m);

/// Accuracy of `mesh` against `truth` (every vertex), and completeness of the seen true
/// surface `seen_truth` (points on the truth, e.g. ground-truth depth pixels back-projected
/// into the world) against `mesh`. Distances are exact point-to-triangle distances,
/// capped at `cap_m`. Inputs larger than `max_samples` are taken at a regular stride.
/// With `view_distance_m` (one per seen_truth point, nearestViewDistance), completeness is also
/// given in bands of that distance, 10 m wide up to the farthest. With `vertex_weights` (one
/// per mesh vertex, TriangleMesh::weights), also by_weight. With `truth_classes` (one per
/// vertex of `truth`; a triangle is its first vertex's class), also by_class. Throws
/// InvalidInputError when `mesh` or `truth` has no triangle, or view_distance_m's size is not
/// seen_truth's, vertex_weights' not the mesh's vertices', truth_classes' not the truth's
/// vertices' or a class index is not below its names' count.
MeshAccuracy evaluateMesh(const pcl::PolygonMesh& mesh, const pcl::PolygonMesh& truth,
                          const std::vector<Eigen::Vector3f>& seen_truth, double threshold_m, double cap_m = 1.0,
                          std::size_t max_samples = 200000, const std::vector<float>* view_distance_m = nullptr,
                          const std::vector<float>* vertex_weights = nullptr,
                          const SurfaceClasses* truth_classes = nullptr);

} // namespace msf
