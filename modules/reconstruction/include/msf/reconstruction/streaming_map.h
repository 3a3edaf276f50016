// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_store.h>
#include <msf/reconstruction/tsdf_volume.h>

#include <Eigen/Core>

#include <cstdint>
#include <iosfwd>
#include <string>
#include <unordered_map>
#include <unordered_set>
#include <vector>

namespace msf {

/// A TsdfVolume that keeps in memory only the space around the sensor (docs/streaming.md).
/// The volume is cut into tiles of tile_blocks^3 blocks. After each frame, a tile whose box
/// (grown by one block, the layer its cubes read) lies farther than the active radius
/// from the sensor is meshed, its mesh written to DIR/tiles/X_Y_Z.ply, its blocks to
/// DIR/tsdf/X_Y_Z.blk (listed in DIR/tsdf/index.txt), and freed. Before each frame, a tile on
/// disk within `reach` of the sensor (how far the integrator changes blocks that exist:
/// TsdfIntegrator::reach) is read back; and a tile on disk within a block of a block that
/// the integrator is about to allocate is read back first (the volume's BlockSource), so that
/// integration always finds the voxels a map in memory would hold, and a revisit adds to the
/// surface instead of doubling it; the tiles whose meshes read the blocks read back are meshed
/// again at the end. The active radius must be at least reach + one tile, so that a tile is
/// not freed and read back at once.
///
/// finish() writes the tiles still in memory the same way and the mesh of the whole drive as
/// one PLY, the union of the tiles. Every file is written atomically, so a run that is killed
/// leaves readable tiles. A tile's mesh is welded inside the tile; vertices on a tile's border
/// are written by both tiles at the same position (bit for bit), and the union is welded by
/// them: it has the in-memory mesh's vertices and open edges (no seams).
class StreamingMap {
public:
  /// The YAML section `streaming`.
  /// Section `streaming` of a config file (docs/streaming.md).
  struct Config {
    static constexpr const char* kSection = "streaming";
    static constexpr const char* kAbout =
        "StreamingMap (docs/streaming.md): the map in bounded memory; tiles farther than active_radius_m from the "
        "camera are meshed into OUT/tiles, their TSDF written to OUT/tsdf and freed";
    /// At least the integrator's reach plus a tile (msf_reconstruct says so when it is less).
    double active_radius_m = 0.0;
    int tile_blocks = 8;

    template <class Keys>
    void keys(Keys& k) {
      k("active_radius_m", active_radius_m, atLeast(0),
        "metres around the sensor that stay in memory (0: the whole map in memory)");
      k("tile_blocks", tile_blocks, between(1, TsdfStore::kMaxTileBlocks),
        "edge of a tile in blocks of 8 voxels: the unit of streaming, of a tile file and of a mesh tile");
    }
    bool enabled() const { return active_radius_m > 0.0; }
    /// Throws ConfigError naming the key of a value out of range.
    void validate() const;
    /// Throws ConfigError when the active radius is below `reach_m` (TsdfIntegrator::reach)
    /// plus a tile of `voxel_size_m` voxels: a tile would be freed and read back at once.
    void requireRadius(double reach_m, double voxel_size_m) const;
  };

  struct Stats {
    std::size_t tiles_written = 0;   ///< tile meshes and block files written (again, for revisits)
    std::size_t tiles_reloaded = 0;  ///< tiles read back from disk
    /// of which read back only when the integrator allocated a block within a block of them
    /// (a band beyond `reach`, in front of a surface)
    std::size_t tiles_reloaded_on_allocation = 0;
    std::size_t tiles_remeshed = 0;  ///< tiles on disk meshed again by finish() after a revisit
    std::size_t blocks_freed = 0;
    std::size_t blocks_reloaded = 0;
    double stream_ms = 0;            ///< meshing, writing, freeing and reading back, in all
  };

  /// Streams `volume` (which must outlive this object) into `directory` (created when
  /// missing; earlier tiles in it are replaced). Throws ConfigError when the active radius is
  /// below reach_m plus a tile, IOError when the folder cannot be made.
  StreamingMap(TsdfVolume& volume, const Config& config, const MarchingCubes::Config& mesher, double reach_m,
               const std::string& directory);
  /// Detaches from the volume (its BlockSource).
  ~StreamingMap();
  StreamingMap(const StreamingMap&) = delete;
  StreamingMap& operator=(const StreamingMap&) = delete;

  /// Before integrating a frame seen from `sensor` (metres, world frame): reads back the tiles
  /// on disk within reach.
  void beforeIntegration(const Eigen::Vector3d& sensor);
  /// After integrating it: meshes, writes and frees the tiles beyond the active radius.
  void afterIntegration(const Eigen::Vector3d& sensor);
  /// Writes every tile still in memory (the volume is empty afterwards), meshes again the
  /// tiles on disk that a revisit made stale, and writes the union of all tiles to
  /// `mesh_path` (a binary PLY; none when no tile has a triangle). Returns its triangles.
  std::size_t finish(const std::string& mesh_path);

