// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/elapsed.h>
#include <msf/common/grid_key.h>
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/mesh_components.h>

#include "marching_cubes_tables.h"

#include <opencv2/core/utility.hpp>
#include <pcl/PCLPointField.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <ostream>

namespace msf {

namespace {

using Clock = std::chrono::steady_clock;

constexpr int kSide = TsdfBlock::kSide;
constexpr int kPad = kSide + 1; // a block's cubes read one voxel layer of its +x, +y, +z neighbours
constexpr int kHalo = kSide + 3; // smoothed, those grid points read one voxel more on every side

// Bourke's corner numbering and edges, those of PCL's tables (see marching_cubes_tables.cpp).
constexpr int kCorner[8][3] = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}, {0, 0, 1}, {1, 0, 1}, {1, 1, 1}, {0, 1, 1}};
/// A crossing this near an edge's end (a share of the edge) is at the end's voxel.
constexpr float kOnVoxel = 1e-5f;
constexpr int kEdge[12][2] = {{0, 1}, {1, 2}, {2, 3}, {3, 0}, {4, 5}, {5, 6}, {6, 7}, {7, 4}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};


/// A vertex is keyed by the grid element it lies on: the lower voxel of a grid edge and the
/// edge's axis (0..2), or a voxel itself (3) when its sdf is exactly 0. Each axis keeps its low
/// 20 bits, so keys differ within any 2^20 voxels an axis (105 km at 0.1 m: more than a mesh
/// holds), wherever in the volume's reach the map lies.
constexpr std::uint64_t kKeyAxisMask = (std::uint64_t(1) << 20) - 1;
std::uint64_t vertexKey(int x, int y, int z, int code) {
  const auto axis = [](int c) { return static_cast<std::uint64_t>(static_cast<std::uint32_t>(c)) & kKeyAxisMask; };
  return axis(x) << 42 | axis(y) << 22 | axis(z) << 2 | static_cast<std::uint64_t>(code);
}

std::uint64_t blockKey(const GridIndex& b) { return GridKey<21>::pack(b); }

bool lessIndex(const GridIndex& a, const GridIndex& b) {
  if (a.x() != b.x()) return a.x() < b.x();
  if (a.y() != b.y()) return a.y() < b.y();
  return a.z() < b.z();
}

/// Per-thread working memory for meshing one block.
struct Scratch {
  // The 9^3 grid points a block's cubes read, as 81 rows of 9 along x (row = y + 9 z): bit x
  // of a row's mask is voxel x, and each row's voxels are found through two pointers (x < 8
  // in one block, x = 8 in its +x neighbour), so no voxel is copied.
  std::array<std::uint16_t, kPad * kPad> valid; // weight > min_weight
  std::array<std::uint16_t, kPad * kPad> negative; // sdf < 0 and valid
  std::array<std::uint16_t, kPad * kPad> unseen;   // weight 0 (no frame reached it)
  std::array<std::array<const TsdfVoxel*, 2>, kPad * kPad> row;
  std::array<float, kPad * kPad * kPad> sdf; // of the 9^3 grid points (x + 9 (y + 9 z)), smoothed or not
  std::array<float, kHalo * kHalo * kHalo> halo_sdf, halo_weight; // -1..9 on each axis, for smoothing
  std::array<std::int32_t, kPad * kPad * kPad * 4> slot; // local vertex of (grid point, code), -1 = none
  std::vector<int> used;
  MarchingCubes::BlockMesh mesh; // grows once per thread, then copied out at its exact size
  Scratch() { slot.fill(-1); }

  const TsdfVoxel& voxel(int x, int y, int z) const { return row[y + kPad * z][x >> 3][x & 7]; }
};

