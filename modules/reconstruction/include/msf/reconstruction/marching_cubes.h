// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/tsdf_volume.h>

#include <Eigen/Core>
#include <pcl/PolygonMesh.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <memory>
#include <unordered_map>
#include <vector>

namespace msf {

/// A welded triangle mesh: each vertex is stored once and shared by its triangles.
struct TriangleMesh {
  std::vector<Eigen::Vector3f> vertices;          ///< metres, world frame
  std::vector<std::array<std::uint8_t, 3>> colors; ///< r, g, b per vertex, or none
  /// Per vertex, the lesser weight (m^-2) of the two voxels whose zero crossing made it: how
  /// precisely the surface there is known; 0 where rays passed the one behind the surface since
  /// it last saw one (TsdfVoxel::passes): once, or MarchingCubes::Config::component_release_passes
  /// times in a row where a surface reappeared there after a pass (TsdfVoxel::reappeared).
  /// Filled by MarchingCubes; empty for other meshes.
  std::vector<float> weights;
  std::vector<std::array<std::uint32_t, 3>> triangles; ///< counter-clockwise seen from outside (sdf > 0)

  /// As a pcl::PolygonMesh whose cloud has fields x y z rgb (what saveMesh writes), x y z for a
  /// mesh without colours; throws InvalidInputError when colours are given but not one a vertex.
  void toPolygonMesh(pcl::PolygonMesh& mesh) const;
};

/// Marching cubes over the voxel centres of a TsdfVolume (Lorensen and Cline, with Paul
/// Bourke's tables), as Voxblox's MeshIntegrator: meshed block by block, in parallel, and
/// incrementally — an object remembers the mesh of each block and on the next call meshes
/// again only the blocks whose voxels changed since (and the blocks whose cubes read them).
/// Vertices are welded across blocks: a vertex is identified by the grid edge it lies on.
/// A cube is meshed only when all 8 of its voxels have weight > min_weight.
class MarchingCubes {
public:
  using Ptr = std::shared_ptr<MarchingCubes>;
  using ConstPtr = std::shared_ptr<const MarchingCubes>;

  /// Section `marching_cubes` of a config file.
  struct Config {
    static constexpr const char* kSection = "marching_cubes";
    static constexpr const char* kAbout = "MarchingCubes (msf_mesh): the mesh of the map's surface";
    /// Weights are inverse variances (m^-2, TsdfIntegrator::Weighting): 4 meshes what is known
    /// to sigma 0.5 m on its own, a LiDAR-backed surface after one frame, a stereo-only one at
    /// 20 m after one or two; smoothing_lambda pools the neighbours' evidence in, and the
    /// floating pieces such a bar lets through (matches in the sky) are removed below.
    float min_weight = 4.f;
    /// The band a frame writes behind a surface seen at a grazing angle, or at the end of its
    /// smooth run, stops short of the far corners of the cubes the surface crosses, which left
    /// holes there (KITTI's cars and roads); such corners are meshed a voxel behind the surface.
    int max_unseen_corners = 1;
    /// Each grid point within half a truncation of its surface is meshed at
    /// (W y + lambda sum_j y_j) / (W + lambda n) over its observed 6-neighbours j, one Jacobi
    /// step on the volume's weighted means y with weights W. A LiDAR-backed voxel (W ~ 1000)
    /// keeps its value; a far stereo-only one (W ~ 10) takes much of its neighbours'. The
    /// volume is not changed, so meshing again gives the same mesh.
    float smoothing_lambda = 10.f;
    /// 2000 triangles are about 10 m^2 at 0.1 m voxels: a piece smaller than that which no
    /// LiDAR return holds floats, as stereo's matches in the sky do, while a canopy hangs on its
    /// trunk and an upper façade on the lower one the LiDAR saw (removeSmallComponents). Not
    /// applied to a streamed map, whose tiles are meshed apart.
    int min_component_triangles = 2000;
    float component_keep_weight = 300.f;
    /// A closed piece within a box of this many voxels a side is removed whatever its weight: a
    /// bubble of a voxel or two whose sign the frames flipped against all their neighbours', which
    /// the weight of a much-seen place would keep; a pole or a sign spans tens of voxels, and an
    /// open fragment of a surface that holes cut off stays.
    float min_component_extent_voxels = 3.f;
    /// A vertex whose voxel behind the surface rays passed since it last saw a surface holds no
    /// piece: where a car stood. Once is enough where no ray had passed the voxel before (a car's
    /// back, whose inside no ray reached); where a surface reappeared after a pass, this many
    /// times in a row. Two, as vegetation's gaps let a single frame's rays through a leaf the
    /// LiDAR hit, a car's old place every frame after it left.
    int component_release_passes = 2;

