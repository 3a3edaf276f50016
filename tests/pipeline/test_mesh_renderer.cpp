// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/pipeline/mesh_renderer.h>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

namespace {

/// A square of side 2 m facing the camera at depth z, centred on its axis, of one colour.
void addSquare(msf::TriangleMesh& mesh, float z, std::array<std::uint8_t, 3> rgb) {
  const auto first = static_cast<std::uint32_t>(mesh.vertices.size());
  for (const auto& [x, y] : {std::pair{-1.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {-1.f, 1.f}}) {
    mesh.vertices.emplace_back(x, y, z);
    mesh.colors.push_back(rgb);
  }
  mesh.triangles.push_back({first, first + 1, first + 2});
  mesh.triangles.push_back({first, first + 2, first + 3});
}

/// Channels within `tol` of each other: shading toward the viewer is 1 only on the axis.
bool near(const cv::Vec3b& a, const cv::Vec3b& b, int tol = 8) {
  for (int k = 0; k < 3; ++k)
    if (std::abs(a[k] - b[k]) > tol)
      return false;
  return true;
}

cv::Vec3b background() {
  const cv::Scalar& b = msf::MeshRenderer::kBackground;
  return cv::Vec3b(static_cast<std::uint8_t>(b[0]), static_cast<std::uint8_t>(b[1]), static_cast<std::uint8_t>(b[2]));
}

TEST(MeshRenderer, ASquareFacingTheCameraCoversItsProjection) {
  msf::TriangleMesh mesh;
  addSquare(mesh, 10.f, {200, 100, 50});
  // f = 100 px: the square spans 2 m * 100 / 10 m = 20 px around the centre (50, 40).
  const cv::Mat image =
      msf::MeshRenderer::render(mesh, Eigen::Isometry3d::Identity(), 100, 100, 50, 40, cv::Size(100, 80));
  ASSERT_EQ(image.type(), CV_8UC3);
  // Facing the viewer squarely (shade about 1): its own colour, in BGR.
  EXPECT_TRUE(near(image.at<cv::Vec3b>(40, 50), cv::Vec3b(50, 100, 200))) << image.at<cv::Vec3b>(40, 50);
  EXPECT_TRUE(near(image.at<cv::Vec3b>(32, 42), cv::Vec3b(50, 100, 200))) << image.at<cv::Vec3b>(32, 42);
  EXPECT_EQ(image.at<cv::Vec3b>(40, 65), background());
  EXPECT_EQ(image.at<cv::Vec3b>(5, 5), background());
  int covered = 0;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      covered += image.at<cv::Vec3b>(y, x) != background();
  EXPECT_NEAR(covered, 21 * 21, 2 * 21); // 20 px a side, give or take the edge pixels
}

TEST(MeshRenderer, TheNearerSurfaceHidesTheFarther) {
  // The same 2 m squares at 5, 10 and 20 m: 40, 20 and 10 px wide; whatever the drawing
  // order, the nearest one is seen where they overlap.
  for (const bool nearest_first : {true, false}) {
    msf::TriangleMesh mesh;
    if (nearest_first)
      addSquare(mesh, 5.f, {255, 0, 0});
    addSquare(mesh, 20.f, {0, 0, 255});
    addSquare(mesh, 10.f, {0, 255, 0});
    if (!nearest_first)
      addSquare(mesh, 5.f, {255, 0, 0});
    const cv::Mat image =
        msf::MeshRenderer::render(mesh, Eigen::Isometry3d::Identity(), 100, 100, 50, 40, cv::Size(100, 80));
    EXPECT_TRUE(near(image.at<cv::Vec3b>(40, 50), cv::Vec3b(0, 0, 255))) << image.at<cv::Vec3b>(40, 50);
    EXPECT_TRUE(near(image.at<cv::Vec3b>(40, 65), cv::Vec3b(0, 0, 255))) << image.at<cv::Vec3b>(40, 65);
    EXPECT_EQ(image.at<cv::Vec3b>(40, 75), background());
  }
  // Without the nearest, the 10 m square hides the 20 m one.
  msf::TriangleMesh mesh;
  addSquare(mesh, 20.f, {0, 0, 255});
  addSquare(mesh, 10.f, {0, 255, 0});
  const cv::Mat image =
      msf::MeshRenderer::render(mesh, Eigen::Isometry3d::Identity(), 100, 100, 50, 40, cv::Size(100, 80));
  EXPECT_TRUE(near(image.at<cv::Vec3b>(40, 50), cv::Vec3b(0, 255, 0))) << image.at<cv::Vec3b>(40, 50);
}

TEST(MeshRenderer, BehindTheCameraNothingIsDrawn) {
  msf::TriangleMesh mesh;
  addSquare(mesh, -10.f, {255, 255, 255});
  const cv::Mat image =
      msf::MeshRenderer::render(mesh, Eigen::Isometry3d::Identity(), 100, 100, 50, 40, cv::Size(100, 80));
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      ASSERT_EQ(image.at<cv::Vec3b>(y, x), background()) << "pixel " << x << ", " << y;
}

TEST(MeshRenderer, FromAboveFramesTheWholeMesh) {
  // A 40 m x 10 m floor in the x-z plane at y = 1.6 (KITTI camera axes: up is -y).
  msf::TriangleMesh mesh;
  mesh.vertices = {{-5.f, 1.6f, 0.f}, {5.f, 1.6f, 0.f}, {5.f, 1.6f, 40.f}, {-5.f, 1.6f, 40.f}};
  mesh.colors.assign(4, {230, 230, 230});
  mesh.triangles = {{0, 1, 2}, {0, 2, 3}};
  const cv::Mat image = msf::MeshRenderer::renderFromAbove(mesh, Eigen::Vector3d(0, -1, 0), cv::Size(200, 200));
  // The floor faces the camera: near-white on the dark background, and wholly inside the frame.
  int covered = 0, top = image.rows, bottom = -1, left = image.cols, right = -1;
  for (int y = 0; y < image.rows; ++y)
    for (int x = 0; x < image.cols; ++x)
      if (image.at<cv::Vec3b>(y, x) != background()) {
        ++covered;
        top = std::min(top, y), bottom = std::max(bottom, y), left = std::min(left, x), right = std::max(right, x);
      }
  ASSERT_GT(covered, 0);
  EXPECT_GT(top, 0);
  EXPECT_GT(left, 0);
  EXPECT_LT(bottom, image.rows - 1);
  EXPECT_LT(right, image.cols - 1);
  // 4:1 in the world, 4:1 on screen (either way round).
  const double w = right - left + 1, h = bottom - top + 1;
  EXPECT_NEAR(std::max(w, h) / std::min(w, h), 4.0, 0.4);
  EXPECT_GT(image.at<cv::Vec3b>((top + bottom) / 2, (left + right) / 2)[1], 200);
}

} // namespace