/// The sdf of the block's 9^3 grid points after one Jacobi step of eq. 7 with each voxel's
/// data term weighed by its weight: x_i = (W_i y_i + lambda sum_j y_j) / (W_i + lambda n_i) over
/// the observed 6-neighbours j, for observed voxels within `band` of their surface (the others
/// keep y_i). `around` holds the 27 blocks at offsets -1..1 (x fastest), or null.
void smoothGridPoints(const TsdfBlock* const* around, float lambda, float band, Scratch& s) {
  for (int z = -1; z <= kSide + 1; ++z)
    for (int y = -1; y <= kSide + 1; ++y) {
      const int bz = z < 0 ? 0 : z < kSide ? 1 : 2, by = y < 0 ? 0 : y < kSide ? 1 : 2;
      float* hs = &s.halo_sdf[static_cast<std::size_t>(kHalo) * ((y + 1) + kHalo * (z + 1))];
      float* hw = &s.halo_weight[static_cast<std::size_t>(kHalo) * ((y + 1) + kHalo * (z + 1))];
      for (int x = -1; x <= kSide + 1; ++x) {
        const int bx = x < 0 ? 0 : x < kSide ? 1 : 2;
        const TsdfBlock* b = around[bx + 3 * (by + 3 * bz)];
        const TsdfVoxel* v = b ? &b->at(x - kSide * (bx - 1), y - kSide * (by - 1), z - kSide * (bz - 1)) : nullptr;
        hs[x + 1] = v ? v->sdf : 0.f;
        hw[x + 1] = v ? v->weight : 0.f;
      }
    }
  constexpr int sy = kHalo, sz = kHalo * kHalo;
  for (int z = 0; z < kPad; ++z)
    for (int y = 0; y < kPad; ++y)
      for (int x = 0; x < kPad; ++x) {
        const int q = (x + 1) + kHalo * ((y + 1) + kHalo * (z + 1));
        const float w = s.halo_weight[q], sdf = s.halo_sdf[q];
        float value = sdf;
        if (w > 0.f && std::abs(sdf) < band) {
          float sum = 0.f, count = 0.f;
          for (const int d : {-1, 1, -sy, sy, -sz, sz}) {
            const bool observed = s.halo_weight[q + d] > 0.f; // without branches: unpredictable
            sum += observed ? s.halo_sdf[q + d] : 0.f;
            count += observed ? 1.f : 0.f;
          }
          value = (w * sdf + lambda * sum) / (w + lambda * count);
        }
        s.sdf[x + kPad * (y + kPad * z)] = value;
      }
}

/// The blocks a block's cubes and (smoothed) grid points read: `corner` the 8 at offsets 0..1
/// (x fastest), `around` the 27 at -1..1 when smoothing. False when no sign change lies within
/// their reach, so the block has no surface.
bool gatherNeighbours(const TsdfVolume& volume, const TsdfBlock& block, bool smooth, const TsdfBlock* corner[8],
                      const TsdfBlock* around[27]) {
  std::uint8_t signs = 0;
  for (int i = 0; i < 8; ++i) {
    corner[i] = i == 0 ? &block : volume.findBlock(block.index + GridIndex(i & 1, (i >> 1) & 1, (i >> 2) & 1));
    signs |= corner[i] ? corner[i]->signs : 0;
  }
  // Smoothed, a grid point also reads the -x, -y, -z layer around the block.
  for (int i = 0; smooth && i < 27; ++i) {
    const GridIndex d(i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1);
    around[i] = d.isZero() ? &block : volume.findBlock(block.index + d);
    signs |= around[i] ? around[i]->signs : 0;
  }
  return signs == (TsdfBlock::kHasPositive | TsdfBlock::kHasNegative);
}

/// What a block that was never allocated reads as: a block no frame reached. A mesh then does
/// not depend on which blocks a run allocated and left unobserved, which a saved volume omits.
const TsdfBlock& unallocatedBlock() {
  static const TsdfBlock unobserved;
  return unobserved;
}

/// Fills the scratch's rows of voxel pointers, the sdf of the grid points (unless smoothing
/// wrote them) and the bit masks of valid, negative and unseen points; a missing neighbour
/// block's points are unseen. False when no valid point is negative or none positive.
bool loadGridPoints(const TsdfBlock* const corner[8], float min_weight, bool smoothed, Scratch& s) {
  std::uint16_t any_negative = 0, any_positive = 0;
  for (int z = 0; z < kPad; ++z)
    for (int y = 0; y < kPad; ++y) {
      const int r = y + kPad * z;
      const int sel = ((y >> 3) << 1) | ((z >> 3) << 2);
      std::uint16_t valid = 0, negative = 0, unseen = 0;
      for (int part = 0; part < 2; ++part) {
        const TsdfBlock* b = corner[sel | part] ? corner[sel | part] : &unallocatedBlock();
        const TsdfVoxel* src = s.row[r][part] = &b->at(0, y & 7, z & 7);
        float* sdf = &s.sdf[static_cast<std::size_t>(kPad) * r];
        for (int x = part * kSide, n = part ? 1 : kSide, k = 0; k < n; ++k, ++x) {
          if (!smoothed)
            sdf[x] = src[k].sdf;
          valid |= static_cast<std::uint16_t>((src[k].weight > min_weight) << x);
          unseen |= static_cast<std::uint16_t>((src[k].weight <= 0.f) << x);
          negative |= static_cast<std::uint16_t>((sdf[x] < 0.f) << x);
        }
      }
      negative &= valid;
      s.valid[r] = valid;
      s.negative[r] = negative;
      s.unseen[r] = unseen;
      any_negative |= negative;
      any_positive |= valid & ~negative;
    }
  return any_negative && any_positive;
}

