// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// MeshRasterizer against analytic depth: exact at pixel centres, first surface, both faces,
// clipped at the near plane, nothing behind the camera, watertight, independent of threads.
#include <msf/common/exceptions.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <cmath>
#include <optional>
#include <random>

using namespace msf;

namespace {

PinholeCamera camera() {
  PinholeCamera c;
  c.width = 120;
  c.height = 90;
  c.fx = 100.f;
  c.fy = 110.f;
  c.cx = 59.3f;
  c.cy = 44.6f;
  return c;
}

/// Ray through the centre of pixel (u, v), z = 1.
Eigen::Vector3d ray(const PinholeCamera& c, int u, int v) {
  return {(u - c.cx) / c.fx, (v - c.cy) / c.fy, 1.0};
}

/// Depth of the ground 1.5 m below the camera seen on row v; -1 above the horizon.
double groundDepth(const PinholeCamera& c, int v) {
  const double dy = (v - c.cy) / c.fy;
  return dy > 0 ? 1.5 / dy : -1.0;
}

std::uint32_t addVertex(TriangleMesh& mesh, const Eigen::Vector3f& p) {
  mesh.vertices.push_back(p);
  return static_cast<std::uint32_t>(mesh.vertices.size() - 1);
}

/// The quadrilateral a, b, c, d as two triangles; `flip` reverses their winding.
void addQuad(TriangleMesh& mesh, const Eigen::Vector3f& a, const Eigen::Vector3f& b, const Eigen::Vector3f& c,
             const Eigen::Vector3f& d, bool flip = false) {
  const std::uint32_t i = addVertex(mesh, a), j = addVertex(mesh, b), k = addVertex(mesh, c), l = addVertex(mesh, d);
  if (flip) {
    mesh.triangles.push_back({i, k, j});
    mesh.triangles.push_back({i, l, k});
  } else {
    mesh.triangles.push_back({i, j, k});
    mesh.triangles.push_back({i, k, l});
  }
}

cv::Mat render(const TriangleMesh& mesh, const Eigen::Isometry3d& T_world_cam = Eigen::Isometry3d::Identity(),
               float near_m = 0.1f, cv::Mat* ids = nullptr) {
  MeshRasterizer rasterizer;
  rasterizer.setNearPlane(near_m);
  cv::Mat depth;
  rasterizer.render(mesh, camera(), T_world_cam, depth, ids);
  return depth;
}

/// First hit of a ray from the origin with the axis-aligned box [lo, hi] (slabs), if any.
std::optional<double> boxHit(const Eigen::Vector3d& d, const Eigen::Vector3d& lo, const Eigen::Vector3d& hi) {
  double t0 = 0, t1 = 1e9;
  for (int k = 0; k < 3; ++k) {
    if (d[k] == 0.0) {
      if (lo[k] > 0 || hi[k] < 0)
        return std::nullopt;
      continue;
    }
    double a = lo[k] / d[k], b = hi[k] / d[k];
    if (a > b)
      std::swap(a, b);
    t0 = std::max(t0, a), t1 = std::min(t1, b);
  }
  if (t0 > t1)
    return std::nullopt;
  return t0 * d.z();
}

/// An axis-aligned box of 12 triangles, windings mixed (marching cubes' is not guaranteed).
TriangleMesh box(const Eigen::Vector3f& lo, const Eigen::Vector3f& hi) {
  TriangleMesh mesh;
  auto corner = [&](int k) {
    return Eigen::Vector3f(k & 1 ? hi.x() : lo.x(), k & 2 ? hi.y() : lo.y(), k & 4 ? hi.z() : lo.z());
  };
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  for (int f = 0; f < 6; ++f)
    addQuad(mesh, corner(faces[f][0]), corner(faces[f][1]), corner(faces[f][2]), corner(faces[f][3]), f % 2 == 1);
  return mesh;
}

} // namespace

