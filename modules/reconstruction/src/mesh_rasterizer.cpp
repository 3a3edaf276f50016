// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>

namespace msf {

namespace {

constexpr int kBandRows = 8;                     // small triangles mostly fall in one band
constexpr std::uint32_t kCulled = ~0u;           // rows_ of a triangle that covers no pixel centre
constexpr std::size_t kChunkTriangles = 1 << 15; // triangles per binning chunk
constexpr std::size_t kChunkVertices = 1 << 15;
constexpr std::size_t kRunTriangles = 1 << 10;    // triangles per bounded run; a binning chunk holds whole runs
static_assert(kChunkTriangles % kRunTriangles == 0);

/// Whether a box (world frame) lies wholly outside the view: behind the near plane, or beyond
/// one side of the image by more than a pixel (a triangle there covers no pixel centre).
bool outsideView(const Eigen::AlignedBox3f& box, const PinholeCamera& camera, const Eigen::Isometry3f& T_cam_world,
                 float near_m) {
  // Each side as a half-space through the camera centre: a.x * x + a.y * y + a.z * z >= 0 inside.
  const Eigen::Vector3f sides[5] = {{0.f, 0.f, 1.f}, // the near plane, tested against near_m
                                    {camera.fx, 0.f, camera.cx + 1.f},
                                    {-camera.fx, 0.f, static_cast<float>(camera.width) - camera.cx},
                                    {0.f, camera.fy, camera.cy + 1.f},
                                    {0.f, -camera.fy, static_cast<float>(camera.height) - camera.cy}};
  Eigen::Vector3f corners[8];
  for (int k = 0; k < 8; ++k)
    corners[k] = T_cam_world * box.corner(static_cast<Eigen::AlignedBox3f::CornerType>(k));
  for (int s = 0; s < 5; ++s) {
    const float least = s == 0 ? near_m : 0.f;
    bool all_out = true;
    for (int k = 0; k < 8 && all_out; ++k)
      all_out = sides[s].dot(corners[k]) < least;
    if (all_out)
      return true;
  }
  return false;
}

/// Pixel of a camera-frame point in front of the camera. Every corner of every triangle is
/// projected by this one expression, so triangles sharing a corner share its pixel exactly.
inline Eigen::Vector2f project(const Eigen::Vector3f& p, const PinholeCamera& cam) {
  return {cam.fx * (p.x() / p.z()) + cam.cx, cam.fy * (p.y() / p.z()) + cam.cy};
}

/// The part of a triangle in front of the near plane, projected: 3 corners, or 4 when one
/// corner was behind it, each with its inverse depth.
struct Polygon {
  int n = 0;
  double u[4], v[4], iz[4];