/// Makes a block's vertices, each once: a grid element's vertex is made by its first cube and
/// found in the scratch's slots by the others.
class BlockVertices {
public:
  BlockVertices(const GridIndex& origin, float voxel_size, int release_passes, MarchingCubes::BlockMesh& out,
                Scratch& s)
      : origin_(origin), voxel_size_(voxel_size), release_passes_(release_passes), out_(out), s_(s) {}
  ~BlockVertices() {
    for (const int u : s_.used)
      s_.slot[u] = -1;
    s_.used.clear();
  }

  /// The vertex on grid point (px, py, pz)'s edge along `code` (0..2) at t from it towards the
  /// voxel `b`, or on the point itself (code 3).
  std::uint32_t vertex(int px, int py, int pz, int code, float t, const TsdfVoxel& a, const TsdfVoxel& b) {
    const int local = px + kPad * (py + kPad * pz);
    std::int32_t& slot = s_.slot[local * 4 + code];
    if (slot >= 0)
      return static_cast<std::uint32_t>(slot);
    slot = static_cast<std::int32_t>(out_.vertices.size());
    s_.used.push_back(local * 4 + code);
    Eigen::Vector3f p(static_cast<float>(origin_.x() + px), static_cast<float>(origin_.y() + py),
                      static_cast<float>(origin_.z() + pz));
    if (code < 3)
      p[code] += t;
    out_.vertices.push_back(p * voxel_size_);
    out_.colors.push_back(colour(t, a, b));
    // 0 next to an unseen corner (no evidence) and where rays passed the corner behind the
    // surface since it last saw one: the surface was seen to go. Once is enough where no ray
    // had passed it before; release_passes times in a row where a surface reappeared after one.
    const TsdfVoxel& behind = a.sdf < b.sdf ? a : b;
    const bool released = release_passes_ > 0 && behind.passes() >= (behind.reappeared() ? release_passes_ : 1);
    out_.weights.push_back(released ? 0.f : std::min(a.weight, b.weight));
    out_.keys.push_back(isInterior(px, py, pz, code)
                            ? MarchingCubes::kInterior
                            : vertexKey(origin_.x() + px, origin_.y() + py, origin_.z() + pz, code));
    return static_cast<std::uint32_t>(slot);
  }

private:
  /// An unseen voxel (a filled cube's corner) has no colour: its edge takes the other end's.
  static std::array<std::uint8_t, 3> colour(float t, const TsdfVoxel& a, const TsdfVoxel& b) {
    const TsdfVoxel& colour_a = a.weight > 0.f ? a : b;
    const TsdfVoxel& colour_b = b.weight > 0.f ? b : a;
    const std::uint8_t ca[3] = {colour_a.r, colour_a.g, colour_a.b}, cb[3] = {colour_b.r, colour_b.g, colour_b.b};
    std::array<std::uint8_t, 3> c;
    for (int k = 0; k < 3; ++k)
      c[k] = static_cast<std::uint8_t>(ca[k] + t * (static_cast<float>(cb[k]) - ca[k]) + 0.5f);
    return c;
  }
  /// Every cube around this edge (or voxel) belongs to this block, so no other block makes it.
  static bool isInterior(int px, int py, int pz, int code) {
    const int q[3] = {px, py, pz};
    for (int k = 0; k < 3; ++k)
      if (k != code && (q[k] < 1 || q[k] > kSide - 1))
        return false;
    return true;
  }

  GridIndex origin_;
  float voxel_size_;
  int release_passes_;
  MarchingCubes::BlockMesh& out_;
  Scratch& s_;
};