TEST(MeshRasterizer, APlaneFacingTheCameraHasItsDepthAtEveryCoveredPixel) {
  TriangleMesh mesh;
  addQuad(mesh, {-2.f, -1.f, 10.f}, {3.f, -1.f, 10.f}, {3.f, 2.f, 10.f}, {-2.f, 2.f, 10.f});
  const cv::Mat depth = render(mesh);
  ASSERT_EQ(depth.type(), CV_32FC1);
  ASSERT_EQ(depth.size(), cv::Size(120, 90));
  const PinholeCamera c = camera();
  int covered = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      // The square's footprint: x in [-2, 3], y in [-1, 2] at z = 10.
      const Eigen::Vector3d p = 10.0 * ray(c, u, v);
      const bool inside = p.x() >= -2 && p.x() <= 3 && p.y() >= -1 && p.y() <= 2;
      if (inside) {
        ++covered;
        ASSERT_NEAR(depth.at<float>(v, u), 10.f, 1e-5f) << u << "," << v;
      } else {
        ASSERT_EQ(depth.at<float>(v, u), 0.f) << u << "," << v;
      }
    }
  EXPECT_EQ(covered, 50 * 33); // 5 m x 3 m at 10 px and 11 px per metre
}

TEST(MeshRasterizer, ASlantedPlaneHasThePerspectiveCorrectDepth) {
  // The ground 1.5 m below the camera from 2 m to 200 m ahead, in two large triangles: depth
  // linear in the image would be far off between their corners; 1/z is what is affine.
  TriangleMesh mesh;
  addQuad(mesh, {-100.f, 1.5f, 2.f}, {100.f, 1.5f, 2.f}, {100.f, 1.5f, 200.f}, {-100.f, 1.5f, 200.f});
  const cv::Mat depth = render(mesh);
  const PinholeCamera c = camera();
  int checked = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const Eigen::Vector3d d = ray(c, u, v);
      const double z = groundDepth(c, v);
      if (z >= 2.0 && z <= 200.0 && std::abs(z * d.x()) <= 100.0) {
        ASSERT_NEAR(depth.at<float>(v, u), z, 1e-5 * z) << u << "," << v;
        ++checked;
      } else if (z < 0 || z > 200.5) {
        ASSERT_EQ(depth.at<float>(v, u), 0.f) << "above the horizon or beyond the far edge: " << u << "," << v;
      }
    }
  EXPECT_GT(checked, 120 * 40);
}

TEST(MeshRasterizer, ABoxShowsItsNearestFaceAtEveryPixel) {
  // Off the axis, so that a side face is seen too; every pixel against the ray's first hit.
  const Eigen::Vector3f lo(0.5f, -1.f, 6.f), hi(2.5f, 1.2f, 8.f);
  const cv::Mat depth = render(box(lo, hi));
  const PinholeCamera c = camera();
  int hits = 0, side = 0;
  for (int v = 0; v < depth.rows; ++v)
    for (int u = 0; u < depth.cols; ++u) {
      const Eigen::Vector3d d = ray(c, u, v);
      const auto z = boxHit(d, lo.cast<double>(), hi.cast<double>());
      // Pixel centres within 1e-4 m of a box edge may go either way.
      const Eigen::Vector3d p = (z ? *z : 7.0) * d;
      int on_bounds = 0;
      for (int k = 0; k < 3; ++k)
        on_bounds += std::abs(p[k] - lo[k]) < 1e-4 || std::abs(p[k] - hi[k]) < 1e-4;
      if (on_bounds >= 2)
        continue;
      if (z) {
        ++hits;
        side += *z > 6.0 + 1e-6;
        ASSERT_NEAR(depth.at<float>(v, u), *z, 1e-5 * *z) << u << "," << v;
      } else {
        ASSERT_EQ(depth.at<float>(v, u), 0.f) << u << "," << v;
      }
    }
  EXPECT_GT(hits, 500);
  EXPECT_GT(side, 20); // the face x = 0.5 is seen obliquely
}

