// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/pinhole_camera.h>
#include <msf/reconstruction/marching_cubes.h>

#include <Eigen/Geometry>
#include <opencv2/core/mat.hpp>

#include <cstdint>
#include <memory>
#include <utility>
#include <vector>

namespace msf {

/// A TriangleMesh seen through a pinhole camera: per pixel, the depth z of the first surface
/// along the ray through the pixel's centre (pixel (u, v) is centred on the integer
/// coordinates, as PinholeCamera and LidarProjector have it), with the triangle it lies on.
/// What evaluation protocol 4 compares with ground-truth depth, and what the colour preview
/// (MeshRenderer) shades.
///
/// Exact at pixel centres: a centre is covered when it is inside or on the triangle's
/// projection (two triangles sharing an edge get the same edge test with opposite signs, so
/// no centre falls between them), and its depth is the perspective-correct one (1/z is
/// affine in the image along a plane). Both faces are drawn: marching cubes' winding is not
/// guaranteed to face the camera. Triangles crossing the near plane are clipped to it, so a
/// surface that passes beside the camera is neither dropped nor smeared across the image.
///
/// Parallel over bands of image rows: the triangles are first sorted into the bands their
/// projection may cover (two counting passes over fixed chunks of triangles, so the order
/// within a band, and the result, do not depend on the threads), then each band is drawn
/// by one thread into its own rows. The buffers are kept between calls: rendering one mesh
/// at many poses allocates nothing per frame or per triangle.
class MeshRasterizer {
public:
  using Ptr = std::shared_ptr<MeshRasterizer>;
  using ConstPtr = std::shared_ptr<const MeshRasterizer>;

  /// Surfaces nearer the camera than `near_m` (metres, > 0) are cut away. Throws
  /// InvalidInputError for a value that is not > 0 and finite.
  void setNearPlane(float near_m);
  float getNearPlane() const { return near_m_; }

  /// The bounding box of each run of consecutive triangles of `mesh` (marching cubes emits a
  /// block's triangles together, so a run is a small piece of the map). Given to render(),
  /// the runs outside the view are skipped whole: rendering a long drive's mesh at each of its
  /// poses then costs what each view holds, not the whole mesh, with the same result. Throws
  /// InvalidInputError for a triangle whose vertex index is out of range.
  struct TriangleRun {
    Eigen::AlignedBox3f box;                     ///< of its triangles' corners
    std::uint32_t first_vertex = ~0u, last_vertex = 0; ///< the least and the greatest index they use
  };
  using RunBounds = std::vector<TriangleRun>;
  static RunBounds triangleRunBounds(const TriangleMesh& mesh);

  /// Renders `mesh` (world frame) through `camera` at `T_world_cam`. depth: CV_32FC1 of the
  /// camera's size, z in metres, 0 where no triangle covers the pixel centre. triangle_ids,
  /// when given: CV_32SC1, the index into mesh.triangles of the surface seen, -1 where none.
  /// bounds, when given: triangleRunBounds(mesh). Throws InvalidInputError for an invalid
  /// camera (or one taller than 65535 rows), a pose that is not finite, a triangle whose vertex
  /// index is out of range, or bounds of another mesh's size.
  void render(const TriangleMesh& mesh, const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
              cv::Mat& depth, cv::Mat* triangle_ids = nullptr, const RunBounds* bounds = nullptr);

private:
  /// Which runs of triangles (triangleRunBounds) may cover a pixel centre (visible_), and the
  /// vertices they use (vertex_ranges_); all of them without bounds.
  void cullRuns(const TriangleMesh& mesh, const RunBounds* bounds, const PinholeCamera& camera,
                const Eigen::Isometry3f& T_cam_world);
  /// The vertices of vertex_ranges_ into the camera frame (cam_) and onto the image (pixel_).
  void transformVertices(const TriangleMesh& mesh, const PinholeCamera& camera, const Eigen::Isometry3f& T_cam_world);
  /// Sorts the triangles of the visible runs into bands_ (bin_start_, binned_); returns false on a bad index.
  bool binTriangles(const TriangleMesh& mesh, const PinholeCamera& camera);
  /// Draws the triangles of band `band` into its rows.
  void drawBand(int band, const TriangleMesh& mesh, const PinholeCamera& camera, cv::Mat& depth,
                cv::Mat* triangle_ids) const;

  float near_m_ = 0.1f;
  int bands_ = 0;
  std::vector<Eigen::Vector3f> cam_;        ///< vertices in the camera frame
  std::vector<Eigen::Vector2f> pixel_;      ///< their projections (those in front of the near plane)
  std::vector<std::uint32_t> rows_;         ///< per triangle: first row << 16 | last row it may cover
  std::vector<std::uint32_t> offsets_;      ///< per chunk and band: where its triangles go in binned_
  std::vector<std::uint32_t> bin_start_;    ///< per band (and one past): its triangles in binned_
  std::vector<std::uint32_t> binned_;       ///< triangle indices, band after band
  std::vector<std::uint8_t> visible_;       ///< per run of triangles: whether it may be in the view
  std::vector<std::pair<std::size_t, std::size_t>> vertex_ranges_; ///< [first, end) of the vertices the view's runs use
};

} // namespace msf