/// The masks of a row of 8 cubes (y, z), read from the 4 rows of grid points around them;
/// cube x reads bits x and x + 1 of each.
struct CubeRow {
  unsigned n00, n10, n01, n11; ///< negative
  unsigned u00, u10, u01, u11; ///< unseen
  unsigned active;             ///< cubes whose 8 corners are observed and not all of one sign
  unsigned filled = 0;         ///< cubes whose unseen corners lie behind the surface

  CubeRow(const Scratch& s, int y, int z, int max_unseen) {
    const int r00 = y + kPad * z, r10 = r00 + 1, r01 = r00 + kPad, r11 = r01 + 1;
    const unsigned valid4 = s.valid[r00] & s.valid[r10] & s.valid[r01] & s.valid[r11];
    n00 = s.negative[r00], n10 = s.negative[r10], n01 = s.negative[r01], n11 = s.negative[r11];
    const unsigned all_negative = n00 & n10 & n01 & n11, any_neg = n00 | n10 | n01 | n11;
    active = valid4 & (valid4 >> 1) & (any_neg | (any_neg >> 1)) & ~(all_negative & (all_negative >> 1)) & 0xffu;
    u00 = s.unseen[r00], u10 = s.unseen[r10], u01 = s.unseen[r01], u11 = s.unseen[r11];
    if (max_unseen <= 0)
      return;
    // Config::max_unseen_corners: every corner valid or unseen, a valid one on each side, and at
    // most max_unseen unseen.
    const unsigned known4 =
        (s.valid[r00] | u00) & (s.valid[r10] | u10) & (s.valid[r01] | u01) & (s.valid[r11] | u11);
    const unsigned any_pos =
        (s.valid[r00] & ~n00) | (s.valid[r10] & ~n10) | (s.valid[r01] & ~n01) | (s.valid[r11] & ~n11);
    const unsigned candidates =
        known4 & (known4 >> 1) & (any_pos | (any_pos >> 1)) & (any_neg | (any_neg >> 1)) & ~active & 0xffu;
    for (unsigned c = candidates; c; c &= c - 1) {
      const int x = __builtin_ctz(c);
      const unsigned corners = ((u00 >> x) & 3) | ((u10 >> x) & 3) << 2 | ((u01 >> x) & 3) << 4 | ((u11 >> x) & 3) << 6;
      filled |= (__builtin_popcount(corners) <= max_unseen ? 1u : 0u) << x;
    }
  }

  /// Cube x's case in Bourke's corners 0..7: (0,0,0) (1,0,0) (1,1,0) (0,1,0) (0,0,1) (1,0,1)
  /// (1,1,1) (0,1,1). A filled cube counts its unseen corners inside.
  int cubeCase(int x, bool fill) const {
    const unsigned m00 = fill ? n00 | u00 : n00, m10 = fill ? n10 | u10 : n10;
    const unsigned m01 = fill ? n01 | u01 : n01, m11 = fill ? n11 | u11 : n11;
    return static_cast<int>(((m00 >> x) & 1) | ((m00 >> x) & 2) | ((m10 >> x) & 2) << 1 | ((m10 >> x) & 1) << 3 |
                            ((m01 >> x) & 1) << 4 | ((m01 >> x) & 2) << 4 | ((m11 >> x) & 2) << 5 |
                            ((m11 >> x) & 1) << 7);
  }
};