TEST(MeshRasterizer, NothingBehindTheCameraIsDrawn) {
  TriangleMesh mesh = box({-1.f, -1.f, -8.f}, {1.f, 1.f, -6.f});
  addQuad(mesh, {-50.f, -50.f, -0.05f}, {50.f, -50.f, -0.05f}, {50.f, 50.f, -0.05f}, {-50.f, 50.f, -0.05f});
  EXPECT_EQ(cv::countNonZero(render(mesh)), 0);
  // The same box seen from behind it, looking the other way: there.
  Eigen::Isometry3d turned = Eigen::Isometry3d::Identity();
  turned.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const cv::Mat depth = render(mesh, turned);
  EXPECT_NEAR(depth.at<float>(45, 60), 6.f, 1e-5f);
}

TEST(MeshRasterizer, ATriangleCrossingTheNearPlaneIsClippedNotSmeared) {
  // The ground from 50 m behind to 50 m ahead, one triangle per half: unclipped, its corners
  // behind the camera would project above the horizon and smear the ground across the sky.
  TriangleMesh mesh;
  addQuad(mesh, {-30.f, 1.5f, -50.f}, {30.f, 1.5f, -50.f}, {30.f, 1.5f, 50.f}, {-30.f, 1.5f, 50.f});
  for (const float near_m : {0.1f, 5.f}) {
    const cv::Mat depth = render(mesh, Eigen::Isometry3d::Identity(), near_m);
    const PinholeCamera c = camera();
    int ground = 0;
    for (int v = 0; v < depth.rows; ++v)
      for (int u = 0; u < depth.cols; ++u) {
        const Eigen::Vector3d d = ray(c, u, v);
        const double z = groundDepth(c, v);
        const float got = depth.at<float>(v, u);
        if (z < 0 || z > 50.5 || std::abs(z * d.x()) > 30.5) {
          ASSERT_EQ(got, 0.f) << "smeared at " << u << "," << v << " (near " << near_m << ")";
        } else if (z < near_m - 1e-3) {
          ASSERT_EQ(got, 0.f) << "nearer than the near plane at " << u << "," << v;
        } else if (z > near_m + 1e-3 && z < 50.0 && std::abs(z * d.x()) < 30.0) {
          ASSERT_NEAR(got, z, 1e-5 * z) << u << "," << v << " (near " << near_m << ")";
          ++ground;
        }
      }
    EXPECT_GT(ground, 120 * 20) << near_m;
  }
  // A plane facing the camera at 2 m, nearer than a 3 m near plane, is cut away.
  TriangleMesh wall;
  addQuad(wall, {-5.f, -5.f, 2.f}, {5.f, -5.f, 2.f}, {5.f, 5.f, 2.f}, {-5.f, 5.f, 2.f});
  EXPECT_EQ(cv::countNonZero(render(wall, Eigen::Isometry3d::Identity(), 3.f)), 0);
  EXPECT_EQ(cv::countNonZero(render(wall, Eigen::Isometry3d::Identity(), 1.f)), 120 * 90);
}

TEST(MeshRasterizer, TheNearerOfTwoOverlappingTrianglesWinsInEitherOrder) {
  for (const bool near_first : {true, false}) {
    TriangleMesh mesh;
    const auto add = [&](float z) { addQuad(mesh, {-1.f, -1.f, z}, {1.f, -1.f, z}, {1.f, 1.f, z}, {-1.f, 1.f, z}); };
    add(near_first ? 5.f : 9.f);
    add(near_first ? 9.f : 5.f);
    cv::Mat ids;
    const cv::Mat depth = render(mesh, Eigen::Isometry3d::Identity(), 0.1f, &ids);
    ASSERT_EQ(ids.type(), CV_32SC1);
    EXPECT_NEAR(depth.at<float>(45, 60), 5.f, 1e-5f) << near_first;
    const int nearer = ids.at<std::int32_t>(45, 60);
    EXPECT_EQ(nearer / 2, near_first ? 0 : 1) << "triangle " << nearer;
    // Beyond the far square's footprint (11 px at 9 m) but inside the near one's (20 px).
    EXPECT_NEAR(depth.at<float>(45, 60 + 15), 5.f, 1e-5f);
    EXPECT_EQ(ids.at<std::int32_t>(5, 5), -1);
    EXPECT_EQ(depth.at<float>(5, 5), 0.f);
  }
}