    template <class Keys>
    void keys(Keys& k) {
      k("min_weight", min_weight, atLeast(0), "voxels of this weight or less make no triangles, m^-2");
      k("max_unseen_corners", max_unseen_corners, between(0, 4),
        "a cube with up to this many corners no frame reached, its others on both sides of the surface, is "
        "meshed with them behind it (0: off)");
      k("smoothing_lambda", smoothing_lambda, atLeast(0),
        "eq. 7 at meshing, each voxel's own mean weighed by its weight, m^-2 (0: off; the volume is not changed)");
      k("min_component_triangles", min_component_triangles, atLeast(0),
        "connected pieces of fewer triangles that no precise depth holds are removed (0: keep all)");
      k("component_keep_weight", component_keep_weight, atLeast(0),
        "a piece with a vertex of at least this weight is kept whatever its size, m^-2 (300: sigma 6 cm)");
      k("min_component_extent_voxels", min_component_extent_voxels, atLeast(0),
        "a closed piece within a box of this many voxels a side is removed whatever its weight (0: off)");
      k("component_release_passes", component_release_passes, between(0, TsdfVoxel::kMaxPasses),
        "a vertex holds no piece once rays passed the voxel behind it this many frames in a row, or once where "
        "no surface reappeared there after a pass (0: never)");
    }
    /// Throws ConfigError naming the key of a value out of range.
    void validate() const;
  };

  struct Stats {
    std::size_t blocks_meshed = 0;  ///< blocks meshed again by the last call
    std::size_t blocks_cached = 0;  ///< blocks whose mesh came from the cache
    std::size_t components_removed = 0; ///< pieces below min_component_triangles
    std::size_t triangles_removed = 0;  ///< their triangles
    double mesh_ms = 0, assemble_ms = 0, filter_ms = 0;
  };

  MarchingCubes() = default;
  explicit MarchingCubes(const Config& config);

  const Config& getConfig() const { return config_; }
  /// Changing min_weight or smoothing_lambda empties the cache.
  void setConfig(const Config& config);
  void setMinWeight(float min_weight);
  float getMinWeight() const { return config_.min_weight; }

  /// Meshes `volume`, incrementally when the same volume was meshed before by this object.
  void extract(const TsdfVolume& volume, TriangleMesh& mesh);
  /// The same as a pcl::PolygonMesh (fields x y z rgb; triangles as pcl::Vertices).
  void extract(const TsdfVolume& volume, pcl::PolygonMesh& mesh);
  /// Meshes only the blocks at `blocks` (absent ones are skipped), not incrementally and
  /// without the small-piece filter: the cubes of a block read its +x, +y, +z neighbours,
  /// which `volume` must hold for the block's mesh to be the one extract() gives. StreamingMap
  /// meshes a tile this way.
  void extractBlocks(const TsdfVolume& volume, const std::vector<GridIndex>& blocks, TriangleMesh& mesh) const;
  /// The offsets of the blocks whose voxels a block's mesh reads: the +x, +y, +z side, and all
  /// 26 around it when smoothing.
  const std::vector<GridIndex>& readNeighbours() const;
  /// Forgets the cached block meshes: the next call meshes everything.
  void reset();

  const Stats& lastStats() const { return stats_; }

  /// Per-block part of the mesh, kept between calls.
  struct BlockMesh {
    std::vector<Eigen::Vector3f> vertices;
    std::vector<std::array<std::uint8_t, 3>> colors;
    std::vector<float> weights;
    std::vector<std::uint64_t> keys; ///< grid edge of a vertex other blocks may also make; kInterior otherwise
    std::vector<std::array<std::uint32_t, 3>> triangles; ///< indices into this block's vertices
  };
  static constexpr std::uint64_t kInterior = ~std::uint64_t(0);

private:
  Config config_;
  Stats stats_;
  std::uint64_t volume_id_ = 0;
  std::uint64_t generation_ = 0;
  std::unordered_map<GridIndex, BlockMesh, GridIndexHash> cache_;
};

} // namespace msf
