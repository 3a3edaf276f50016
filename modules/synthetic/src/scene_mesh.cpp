// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/synthetic/scene_mesh.h>

#include <pcl/conversions.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

namespace msf::synthetic {

namespace {

constexpr float kPi = 3.14159265f;
constexpr float kHiddenProbe = 0.01f; // metres outside a face where we test for another solid

class MeshBuilder {
public:
  MeshBuilder(const Scene& scene, float max_edge) : scene_(scene), max_edge_(max_edge) {}

  /// The primitive being tessellated (-1: the road plane).
  void setCurrent(std::int32_t index) { current_ = index; }

  void setMaterial(const Material& m) {
    class_ = static_cast<std::uint8_t>(surfaceClass(m.type));
    auto to8 = [](float linear) {
      return static_cast<std::uint8_t>(std::lround(255.f * std::pow(std::clamp(linear, 0.f, 1.f), 1.f / 2.2f)));
    };
    color_ = {to8(m.r), to8(m.g), to8(m.b)};
  }

  /// A planar grid from `origin` spanning edges A and B; its outward normal is A x B.
  void grid(V3 origin, V3 A, V3 B) {
    const int nu = std::max(1, static_cast<int>(std::ceil(norm(A) / max_edge_)));
    const int nv = std::max(1, static_cast<int>(std::ceil(norm(B) / max_edge_)));
    const V3 n = normalized(cross(A, B));
    std::vector<std::int64_t> index(static_cast<std::size_t>((nu + 1) * (nv + 1)), -1);
    auto point = [&](int i, int j) { return origin + A * (static_cast<float>(i) / nu) + B * (static_cast<float>(j) / nv); };
    auto vertex = [&](int i, int j) {
      std::int64_t& id = index[static_cast<std::size_t>(j * (nu + 1) + i)];
      if (id < 0)
        id = addVertex(point(i, j));
      return static_cast<std::uint32_t>(id);
    };
    for (int j = 0; j < nv; ++j)
      for (int i = 0; i < nu; ++i) {
        const V3 centre = (point(i, j) + point(i + 1, j + 1)) * 0.5f;
        if (scene_.occupied(centre + n * kHiddenProbe, 0.f, current_))
          continue;
        const std::uint32_t a = vertex(i, j), b = vertex(i + 1, j), c = vertex(i + 1, j + 1), d = vertex(i, j + 1);
        triangles_.push_back({a, b, c});
        triangles_.push_back({a, c, d});
      }
  }

  /// One triangle, wound so that its normal agrees with `outward`; skipped when hidden.
  void triangle(V3 a, V3 b, V3 c, V3 outward) {
    const V3 centre = (a + b + c) * (1.f / 3.f);
    // The solid itself does not hide its own faces: a chord of a curved face lies inside it.
    if (scene_.occupied(centre + normalized(outward) * kHiddenProbe, 0.f, current_))
      return;
    if (dot(cross(b - a, c - a), outward) < 0.f)
      std::swap(b, c);
    const std::uint32_t ia = addVertex(a), ib = addVertex(b), ic = addVertex(c);
    triangles_.push_back({ia, ib, ic});
  }

  void box(const Primitive& p) {
    const float h[3] = {p.half.x, p.half.y, p.half.z};
    for (int k = 0; k < 3; ++k) {
      const int i = (k + 1) % 3, j = (k + 2) % 3;
      for (const float s : {1.f, -1.f}) {
        float o[3], a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
        o[k] = s * h[k];
        o[i] = -h[i];
        o[j] = -h[j];
        a[i] = 2.f * h[i];
        b[j] = 2.f * h[j];
        V3 A = p.dirToWorld({a[0], a[1], a[2]}), B = p.dirToWorld({b[0], b[1], b[2]});
        if (s < 0.f)
          std::swap(A, B);
        grid(p.toWorld({o[0], o[1], o[2]}), A, B);
      }
    }
  }

  void cylinder(const Primitive& p) {
    const int ia = p.axis, ib = (ia + 1) % 3, ic = (ia + 2) % 3;
    const float r = p.half[ib], len = p.half[ia];
    // Chord error r (1 - cos(pi / n)) under 1 cm, at least 12 sides.
    const int n = std::max(12, static_cast<int>(std::ceil(kPi / std::acos(std::max(0.f, 1.f - 0.01f / r)))));
    const int m = std::max(1, static_cast<int>(std::ceil(2.f * len / max_edge_)));
    auto local = [&](float angle, float s, float radius) {
      float q[3];
      q[ia] = s;
      q[ib] = radius * std::cos(angle);
      q[ic] = radius * std::sin(angle);
      return V3{q[0], q[1], q[2]};
    };
    for (int i = 0; i < n; ++i) {
      const float a0 = 2.f * kPi * i / n, a1 = 2.f * kPi * (i + 1) / n, am = 0.5f * (a0 + a1);
      const V3 outward = p.dirToWorld(local(am, 0.f, 1.f));
      for (int j = 0; j < m; ++j) {
        const float s0 = -len + 2.f * len * j / m, s1 = -len + 2.f * len * (j + 1) / m;
        const V3 q00 = p.toWorld(local(a0, s0, r)), q10 = p.toWorld(local(a1, s0, r));
        const V3 q11 = p.toWorld(local(a1, s1, r)), q01 = p.toWorld(local(a0, s1, r));
        triangle(q00, q10, q11, outward);
        triangle(q00, q11, q01, outward);
      }
      for (const float s : {len, -len}) {
        float e[3] = {0, 0, 0};
        e[ia] = s > 0.f ? 1.f : -1.f;
        triangle(p.toWorld(local(0.f, s, 0.f)), p.toWorld(local(a0, s, r)), p.toWorld(local(a1, s, r)),
                 p.dirToWorld({e[0], e[1], e[2]}));
      }
    }
  }