  void add(const Eigen::Vector2f& pixel, float z) {
    u[n] = pixel.x();
    v[n] = pixel.y();
    iz[n] = 1.0 / z;
    ++n;
  }
};

/// Sutherland-Hodgman against z >= near. A crossing point is computed from the edge's corner
/// of smaller index, so two triangles sharing a crossing edge get the same point.
void clipTriangle(const std::array<std::uint32_t, 3>& tri, const std::vector<Eigen::Vector3f>& cam,
                  const std::vector<Eigen::Vector2f>& pixel, float near, const PinholeCamera& camera, Polygon& out) {
  out.n = 0;
  for (int k = 0; k < 3; ++k) {
    const std::uint32_t p = tri[k], q = tri[(k + 1) % 3];
    const bool p_in = cam[p].z() >= near, q_in = cam[q].z() >= near;
    if (p_in)
      out.add(pixel[p], cam[p].z());
    if (p_in != q_in) {
      const std::uint32_t a = std::min(p, q), b = std::max(p, q);
      const float t = (near - cam[a].z()) / (cam[b].z() - cam[a].z());
      Eigen::Vector3f x = cam[a] + t * (cam[b] - cam[a]);
      x.z() = near;
      out.add(project(x, camera), near);
    }
  }
}

/// The corners of triangle t that the camera may see: all three when in front of the near
/// plane, the clipped polygon when it crosses it; n = 0 when it is wholly behind.
void visiblePolygon(const std::array<std::uint32_t, 3>& tri, const std::vector<Eigen::Vector3f>& cam,
                    const std::vector<Eigen::Vector2f>& pixel, float near, const PinholeCamera& camera,
                    Polygon& out) {
  const int in_front = (cam[tri[0]].z() >= near) + (cam[tri[1]].z() >= near) + (cam[tri[2]].z() >= near);
  out.n = 0;
  if (in_front == 3) {
    for (const std::uint32_t i : tri)
      out.add(pixel[i], cam[i].z());
  } else if (in_front > 0) {
    clipTriangle(tri, cam, pixel, near, camera, out);
  }
}

/// Pixel centres in [lo, hi] along one axis of `size` pixels: first and last, first > last when none.
inline void centresWithin(double lo, double hi, int size, int& first, int& last) {
  if (!(lo <= hi)) { // NaN from a vertex that is not finite
    first = 0, last = -1;
    return;
  }
  first = std::max(0, static_cast<int>(std::ceil(std::clamp(lo, -1.0, static_cast<double>(size)))));
  last = std::min(size - 1, static_cast<int>(std::floor(std::clamp(hi, -1.0, static_cast<double>(size)))));
}

/// An edge's test: the signed area of (a, b, pixel), evaluated from the edge's
/// lexicographically smaller end so that the two triangles sharing it compute the same
/// number, with opposite signs: a pixel centre on the edge gives 0 in both and is drawn.
struct EdgeTest {
  double ax, ay, dx, dy, sign;
  EdgeTest(double pu, double pv, double qu, double qv) {
    const bool swap = qu < pu || (qu == pu && qv < pv);
    ax = swap ? qu : pu;
    ay = swap ? qv : pv;
    dx = (swap ? pu : qu) - ax;
    dy = (swap ? pv : qv) - ay;
    sign = swap ? -1.0 : 1.0;
  }
  double at(double x, double y) const { return sign * (dx * (y - ay) - dy * (x - ax)); }
  /// Narrows [lo, hi] to the x where the test may pass on row y (to within rounding: the
  /// pixels are then tested exactly).
  void narrow(double y, double& lo, double& hi) const {
    const double slope = -sign * dy, offset = sign * (dx * (y - ay) + dy * ax);
    if (slope > 0.0)
      lo = std::max(lo, -offset / slope);
    else if (slope < 0.0)
      hi = std::min(hi, -offset / slope);
    else if (offset < 0.0)
      hi = -1.0, lo = 1.0;
  }
};

/// Draws triangle (i, j, k) of polygon `p` into rows [row0, row1] of the z-buffer `depth`.
void drawTriangle(const Polygon& p, int i, int j, int k, std::int32_t id, int row0, int row1, cv::Mat& depth,
                  cv::Mat* ids) {
  int x0, x1, y0, y1;
  centresWithin(std::min({p.v[i], p.v[j], p.v[k]}), std::max({p.v[i], p.v[j], p.v[k]}), depth.rows, y0, y1);
  y0 = std::max(y0, row0);
  y1 = std::min(y1, row1);
  if (y0 > y1)
    return;
  centresWithin(std::min({p.u[i], p.u[j], p.u[k]}), std::max({p.u[i], p.u[j], p.u[k]}), depth.cols, x0, x1);
  if (x0 > x1)
    return;
  const double area = (p.u[j] - p.u[i]) * (p.v[k] - p.v[i]) - (p.v[j] - p.v[i]) * (p.u[k] - p.u[i]);
  if (!(std::abs(area) > 0.0) || !std::isfinite(area))
    return; // seen edge-on: it covers no area
  // Edge opposite each corner; both faces: the orientation makes the inside positive.
  EdgeTest e0(p.u[j], p.v[j], p.u[k], p.v[k]), e1(p.u[k], p.v[k], p.u[i], p.v[i]), e2(p.u[i], p.v[i], p.u[j], p.v[j]);
  const double orientation = area > 0 ? 1.0 : -1.0;
  e0.sign *= orientation, e1.sign *= orientation, e2.sign *= orientation;
  for (int y = y0; y <= y1; ++y) {
    // The row's span inside the three edges, a pixel wider each side for rounding; a thin
    // triangle's bounding box is mostly outside it.
    int first = x0, last = x1;
    if (last - first > 2) {
      double lo = x0, hi = x1;
      e0.narrow(y, lo, hi), e1.narrow(y, lo, hi), e2.narrow(y, lo, hi);
      if (!(lo <= hi + 2.0))
        continue;
      first = std::max(x0, static_cast<int>(std::ceil(lo)) - 1);
      last = std::min(x1, static_cast<int>(std::floor(hi)) + 1);
    }
    float* zrow = depth.ptr<float>(y);
    std::int32_t* idrow = ids ? ids->ptr<std::int32_t>(y) : nullptr;
    for (int x = first; x <= last; ++x) {
      const double w0 = e0.at(x, y);
      if (w0 < 0.0)
        continue;
      const double w1 = e1.at(x, y);
      if (w1 < 0.0)
        continue;
      const double w2 = e2.at(x, y);
      const double sum = w0 + w1 + w2;
      if (w2 < 0.0 || !(sum > 0.0))
        continue;
      // 1/z is affine in the image along a plane: the barycentric mean of the corners'.
      const float z = static_cast<float>(sum / (w0 * p.iz[i] + w1 * p.iz[j] + w2 * p.iz[k]));
      if (z < zrow[x]) {
        zrow[x] = z;
        if (idrow)
          idrow[x] = id;
      }
    }
  }
}

} // namespace

void MeshRasterizer::setNearPlane(float near_m) {
  if (!(near_m > 0.f) || !std::isfinite(near_m))
    throw InvalidInputError("mesh rasterizer: the near plane must be > 0 m, not " + std::to_string(near_m));
  near_m_ = near_m;
}

MeshRasterizer::RunBounds MeshRasterizer::triangleRunBounds(const TriangleMesh& mesh) {
  const std::size_t n = mesh.triangles.size(), vertices = mesh.vertices.size();
  RunBounds bounds((n + kRunTriangles - 1) / kRunTriangles);
  std::atomic<bool> bad_index{false};
  parallelFor(cv::Range(0, static_cast<int>(bounds.size())), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r) {
      TriangleRun& run = bounds[static_cast<std::size_t>(r)];
      const std::size_t end = std::min(n, (static_cast<std::size_t>(r) + 1) * kRunTriangles);
      for (std::size_t t = static_cast<std::size_t>(r) * kRunTriangles; t < end; ++t)
        for (const std::uint32_t v : mesh.triangles[t]) {
          if (v >= vertices) {
            bad_index = true;
            continue;
          }
          run.box.extend(mesh.vertices[v]);
          run.first_vertex = std::min(run.first_vertex, v);
          run.last_vertex = std::max(run.last_vertex, v);
        }
    }
  });
  if (bad_index)
    throw InvalidInputError("mesh rasterizer: a triangle has a vertex index out of range (the mesh has " +
                            std::to_string(vertices) + " vertices)");
  return bounds;
}

