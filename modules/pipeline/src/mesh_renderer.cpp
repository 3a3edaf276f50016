// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/mesh_renderer.h>
#include <msf/reconstruction/mesh_rasterizer.h>

#include <algorithm>
#include <cmath>

namespace msf {

cv::Mat MeshRenderer::render(const TriangleMesh& mesh, const Eigen::Isometry3d& T_world_cam, double fx, double fy,
                             double cx, double cy, cv::Size size) {
  cv::Mat image(size, CV_8UC3, kBackground);
  PinholeCamera camera;
  camera.fx = static_cast<float>(fx), camera.fy = static_cast<float>(fy);
  camera.cx = static_cast<float>(cx), camera.cy = static_cast<float>(cy);
  camera.width = size.width, camera.height = size.height;
  // Visibility from the rasteriser (the surface seen at each pixel), then each pixel shaded.
  cv::Mat depth, ids;
  MeshRasterizer().render(mesh, camera, T_world_cam, depth, &ids);
  const Eigen::Isometry3f T_cam_world = T_world_cam.inverse().cast<float>();
  const bool coloured = mesh.colors.size() == mesh.vertices.size();
  for (int y = 0; y < size.height; ++y)
    for (int x = 0; x < size.width; ++x) {
      const std::int32_t id = ids.at<std::int32_t>(y, x);
      if (id < 0)
        continue;
      const auto& tri = mesh.triangles[static_cast<std::size_t>(id)];
      const Eigen::Vector3f a = T_cam_world * mesh.vertices[tri[0]], b = T_cam_world * mesh.vertices[tri[1]],
                            c = T_cam_world * mesh.vertices[tri[2]];
      const Eigen::Vector3f normal = (b - a).cross(c - a);
      const float n2 = normal.squaredNorm();
      if (!(n2 > 0.f))
        continue;
      const float z = depth.at<float>(y, x);
      const Eigen::Vector3f p = camera.point(static_cast<float>(x), static_cast<float>(y), z);
      // Lambert-like shading toward the viewer, both sides lit.
      const float shade = 0.35f + 0.65f * std::abs(normal.dot(p.normalized())) / std::sqrt(n2);
      float r = 170.f, g = 170.f, bl = 170.f;
      if (coloured) {
        // Barycentric weights of the point seen, from the areas it makes with the corners.
        const float wa = (b - p).cross(c - p).dot(normal) / n2, wb = (c - p).cross(a - p).dot(normal) / n2;
        const float wc = 1.f - wa - wb;
        const auto &ca = mesh.colors[tri[0]], &cb = mesh.colors[tri[1]], &cc = mesh.colors[tri[2]];
        r = wa * ca[0] + wb * cb[0] + wc * cc[0];
        g = wa * ca[1] + wb * cb[1] + wc * cc[1];
        bl = wa * ca[2] + wb * cb[2] + wc * cc[2];
      }
      image.at<cv::Vec3b>(y, x) = cv::Vec3b(cv::saturate_cast<std::uint8_t>(bl * shade),
                                            cv::saturate_cast<std::uint8_t>(g * shade),
                                            cv::saturate_cast<std::uint8_t>(r * shade));
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
