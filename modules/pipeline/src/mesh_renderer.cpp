#include <msf/pipeline/mesh_renderer.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace msf {

cv::Mat MeshRenderer::render(const TriangleMesh& mesh, const Eigen::Isometry3d& T_world_cam, double fx, double fy,
                             double cx, double cy, cv::Size size) {
  cv::Mat image(size, CV_8UC3, kBackground);
  std::vector<float> zbuffer(static_cast<std::size_t>(size.area()), std::numeric_limits<float>::infinity());
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  constexpr float kNear = 0.3f;

  std::vector<Eigen::Vector3f> cam(mesh.vertices.size());
  for (std::size_t i = 0; i < cam.size(); ++i)
    cam[i] = T_cam_world * mesh.vertices[i];
  const bool coloured = mesh.colors.size() == mesh.vertices.size();

  for (const auto& tri : mesh.triangles) {
    const Eigen::Vector3f& a = cam[tri[0]];
    const Eigen::Vector3f& b = cam[tri[1]];
    const Eigen::Vector3f& c = cam[tri[2]];
    if (a.z() < kNear || b.z() < kNear || c.z() < kNear)
      continue; // no clipping: previews only lose triangles that cross the near plane
    const Eigen::Vector3f normal = (b - a).cross(c - a);
    const float n = normal.norm();
    if (n <= 0.f)
      continue;
    // Lambert-like shading toward the viewer, both sides lit.
    const float shade = 0.35f + 0.65f * std::abs(normal.dot(a.normalized())) / n;
    float u[3], v[3], z[3];
    const Eigen::Vector3f* p[3] = {&a, &b, &c};
    for (int k = 0; k < 3; ++k) {
      z[k] = p[k]->z();
      u[k] = static_cast<float>(fx * p[k]->x() / z[k] + cx);
      v[k] = static_cast<float>(fy * p[k]->y() / z[k] + cy);
    }
    const int u0 = std::max(0, static_cast<int>(std::floor(std::min({u[0], u[1], u[2]}))));
    const int u1 = std::min(size.width - 1, static_cast<int>(std::ceil(std::max({u[0], u[1], u[2]}))));
    const int v0 = std::max(0, static_cast<int>(std::floor(std::min({v[0], v[1], v[2]}))));
    const int v1 = std::min(size.height - 1, static_cast<int>(std::ceil(std::max({v[0], v[1], v[2]}))));
    const float area = (u[1] - u[0]) * (v[2] - v[0]) - (u[2] - u[0]) * (v[1] - v[0]);
    if (u0 > u1 || v0 > v1 || std::abs(area) < 1e-9f)
      continue;
    for (int y = v0; y <= v1; ++y)
      for (int x = u0; x <= u1; ++x) {
        const float px = static_cast<float>(x), py = static_cast<float>(y);
        const float w0 = ((u[1] - px) * (v[2] - py) - (u[2] - px) * (v[1] - py)) / area;
        const float w1 = ((u[2] - px) * (v[0] - py) - (u[0] - px) * (v[2] - py)) / area;
        const float w2 = 1.f - w0 - w1;
        if (w0 < 0.f || w1 < 0.f || w2 < 0.f)
          continue;
        const float depth = w0 * z[0] + w1 * z[1] + w2 * z[2];
        float& zb = zbuffer[static_cast<std::size_t>(y) * size.width + x];
        if (depth >= zb)
          continue;
        zb = depth;
        float r = 170.f, g = 170.f, bl = 170.f;
        if (coloured) {
          const auto &ca = mesh.colors[tri[0]], &cb = mesh.colors[tri[1]], &cc = mesh.colors[tri[2]];
          r = w0 * ca[0] + w1 * cb[0] + w2 * cc[0];
          g = w0 * ca[1] + w1 * cb[1] + w2 * cc[1];
          bl = w0 * ca[2] + w1 * cb[2] + w2 * cc[2];
        }
        image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<std::uint8_t>(bl * shade),
                                              cv::saturate_cast<std::uint8_t>(g * shade),
                                              cv::saturate_cast<std::uint8_t>(r * shade));
      }
  }
  return image;
}

cv::Mat MeshRenderer::renderFromAbove(const TriangleMesh& mesh, const Eigen::Vector3d& up, cv::Size size) {
  if (mesh.vertices.empty())
    return cv::Mat(size, CV_8UC3, kBackground);
  Eigen::Vector3f lo = mesh.vertices.front(), hi = lo;
  for (const auto& p : mesh.vertices)
    lo = lo.cwiseMin(p), hi = hi.cwiseMax(p);
  const Eigen::Vector3d centre = ((lo + hi) / 2).cast<double>();
  // Camera axes: z looks down (-up); x along the world's most horizontal axis.
  const Eigen::Vector3d z = -up.normalized();
  Eigen::Vector3d x = (std::abs(z.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitZ());
  x = (x - x.dot(z) * z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  // Half extents of the box in the camera's x and y.
  double half_x = 0, half_y = 0, half_z = 0;
  for (int k = 0; k < 8; ++k) {
    const Eigen::Vector3d corner((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(), (k & 4) ? hi.z() : lo.z());
    const Eigen::Vector3d d = corner - centre;
    half_x = std::max(half_x, std::abs(d.dot(x)));
    half_y = std::max(half_y, std::abs(d.dot(y)));
    half_z = std::max(half_z, std::abs(d.dot(z)));
  }
  // A long lens from far away is nearly orthographic: `scale` pixels per metre at the centre.
  const double scale = 0.45 * std::min(size.width / std::max(half_x, 1e-3), size.height / std::max(half_y, 1e-3));
  const double distance = 20.0 * std::max({half_x, half_y, 1.0}) + half_z;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() << x, y, z;
  T_world_cam.translation() = centre - distance * z;
  return render(mesh, T_world_cam, scale * distance, scale * distance, size.width / 2.0, size.height / 2.0, size);
}

} // namespace msf