  const Stats& stats() const { return stats_; }
  double minimumRadius() const;

  /// Meshes a block store written by a StreamingMap (DIR/tsdf) tile by tile, in bounded
  /// memory, into the folder `mesh_path`.tiles (an OutputFolder: absent, empty or written by
  /// an earlier remesh, which it replaces) and their union `mesh_path`; with
  /// `lo` <= `hi` (metres) only the tiles that overlap that box. Returns the triangles
  /// written. Throws IOError naming a missing or garbled file.
  static std::size_t remesh(const std::string& directory, const MarchingCubes::Config& mesher,
                            const std::string& mesh_path, const Eigen::Vector3d& lo = Eigen::Vector3d::Ones(),
                            const Eigen::Vector3d& hi = Eigen::Vector3d::Zero());
  /// The blocks of a store as one volume (a region of a drive, or a short one: all of it is
  /// in memory). Throws IOError as remesh.
  static TsdfVolume loadStore(const std::string& directory);
  /// Meshes `tiles` of `store`, each with the layer around it read from the store's other
  /// tiles, into `tiles_directory`/X_Y_Z.ply (written atomically; a tile without a triangle
  /// has no file), one tile in memory at a time: tasks that mesh parts of one store side by
  /// side write the tiles a remesh would. Returns the triangles written.
  static std::size_t meshTiles(const TsdfStore& store, const MarchingCubes::Config& mesher,
                               const std::vector<GridIndex>& tiles, const std::string& tiles_directory);
  /// The welded union of the meshes of `tiles` in `tiles_directory` (those with a file) as one
  /// binary PLY at `mesh_path`, read one tile at a time (none written without a triangle).
  /// Returns its triangles. Throws IOError naming a tile mesh that is not one meshTiles wrote.
  static std::size_t unionOfTiles(const TsdfStore& store, const std::vector<GridIndex>& tiles,
                                  const std::string& tiles_directory, const std::string& mesh_path);

  /// Reads a PLY that writeMesh or finish wrote (binary, x y z float, red green blue uchar,
  /// triangles). Throws IOError naming the file when it is not one.
  static void readMesh(const std::string& path, TriangleMesh& mesh);
  /// Moves the vertices of a PLY that writeMesh or finish wrote by T, in place (atomically):
  /// the union of a streamed map in another world (msf_reconstruct -world z_up).
  static void transformMeshFile(const std::string& path, const Eigen::Isometry3d& T);
  /// Writes `mesh` as such a PLY, atomically.
  static void writeMesh(const std::string& path, const TriangleMesh& mesh);
  /// Merges vertices at the same position (bit for bit), e.g. of tiles/*.ply put together
  /// by another tool; triangles keep their order.
  static void weldByPosition(TriangleMesh& mesh);

private:
  using TileKey = std::uint64_t;
  TileKey tileOf(const GridIndex& block) const;
  GridIndex tileIndex(TileKey key) const;
  /// Distance from `p` to the tile's box of voxel centres grown by `grow_blocks` blocks.
  double distanceToTile(TileKey key, const Eigen::Vector3d& p, int grow_blocks) const;
  /// Meshes, writes and frees the tiles `tiles` (whose blocks are in memory).
  void evict(const std::vector<TileKey>& tiles);
  /// Reads the stored tiles `tiles` (evicted) back into the volume.
  void readBack(std::vector<TileKey> tiles);
  /// The volume's BlockSource: reads back the evicted tiles within a block of `blocks`.
  void readBackAround(const std::vector<GridIndex>& blocks);
  void writeIndex();
  std::string tilesDirectory() const;

  TsdfVolume& volume_;
  Config config_;
  MarchingCubes mesher_;
  double reach_m_;
  std::string directory_;
  TsdfStore store_;                      ///< DIR/tsdf
  std::unordered_set<TileKey> stored_;   ///< tiles with a block file
  std::unordered_set<TileKey> evicted_;  ///< stored tiles whose blocks are not in memory
  std::unordered_set<TileKey> stale_;    ///< evicted tiles whose mesh read blocks that were read back since
  Eigen::Vector3d last_check_{Eigen::Vector3d::Constant(1e300)};
  /// While this map puts blocks into the volume or frees them (readBackAround ignores it).
  bool moving_blocks_ = false;
  struct MovingBlocks {
    explicit MovingBlocks(bool& flag) : flag_(flag) { flag_ = true; }
    ~MovingBlocks() { flag_ = false; }
    bool& flag_;
  };
  Stats stats_;
};

} // namespace msf