TEST(MeshRasterizer, AGridOfSmallTrianglesLeavesNoPixelBetweenThem) {
  // 0.1 m triangles at 10 m facing the camera, 1 px each, their edges through pixel centres
  // (cx, cy integers): a centre on an edge shared by two triangles is drawn by at least one.
  PinholeCamera c;
  c.width = 80, c.height = 60, c.fx = c.fy = 100.f, c.cx = 40.f, c.cy = 30.f;
  TriangleMesh mesh;
  const int n = 100; // 10 m a side
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i)
      mesh.vertices.emplace_back(-5.f + 0.1f * i, -5.f + 0.1f * j, 10.f);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const auto a = static_cast<std::uint32_t>(j * (n + 1) + i), b = a + 1, d = a + n + 1, e = d + 1;
      mesh.triangles.push_back({a, b, e});
      mesh.triangles.push_back({a, e, d});
    }
  MeshRasterizer rasterizer;
  cv::Mat depth;
  rasterizer.render(mesh, c, Eigen::Isometry3d::Identity(), depth);
  EXPECT_EQ(cv::countNonZero(depth), c.width * c.height);
  double lo, hi;
  cv::minMaxLoc(depth, &lo, &hi);
  EXPECT_NEAR(lo, 10.0, 1e-5);
  EXPECT_NEAR(hi, 10.0, 1e-5);
}

TEST(MeshRasterizer, AgreesWithRayCastingOnRandomTrianglesWhateverTheThreads) {
  // 400 random triangles around the camera, many crossing the near plane or behind it,
  // against a brute-force ray cast of every pixel (Moller-Trumbore, nearest hit).
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> xy(-6.f, 6.f), z(-3.f, 15.f), edge(-2.f, 2.f);
  TriangleMesh mesh;
  for (int t = 0; t < 400; ++t) {
    const Eigen::Vector3f a(xy(rng), xy(rng), z(rng));
    const std::uint32_t i = addVertex(mesh, a), j = addVertex(mesh, a + Eigen::Vector3f(edge(rng), edge(rng), edge(rng))),
                        k = addVertex(mesh, a + Eigen::Vector3f(edge(rng), edge(rng), edge(rng)));
    mesh.triangles.push_back({i, j, k});
  }
  const float near_m = 0.5f;
  const PinholeCamera c = camera();
  const cv::Mat depth = render(mesh, Eigen::Isometry3d::Identity(), near_m);
  int compared = 0, differ = 0;
  for (int v = 0; v < c.height; ++v)
    for (int u = 0; u < c.width; ++u) {
      const Eigen::Vector3d d = ray(c, u, v);
      double best = 0;
      for (const auto& t : mesh.triangles) {
        const Eigen::Vector3d a = mesh.vertices[t[0]].cast<double>(), e1 = mesh.vertices[t[1]].cast<double>() - a,
                              e2 = mesh.vertices[t[2]].cast<double>() - a;
        const Eigen::Vector3d p = d.cross(e2);
        const double det = e1.dot(p);
        if (std::abs(det) < 1e-12)
          continue;
        const Eigen::Vector3d s = -a;
        const double b1 = s.dot(p) / det;
        const Eigen::Vector3d q = s.cross(e1);
        const double b2 = d.dot(q) / det;
        const double hit = e2.dot(q) / det; // = z, since d.z() = 1
        if (b1 >= 0 && b2 >= 0 && b1 + b2 <= 1 && hit >= near_m && (best == 0 || hit < best))
          best = hit;
      }
      ++compared;
      const float got = depth.at<float>(v, u);
      differ += best == 0 ? got != 0.f : std::abs(got - best) > 1e-4 * best;
    }
  // Pixel centres within rounding of a triangle's edge may go either way.
  EXPECT_LE(differ, compared / 1000) << differ << " of " << compared << " pixels differ";

  const int threads = cv::getNumThreads();
  cv::setNumThreads(1);
  const cv::Mat one_thread = render(mesh, Eigen::Isometry3d::Identity(), near_m);
  cv::setNumThreads(threads);
  EXPECT_EQ(cv::norm(one_thread, depth, cv::NORM_INF), 0.0);
}