void MeshRasterizer::cullRuns(const TriangleMesh& mesh, const RunBounds* bounds, const PinholeCamera& camera,
                              const Eigen::Isometry3f& T_cam_world) {
  const std::size_t runs = (mesh.triangles.size() + kRunTriangles - 1) / kRunTriangles;
  visible_.assign(runs, 1);
  vertex_ranges_.assign(1, {0, mesh.vertices.size()});
  if (!bounds)
    return;
  if (bounds->size() != runs)
    throw InvalidInputError("mesh rasterizer: bounds of " + std::to_string(bounds->size()) + " runs for a mesh of " +
                            std::to_string(runs) + " (triangleRunBounds of another mesh?)");
  parallelFor(cv::Range(0, static_cast<int>(runs)), [&](const cv::Range& range) {
    for (int r = range.start; r < range.end; ++r)
      visible_[static_cast<std::size_t>(r)] =
          !outsideView((*bounds)[static_cast<std::size_t>(r)].box, camera, T_cam_world, near_m_);
  });
  // The visible runs' vertices, as few ranges as they make: marching cubes emits a block's
  // vertices with its triangles, so a run uses a short range.
  vertex_ranges_.clear();
  for (std::size_t r = 0; r < runs; ++r)
    if (visible_[r])
      vertex_ranges_.push_back({(*bounds)[r].first_vertex, std::size_t{(*bounds)[r].last_vertex} + 1});
  std::sort(vertex_ranges_.begin(), vertex_ranges_.end());
  std::size_t merged = 0;
  for (const auto& range : vertex_ranges_) {
    if (merged > 0 && range.first <= vertex_ranges_[merged - 1].second)
      vertex_ranges_[merged - 1].second = std::max(vertex_ranges_[merged - 1].second, range.second);
    else
      vertex_ranges_[merged++] = range;
  }
  vertex_ranges_.resize(merged);
}

