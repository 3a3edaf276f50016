#pragma once
#include <Eigen/Core>
#include <pcl/PolygonMesh.h>

#include <array>
#include <cstdint>
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

  /// Distance from p to the nearest triangle, or `max_distance_m` when none is nearer.
  float distance(const Eigen::Vector3f& p, float max_distance_m) const;

  std::size_t numTriangles() const { return triangles_.size(); }

private:
  using Cell = Eigen::Vector3i;
  struct CellHash {
    std::size_t operator()(const Cell& c) const {
      return static_cast<std::size_t>(c.x()) * 73856093u ^ static_cast<std::size_t>(c.y()) * 19349663u ^
             static_cast<std::size_t>(c.z()) * 83492791u;
    }
  };
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
/// given in bands of that distance, 10 m wide up to the farthest. Throws InvalidInputError
/// when `mesh` or `truth` has no triangle or view_distance_m's size is not seen_truth's.
MeshAccuracy evaluateMesh(const pcl::PolygonMesh& mesh, const pcl::PolygonMesh& truth,
                          const std::vector<Eigen::Vector3f>& seen_truth, double threshold_m, double cap_m = 1.0,
                          std::size_t max_samples = 200000, const std::vector<float>* view_distance_m = nullptr);

} // namespace msf