TEST(MeshRasterizer, ALongMeshRenderedRunByRunIsTheWholeMeshRendered) {
  // A 600 m drive's worth of small triangles, in clusters along it (as marching cubes emits a
  // block's together), seen from poses along it, turned, and from inside a cluster (its
  // triangles cross the near plane): with the runs' bounds, what is outside the view is
  // skipped, and every depth and triangle id is the whole mesh's.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> across(-12.f, 12.f), height(-3.f, 3.f), edge(-1.f, 1.f);
  TriangleMesh mesh;
  for (int cluster = 0; cluster < 40; ++cluster)
    for (int t = 0; t < 1100; ++t) {
      const Eigen::Vector3f a(across(rng), height(rng), -50.f + 15.f * static_cast<float>(cluster) + 3.f * edge(rng));
      const std::uint32_t i = addVertex(mesh, a),
                          j = addVertex(mesh, a + Eigen::Vector3f(edge(rng), edge(rng), edge(rng))),
                          k = addVertex(mesh, a + Eigen::Vector3f(edge(rng), edge(rng), edge(rng)));
      mesh.triangles.push_back({i, j, k});
    }
  const MeshRasterizer::RunBounds bounds = MeshRasterizer::triangleRunBounds(mesh);
  MeshRasterizer whole, by_runs;
  int drawn = 0;
  for (const double z : {-60.0, 0.0, 101.0, 300.0, 590.0})
    for (const double yaw : {0.0, 0.7, 3.1}) {
      const Eigen::Isometry3d pose =
          Eigen::Translation3d(1.0, 0.5, z) * Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitY());
      cv::Mat depth, ids, culled_depth, culled_ids;
      whole.render(mesh, camera(), pose, depth, &ids);
      by_runs.render(mesh, camera(), pose, culled_depth, &culled_ids, &bounds);
      EXPECT_EQ(cv::norm(depth, culled_depth, cv::NORM_INF), 0.0) << "z " << z << ", yaw " << yaw;
      EXPECT_EQ(cv::countNonZero(ids != culled_ids), 0) << "z " << z << ", yaw " << yaw;
      drawn += cv::countNonZero(depth);
    }
  EXPECT_GT(drawn, 10000);
  // Bounds of another mesh are refused by name.
  TriangleMesh shorter = mesh;
  shorter.triangles.resize(1000);
  cv::Mat depth;
  EXPECT_THROW(by_runs.render(shorter, camera(), Eigen::Isometry3d::Identity(), depth, nullptr, &bounds),
               InvalidInputError);
}

TEST(MeshRasterizer, BadInputIsAClearError) {
  MeshRasterizer rasterizer;
  EXPECT_THROW(rasterizer.setNearPlane(0.f), InvalidInputError);
  EXPECT_THROW(rasterizer.setNearPlane(std::nanf("")), InvalidInputError);
  TriangleMesh mesh;
  mesh.vertices = {{0.f, 0.f, 5.f}, {1.f, 0.f, 5.f}};
  mesh.triangles = {{0, 1, 2}};
  cv::Mat depth;
  try {
    rasterizer.render(mesh, camera(), Eigen::Isometry3d::Identity(), depth);
    ADD_FAILURE() << "a vertex index out of range was accepted";
  } catch (const InvalidInputError& e) {
    EXPECT_NE(std::string(e.what()).find("out of range"), std::string::npos) << e.what();
  }
  EXPECT_THROW(MeshRasterizer::triangleRunBounds(mesh), InvalidInputError);
  EXPECT_THROW(rasterizer.render(TriangleMesh(), PinholeCamera(), Eigen::Isometry3d::Identity(), depth),
               InvalidInputError);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_THROW(rasterizer.render(TriangleMesh(), camera(), bad, depth), InvalidInputError);
  // An empty mesh renders an empty image.
  rasterizer.render(TriangleMesh(), camera(), Eigen::Isometry3d::Identity(), depth);
  EXPECT_EQ(depth.size(), cv::Size(120, 90));
  EXPECT_EQ(cv::countNonZero(depth), 0);
}