void MeshRasterizer::transformVertices(const TriangleMesh& mesh, const PinholeCamera& camera,
                                       const Eigen::Isometry3f& T_cam_world) {
  cam_.resize(mesh.vertices.size());
  pixel_.resize(mesh.vertices.size());
  std::vector<std::pair<std::size_t, std::size_t>> tasks; // the ranges in pieces of kChunkVertices
  for (const auto& [first, end] : vertex_ranges_)
    for (std::size_t i = first; i < end; i += kChunkVertices)
      tasks.push_back({i, std::min(end, i + kChunkVertices)});
  parallelFor(cv::Range(0, static_cast<int>(tasks.size())), [&](const cv::Range& range) {
    for (int k = range.start; k < range.end; ++k)
      for (std::size_t i = tasks[static_cast<std::size_t>(k)].first; i < tasks[static_cast<std::size_t>(k)].second;
           ++i) {
        cam_[i] = T_cam_world * mesh.vertices[i];
        pixel_[i] = cam_[i].z() >= near_m_ ? project(cam_[i], camera) : Eigen::Vector2f::Zero();
      }
  });
}

bool MeshRasterizer::binTriangles(const TriangleMesh& mesh, const PinholeCamera& camera) {
  const std::size_t n = mesh.triangles.size(), vertices = mesh.vertices.size();
  const std::size_t chunks = std::max<std::size_t>(1, (n + kChunkTriangles - 1) / kChunkTriangles);
  const auto bands = static_cast<std::size_t>(bands_);
  rows_.resize(n);
  offsets_.assign(chunks * bands, 0);
  std::atomic<bool> bad_index{false};
  // 1. The rows each triangle may cover; per chunk, how many triangles each band gets.
  parallelFor(cv::Range(0, static_cast<int>(chunks)), [&](const cv::Range& range) {
    Polygon polygon;
    for (int c = range.start; c < range.end; ++c) {
      std::uint32_t* count = &offsets_[static_cast<std::size_t>(c) * bands];
      const std::size_t end = std::min(n, (static_cast<std::size_t>(c) + 1) * kChunkTriangles);
      for (std::size_t t = static_cast<std::size_t>(c) * kChunkTriangles; t < end; ++t) {
        if (!visible_[t / kRunTriangles]) {
          t = (t / kRunTriangles + 1) * kRunTriangles - 1; // on to the next run
          continue;
        }
        const auto& tri = mesh.triangles[t];
        rows_[t] = kCulled;
        if (tri[0] >= vertices || tri[1] >= vertices || tri[2] >= vertices) {
          bad_index = true;
          continue;
        }
        int x0, x1, y0, y1;
        if (cam_[tri[0]].z() >= near_m_ && cam_[tri[1]].z() >= near_m_ && cam_[tri[2]].z() >= near_m_) {
          const Eigen::Vector2f &p = pixel_[tri[0]], &q = pixel_[tri[1]], &r = pixel_[tri[2]];
          centresWithin(std::min({p.y(), q.y(), r.y()}), std::max({p.y(), q.y(), r.y()}), camera.height, y0, y1);
          if (y0 > y1)
            continue;
          centresWithin(std::min({p.x(), q.x(), r.x()}), std::max({p.x(), q.x(), r.x()}), camera.width, x0, x1);
        } else {
          visiblePolygon(tri, cam_, pixel_, near_m_, camera, polygon);
          if (polygon.n == 0)
            continue;
          const double* u = polygon.u;
          const double* v = polygon.v;
          centresWithin(*std::min_element(u, u + polygon.n), *std::max_element(u, u + polygon.n), camera.width, x0, x1);
          centresWithin(*std::min_element(v, v + polygon.n), *std::max_element(v, v + polygon.n), camera.height, y0,
                        y1);
        }
        if (x0 > x1 || y0 > y1)
          continue;
        rows_[t] = static_cast<std::uint32_t>(y0) << 16 | static_cast<std::uint32_t>(y1);
        for (int b = y0 / kBandRows; b <= y1 / kBandRows; ++b)
          ++count[b];
      }
    }
  });
  if (bad_index)
    return false;
  // 2. Where each chunk's triangles of each band go: band after band, chunks in order, so a
  //    band lists its triangles in mesh order whatever the threads.
  bin_start_.resize(bands + 1);
  std::uint32_t total = 0;
  for (std::size_t b = 0; b < bands; ++b) {
    bin_start_[b] = total;
    for (std::size_t c = 0; c < chunks; ++c) {
      const std::uint32_t count = offsets_[c * bands + b];
      offsets_[c * bands + b] = total;
      total += count;
    }
  }
  bin_start_[bands] = total;
  binned_.resize(total);
  // 3. The lists.
  parallelFor(cv::Range(0, static_cast<int>(chunks)), [&](const cv::Range& range) {
    for (int c = range.start; c < range.end; ++c) {
      std::uint32_t* next = &offsets_[static_cast<std::size_t>(c) * bands];
      const std::size_t end = std::min(n, (static_cast<std::size_t>(c) + 1) * kChunkTriangles);
      for (std::size_t t = static_cast<std::size_t>(c) * kChunkTriangles; t < end; ++t) {
        if (!visible_[t / kRunTriangles]) {
          t = (t / kRunTriangles + 1) * kRunTriangles - 1;
          continue;
        }
        if (rows_[t] == kCulled)
          continue;
        const int y0 = static_cast<int>(rows_[t] >> 16), y1 = static_cast<int>(rows_[t] & 0xffffu);
        for (int b = y0 / kBandRows; b <= y1 / kBandRows; ++b)
          binned_[next[b]++] = static_cast<std::uint32_t>(t);
      }
    }
  });
  return true;
}