/// The triangles of cube (x, y, z). An unseen corner of a filled cube is a voxel behind the
/// surface: an edge from a seen corner at distance p to it is crossed p * voxel / (p + voxel)
/// from that corner, about p for a small p.
void meshCube(int x, int y, int z, int cube, bool fill, float voxel_size, const Scratch& s, BlockVertices& vertices,
              MarchingCubes::BlockMesh& out) {
  const unsigned int edges = detail::kEdgeTable[cube];
  const TsdfVoxel* c[8];
  float d[8];
  for (int i = 0; i < 8; ++i) {
    const int px = x + kCorner[i][0], py = y + kCorner[i][1], pz = z + kCorner[i][2];
    c[i] = &s.voxel(px, py, pz);
    d[i] = fill && c[i]->weight <= 0.f ? -voxel_size : s.sdf[px + kPad * (py + kPad * pz)];
  }
  std::uint32_t vert[12];
  for (int e = 0; e < 12; ++e) {
    if (!(edges & (1u << e)))
      continue;
    int ia = kEdge[e][0], ib = kEdge[e][1];
    int axis = 0;
    while (kCorner[ia][axis] == kCorner[ib][axis])
      ++axis;
    if (kCorner[ia][axis] > kCorner[ib][axis])
      std::swap(ia, ib); // interpolate from the lower end, so every block computes the same vertex
    const TsdfVoxel& a = *c[ia];
    const TsdfVoxel& b = *c[ib];
    const int px = x + kCorner[ia][0], py = y + kCorner[ia][1], pz = z + kCorner[ia][2];
    // A voxel at the crossing (sdf 0, or so near it that the vertex would round to the voxel's
    // position) is the vertex of all its edges (no duplicate positions).
    const float t = d[ia] / (d[ia] - d[ib]);
    if (!(t > kOnVoxel))
      vert[e] = vertices.vertex(px, py, pz, 3, 0.f, a, a);
    else if (!(t < 1.f - kOnVoxel))
      vert[e] = vertices.vertex(px + (axis == 0), py + (axis == 1), pz + (axis == 2), 3, 0.f, b, b);
    else
      vert[e] = vertices.vertex(px, py, pz, axis, t, a, b);
  }
  const int* tri = detail::kTriTable[cube];
  for (int t = 0; tri[t] != -1; t += 3) {
    // Bourke's order is clockwise seen from outside with "inside = sdf < 0": reversed here.
    const std::array<std::uint32_t, 3> f = {vert[tri[t]], vert[tri[t + 2]], vert[tri[t + 1]]};
    if (f[0] != f[1] && f[1] != f[2] && f[0] != f[2])
      out.triangles.push_back(f);
  }
}

void meshBlockInto(const TsdfVolume& volume, const TsdfBlock& block, const MarchingCubes::Config& config,
                   MarchingCubes::BlockMesh& out, Scratch& s) {
  if (block.signs == 0)
    return; // never observed: every cube has this block's unobserved corner
  const bool smooth = config.smoothing_lambda > 0.f;
  const TsdfBlock* corner[8];
  const TsdfBlock* around[27] = {};
  if (!gatherNeighbours(volume, block, smooth, corner, around))
    return;
  if (smooth)
    smoothGridPoints(around, config.smoothing_lambda, 0.5f * static_cast<float>(volume.truncation()), s);
  if (!loadGridPoints(corner, config.min_weight, smooth, s))
    return;
  const float voxel_size = static_cast<float>(volume.voxelSize());
  BlockVertices vertices(block.origin(), voxel_size, config.component_release_passes, out, s);
  for (int z = 0; z < kSide; ++z)
    for (int y = 0; y < kSide; ++y) {
      const CubeRow row(s, y, z, config.max_unseen_corners);
      for (unsigned cubes = row.active | row.filled; cubes; cubes &= cubes - 1) {
        const int x = __builtin_ctz(cubes);
        const bool fill = (row.filled >> x) & 1;
        meshCube(x, y, z, row.cubeCase(x, fill), fill, voxel_size, s, vertices, out);
      }
    }
}

void meshBlock(const TsdfVolume& volume, const TsdfBlock& block, const MarchingCubes::Config& config,
               MarchingCubes::BlockMesh& out, Scratch& s) {
  MarchingCubes::BlockMesh& m = s.mesh;
  m.vertices.clear();
  m.colors.clear();
  m.weights.clear();
  m.keys.clear();
  m.triangles.clear();
  meshBlockInto(volume, block, config, m, s);
  out.vertices.assign(m.vertices.begin(), m.vertices.end());
  out.colors.assign(m.colors.begin(), m.colors.end());
  out.weights.assign(m.weights.begin(), m.weights.end());
  out.keys.assign(m.keys.begin(), m.keys.end());
  out.triangles.assign(m.triangles.begin(), m.triangles.end());
}