  void ellipsoid(const Primitive& p) {
    const float rmax = std::max({p.half.x, p.half.y, p.half.z});
    const int lon = std::max(16, static_cast<int>(std::ceil(kPi / std::acos(std::max(0.f, 1.f - 0.02f / rmax)))));
    const int lat = std::max(8, lon / 2);
    auto local = [&](int i, int j) {
      const float phi = -0.5f * kPi + kPi * j / lat, lambda = 2.f * kPi * i / lon;
      return V3{p.half.x * std::cos(phi) * std::cos(lambda), p.half.y * std::sin(phi),
                p.half.z * std::cos(phi) * std::sin(lambda)};
    };
    for (int j = 0; j < lat; ++j)
      for (int i = 0; i < lon; ++i) {
        const V3 a = local(i, j), b = local(i + 1, j), c = local(i + 1, j + 1), d = local(i, j + 1);
        const V3 outward = p.dirToWorld((a + b + c + d) * 0.25f);
        if (j > 0)
          triangle(p.toWorld(a), p.toWorld(b), p.toWorld(c), outward);
        if (j < lat - 1)
          triangle(p.toWorld(a), p.toWorld(c), p.toWorld(d), outward);
      }
  }

  /// The road plane between the kerbs (the rest of it lies under the sidewalks).
  void road() {
    const StreetLayout& L = scene_.layout;
    const float half = L.halfRoadWidth() + 0.5f;
    const float z0 = L.z_begin - 40.f, z1 = L.z_end + 40.f;
    // (dx, 0, 0) x (0, 0, dz) = (0, -dx dz, 0): the normal points up (-y).
    grid({L.road_center_x - half, L.ground_y, z0}, {2.f * half, 0.f, 0.f}, {0.f, 0.f, z1 - z0});
  }

  std::vector<std::uint8_t>& vertexClasses() { return vertex_class_; }

  pcl::PolygonMesh finish() {
    pcl::PolygonMesh mesh;
    pcl::toPCLPointCloud2(cloud_, mesh.cloud);
    mesh.polygons.resize(triangles_.size());
    for (std::size_t t = 0; t < triangles_.size(); ++t)
      mesh.polygons[t].vertices.assign(triangles_[t].begin(), triangles_[t].end());
    return mesh;
  }

private:
  std::uint32_t addVertex(V3 p) {
    pcl::PointXYZRGB q;
    q.x = p.x;
    q.y = p.y;
    q.z = p.z;
    q.r = color_[0];
    q.g = color_[1];
    q.b = color_[2];
    cloud_.push_back(q);
    vertex_class_.push_back(class_);
    return static_cast<std::uint32_t>(cloud_.size() - 1);
  }

  const Scene& scene_;
  float max_edge_;
  std::int32_t current_ = -1;
  std::array<std::uint8_t, 3> color_{{128, 128, 128}};
  std::uint8_t class_ = 0;
  std::vector<std::uint8_t> vertex_class_; ///< SurfaceClass of each vertex
  pcl::PointCloud<pcl::PointXYZRGB> cloud_;
  std::vector<std::array<std::uint32_t, 3>> triangles_;
};

} // namespace

pcl::PolygonMesh sceneMesh(const Scene& scene, double max_edge_m, SurfaceClasses* classes) {
  MeshBuilder builder(scene, static_cast<float>(max_edge_m));
  builder.setMaterial(scene.materials[scene.ground_material]);
  builder.road();
  for (std::size_t i = 0; i < scene.primitives.size(); ++i) {
    const Primitive& p = scene.primitives[i];
    builder.setCurrent(static_cast<std::int32_t>(i));
    builder.setMaterial(scene.materials[p.material]);
    switch (p.shape) {
    case Shape::Box:
      builder.box(p);
      break;
    case Shape::Cylinder:
      builder.cylinder(p);
      break;
    case Shape::Ellipsoid:
      builder.ellipsoid(p);
      break;
    }
  }
  if (classes) {
    classes->names.clear();
    for (std::size_t c = 0; c < static_cast<std::size_t>(SurfaceClass::Count); ++c)
      classes->names.emplace_back(surfaceClassName(static_cast<SurfaceClass>(c)));
    classes->vertex_class = std::move(builder.vertexClasses());
  }
  return builder.finish();
}

} // namespace msf::synthetic