void MeshRasterizer::drawBand(int band, const TriangleMesh& mesh, const PinholeCamera& camera, cv::Mat& depth,
                              cv::Mat* triangle_ids) const {
  const int row0 = band * kBandRows, row1 = std::min(camera.height, row0 + kBandRows) - 1;
  for (int y = row0; y <= row1; ++y) {
    std::fill_n(depth.ptr<float>(y), depth.cols, std::numeric_limits<float>::infinity());
    if (triangle_ids)
      std::fill_n(triangle_ids->ptr<std::int32_t>(y), depth.cols, -1);
  }
  Polygon polygon;
  for (std::uint32_t k = bin_start_[band]; k < bin_start_[band + 1]; ++k) {
    const std::uint32_t t = binned_[k];
    visiblePolygon(mesh.triangles[t], cam_, pixel_, near_m_, camera, polygon);
    for (int f = 1; f + 1 < polygon.n; ++f) // a fan: the clipped quadrilateral is two triangles
      drawTriangle(polygon, 0, f, f + 1, static_cast<std::int32_t>(t), row0, row1, depth, triangle_ids);
  }
  for (int y = row0; y <= row1; ++y) {
    float* z = depth.ptr<float>(y);
    for (int x = 0; x < depth.cols; ++x)
      if (std::isinf(z[x]))
        z[x] = 0.f;
  }
}

void MeshRasterizer::render(const TriangleMesh& mesh, const PinholeCamera& camera,
                            const Eigen::Isometry3d& T_world_cam, cv::Mat& depth, cv::Mat* triangle_ids,
                            const RunBounds* bounds) {
  if (!camera.valid() || camera.height > 0xffff)
    throw InvalidInputError("mesh rasterizer: invalid camera (fx " + std::to_string(camera.fx) + ", fy " +
                            std::to_string(camera.fy) + ", " + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " px)");
  if (!T_world_cam.matrix().allFinite())
    throw InvalidInputError("mesh rasterizer: T_world_cam has a value that is not finite");
  if (mesh.triangles.size() > static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max()))
    throw InvalidInputError("mesh rasterizer: more than 2^31 triangles");
  depth.create(camera.height, camera.width, CV_32FC1);
  if (triangle_ids)
    triangle_ids->create(camera.height, camera.width, CV_32SC1);

  // The runs of triangles in the view; their vertices into the camera frame, and onto the
  // image when in front of the near plane.
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  const std::size_t vertices = mesh.vertices.size();
  cullRuns(mesh, bounds, camera, T_cam_world);
  transformVertices(mesh, camera, T_cam_world);

  bands_ = (camera.height + kBandRows - 1) / kBandRows;
  if (!binTriangles(mesh, camera))
    throw InvalidInputError("mesh rasterizer: a triangle has a vertex index out of range (the mesh has " +
                            std::to_string(vertices) + " vertices)");
  parallelFor(
      cv::Range(0, bands_),
      [&](const cv::Range& range) {
        for (int band = range.start; band < range.end; ++band)
          drawBand(band, mesh, camera, depth, triangle_ids);
      },
      bands_);
}

} // namespace msf