/// Open addressing map from a vertex key to its index in the assembled mesh.
class VertexIndexMap {
public:
  explicit VertexIndexMap(std::size_t expected) {
    std::size_t cap = 16;
    while (cap < 2 * expected)
      cap <<= 1;
    table_.assign(cap, Entry{MarchingCubes::kInterior, 0});
    mask_ = cap - 1;
  }
  /// The index stored for `key`, or `value` after storing it.
  std::uint32_t findOrInsert(std::uint64_t key, std::uint32_t value, bool& inserted) {
    for (std::size_t h = slot(key);; h = (h + 1) & mask_) {
      Entry& e = table_[h];
      if (e.key == key) {
        inserted = false;
        return e.value;
      }
      if (e.key == MarchingCubes::kInterior) {
        e = {key, value};
        inserted = true;
        return value;
      }
    }
  }
  /// The table is larger than the caches and the keys are spread over it: fetching a key's
  /// slot a few keys ahead hides most of the wait.
  void prefetch(std::uint64_t key) const { __builtin_prefetch(&table_[slot(key)]); }

private:
  struct Entry {
    std::uint64_t key;
    std::uint32_t value;
  };
  std::size_t slot(std::uint64_t key) const { return (key * 0x9E3779B97F4A7C15ull) >> 20 & mask_; }

  std::vector<Entry> table_;
  std::size_t mask_;
};

/// The mesh of block meshes, welded through their shared vertices' keys, in block order
/// (sorted here), whatever the order of `order`.
void assembleParts(std::vector<std::pair<GridIndex, const MarchingCubes::BlockMesh*>>& order, TriangleMesh& mesh) {
  order.erase(std::remove_if(order.begin(), order.end(), [](const auto& p) { return p.second->triangles.empty(); }),
              order.end());
  std::size_t total_shared = 0;
  for (const auto& entry : order)
    for (const std::uint64_t k : entry.second->keys)
      total_shared += k != MarchingCubes::kInterior;
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return lessIndex(a.first, b.first); });
  // Vertices that several blocks may make are numbered first, serially through a hash of
  // their grid keys; each block's interior vertices follow in block order, copied in parallel.
  const std::size_t parts = order.size();
  std::vector<std::size_t> remap_offset(parts + 1, 0), triangle_offset(parts + 1, 0), interior_offset(parts + 1, 0);
  for (std::size_t i = 0; i < parts; ++i) {
    remap_offset[i + 1] = remap_offset[i] + order[i].second->vertices.size();
    triangle_offset[i + 1] = triangle_offset[i] + order[i].second->triangles.size();
  }
  std::vector<std::uint32_t> remap(remap_offset[parts]);
  std::vector<std::pair<std::uint32_t, std::uint32_t>> shared_source; // (part, vertex) of each shared vertex
  shared_source.reserve(total_shared);
  VertexIndexMap shared(total_shared);
  for (std::size_t i = 0; i < parts; ++i) {
    const MarchingCubes::BlockMesh& part = *order[i].second;
    std::size_t interior = 0;
    for (std::size_t v = 0; v < part.keys.size(); ++v) {
      constexpr std::size_t kAhead = 8;
      if (v + kAhead < part.keys.size() && part.keys[v + kAhead] != MarchingCubes::kInterior)
        shared.prefetch(part.keys[v + kAhead]);
      if (part.keys[v] == MarchingCubes::kInterior) {
        ++interior;
        continue;
      }
      bool inserted = false;
      const auto next = static_cast<std::uint32_t>(shared_source.size());
      remap[remap_offset[i] + v] = shared.findOrInsert(part.keys[v], next, inserted);
      if (inserted)
        shared_source.emplace_back(static_cast<std::uint32_t>(i), static_cast<std::uint32_t>(v));
    }
    interior_offset[i + 1] = interior_offset[i] + interior;
  }
  const std::size_t n_shared = shared_source.size();
  const std::size_t n_vertices = n_shared + interior_offset[parts];
  mesh.vertices.resize(n_vertices);
  mesh.colors.resize(n_vertices);
  mesh.weights.resize(n_vertices);
  mesh.triangles.resize(triangle_offset[parts]);
  parallelFor(cv::Range(0, static_cast<int>(parts)), [&](const cv::Range& range) {
  for (int i = range.start; i < range.end; ++i) {
    const MarchingCubes::BlockMesh& part = *order[i].second;
    std::uint32_t* map = &remap[remap_offset[i]];
    auto next = static_cast<std::uint32_t>(n_shared + interior_offset[i]);
    for (std::size_t v = 0; v < part.keys.size(); ++v)
      if (part.keys[v] == MarchingCubes::kInterior) {
        map[v] = next;
        mesh.vertices[next] = part.vertices[v];
        mesh.colors[next] = part.colors[v];
        mesh.weights[next] = part.weights[v];
        ++next;
      }
    std::array<std::uint32_t, 3>* out = &mesh.triangles[triangle_offset[i]];
    for (std::size_t t = 0; t < part.triangles.size(); ++t)
      out[t] = {map[part.triangles[t][0]], map[part.triangles[t][1]], map[part.triangles[t][2]]};
  }
  }, std::max(1.0, static_cast<double>(parts) / 16));
  parallelFor(cv::Range(0, static_cast<int>(n_shared)), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k) {
      const MarchingCubes::BlockMesh& part = *order[shared_source[k].first].second;
      mesh.vertices[k] = part.vertices[shared_source[k].second];
      mesh.colors[k] = part.colors[shared_source[k].second];
      mesh.weights[k] = part.weights[shared_source[k].second];
    }
  }, 8);
}

} // namespace

void MarchingCubes::Config::validate() const { checkKeyRanges(*this); }

MarchingCubes::MarchingCubes(const Config& config) { setConfig(config); }

void MarchingCubes::setConfig(const Config& config) {
  config.validate();
  if (config.min_weight != config_.min_weight || config.smoothing_lambda != config_.smoothing_lambda ||
      config.max_unseen_corners != config_.max_unseen_corners ||
      config.component_release_passes != config_.component_release_passes)
    reset();
  config_ = config;
}

void MarchingCubes::setMinWeight(float min_weight) {
  Config c = config_;
  c.min_weight = min_weight;
  setConfig(c);
}

const std::vector<GridIndex>& MarchingCubes::readNeighbours() const {
  static const std::vector<GridIndex> upper = {{1, 0, 0}, {0, 1, 0}, {1, 1, 0}, {0, 0, 1},
                                               {1, 0, 1}, {0, 1, 1}, {1, 1, 1}};
  static const std::vector<GridIndex> all = [] {
    std::vector<GridIndex> v;
    for (int i = 0; i < 27; ++i)
      if (i != 13)
        v.emplace_back(i % 3 - 1, (i / 3) % 3 - 1, i / 9 - 1);
    return v;
  }();
  return config_.smoothing_lambda > 0.f ? all : upper;
}

void MarchingCubes::reset() {
  cache_.clear();
  volume_id_ = 0;
  generation_ = 0;
}

void MarchingCubes::extract(const TsdfVolume& volume, TriangleMesh& mesh) {
  stats_ = Stats();
  const auto t0 = Clock::now();
  if (volume.id() != volume_id_) {
    cache_.clear();
    volume_id_ = volume.id();
    generation_ = 0;
  }

  // Blocks to mesh again: the changed ones and those whose cubes read them.
  const std::vector<GridIndex>& readers = readNeighbours();
  std::vector<std::uint64_t> dirty_keys;
  std::vector<const TsdfBlock*> dirty;
  for (const auto& block : volume.blocks()) {
    if (block->stamp <= generation_)
      continue;
    if (generation_ == 0) { // first call: every block is meshed anyway
      dirty_keys.push_back(blockKey(block->index));
      continue;
    }
    dirty_keys.push_back(blockKey(block->index));
    for (const GridIndex& d : readers)
      if (volume.findBlock(block->index - d))
        dirty_keys.push_back(blockKey(block->index - d));
  }
  std::sort(dirty_keys.begin(), dirty_keys.end());
  dirty_keys.erase(std::unique(dirty_keys.begin(), dirty_keys.end()), dirty_keys.end());
  std::vector<BlockMesh*> targets;
  for (const auto& block : volume.blocks())
    if (std::binary_search(dirty_keys.begin(), dirty_keys.end(), blockKey(block->index))) {
      dirty.push_back(block);
      targets.push_back(&cache_[block->index]);
    }
  // cv::parallel_for_ (TBB) as the integrator: one pool shared with the other stages.
  parallelFor(cv::Range(0, static_cast<int>(dirty.size())), [&](const cv::Range& range) {
    Scratch scratch;
    for (int i = range.start; i < range.end; ++i)
      meshBlock(volume, *dirty[i], config_, *targets[i], scratch);
  }, std::max(1.0, static_cast<double>(dirty.size()) / 16));
  generation_ = volume.generation();
  stats_.blocks_meshed = dirty.size();
  stats_.blocks_cached = cache_.size() - dirty.size();
  stats_.mesh_ms = msSince(t0);

  // Assemble in block order (not cache order), so incremental and full meshing agree.
  const auto t1 = Clock::now();
  std::vector<std::pair<GridIndex, const BlockMesh*>> order;
  order.reserve(cache_.size());
  for (const auto& [index, part] : cache_)
    order.emplace_back(index, &part);
  assembleParts(order, mesh);
  stats_.assemble_ms = msSince(t1);
  if (config_.min_component_triangles > 0) {
    // On the assembled mesh only: a piece may span many blocks, and the cache stays whole.
    const auto t2 = Clock::now();
    const ComponentFilterStats removed =
        removeSmallComponents(mesh, static_cast<std::size_t>(config_.min_component_triangles),
                              config_.component_keep_weight,
                              config_.min_component_extent_voxels * static_cast<float>(volume.voxelSize()));
    stats_.components_removed = removed.components_removed;
    stats_.triangles_removed = removed.triangles_removed;
    stats_.filter_ms = msSince(t2);
  }
}

void MarchingCubes::extractBlocks(const TsdfVolume& volume, const std::vector<GridIndex>& blocks,
                                  TriangleMesh& mesh) const {
  std::vector<const TsdfBlock*> present;
  for (const GridIndex& index : blocks)
    if (const TsdfBlock* block = volume.findBlock(index))
      present.push_back(block);
  std::vector<BlockMesh> parts(present.size());
  parallelFor(cv::Range(0, static_cast<int>(present.size())), [&](const cv::Range& range) {
    Scratch scratch;
    for (int i = range.start; i < range.end; ++i)
      meshBlock(volume, *present[i], config_, parts[i], scratch);
  }, std::max(1.0, static_cast<double>(present.size()) / 16));
  std::vector<std::pair<GridIndex, const BlockMesh*>> order;
  order.reserve(present.size());
  for (std::size_t i = 0; i < present.size(); ++i)
    order.emplace_back(present[i]->index, &parts[i]);
  assembleParts(order, mesh);
}

void MarchingCubes::extract(const TsdfVolume& volume, pcl::PolygonMesh& mesh) {
  TriangleMesh triangles;
  extract(volume, triangles);
  const auto t1 = Clock::now();
  triangles.toPolygonMesh(mesh);
  stats_.assemble_ms += msSince(t1);
}

void TriangleMesh::toPolygonMesh(pcl::PolygonMesh& mesh) const {
  const bool coloured = !colors.empty();
  if (coloured && colors.size() != vertices.size())
    throw InvalidInputError("a mesh of " + std::to_string(vertices.size()) + " vertices has " +
                            std::to_string(colors.size()) + " colours: one a vertex, or none");
  pcl::PCLPointCloud2& cloud = mesh.cloud;
  cloud = pcl::PCLPointCloud2();
  const char* names[4] = {"x", "y", "z", "rgb"};
  const int fields = coloured ? 4 : 3;
  for (int i = 0; i < fields; ++i) {
    pcl::PCLPointField f;
    f.name = names[i];
    f.offset = static_cast<std::uint32_t>(4 * i);
    f.datatype = pcl::PCLPointField::FLOAT32;
    f.count = 1;
    cloud.fields.push_back(f);
  }
  const std::size_t step = 4 * static_cast<std::size_t>(fields);
  cloud.point_step = static_cast<std::uint32_t>(step);
  cloud.width = static_cast<std::uint32_t>(vertices.size());
  cloud.height = 1;
  cloud.row_step = cloud.point_step * cloud.width;
  cloud.is_dense = true;
  cloud.data.resize(static_cast<std::size_t>(cloud.row_step));
  parallelFor(cv::Range(0, static_cast<int>(vertices.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i) {
      std::uint8_t* p = cloud.data.data() + step * static_cast<std::size_t>(i);
      std::memcpy(p, vertices[i].data(), 12);
      if (!coloured)
        continue;
      const std::uint32_t rgb = (std::uint32_t(255) << 24) | (std::uint32_t(colors[i][0]) << 16) |
                                (std::uint32_t(colors[i][1]) << 8) | std::uint32_t(colors[i][2]);
      std::memcpy(p + 12, &rgb, 4);
    }
  }, 8);
  mesh.polygons.resize(triangles.size());
  parallelFor(cv::Range(0, static_cast<int>(triangles.size())), [&](const cv::Range& range) {
    for (int i = range.start; i < range.end; ++i)
      mesh.polygons[i].vertices.assign(triangles[i].begin(), triangles[i].end());
  }, 8);
}

} // namespace msf
