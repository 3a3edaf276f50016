// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include "scenes.h"

#include <msf/common/exceptions.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <gtest/gtest.h>
#include <opencv2/imgproc.hpp>

#include <cstddef>
#include <cstdio>
#include <functional>

namespace msf {
namespace {

/// A façade 75 m ahead (beyond max_depth_m, 40 m), a pole 0.3 m wide 18 m ahead and 1.5 m to
/// the left, and with `car` the back of a car 16 m ahead in the lane.
AnalyticScene street(bool car) {
  AnalyticScene s;
  s.addBox(Eigen::Vector3d(0, 0, 75), Eigen::Vector3d(60, 30, 0.5));
  s.addBox(Eigen::Vector3d(-1.5, -1, 18), Eigen::Vector3d(0.15, 3, 0.15));
  if (car)
    s.addBox(Eigen::Vector3d(0, 0.9, 18), Eigen::Vector3d(0.9, 0.7, 2));
  return s;
}

/// The scene's depth from the origin, the silhouettes of what lies in range narrowed by
/// `narrowed_px` (where the façade shows instead), as matching and interpolation narrow them.
DepthFrame frameOf(const AnalyticScene& scene, const PinholeCamera& camera, int narrowed_px = 0) {
  DepthFrame frame;
  frame.camera = camera;
  frame.depth = scene.renderDepth(camera, Eigen::Isometry3d::Identity(), 100.0);
  if (narrowed_px > 0) {
    const cv::Mat near = frame.depth < 40.f;
    const int side = 2 * narrowed_px + 1;
    cv::Mat inner;
    cv::erode(near, inner, cv::getStructuringElement(cv::MORPH_RECT, cv::Size(side, side)));
    frame.depth.setTo(75.f, near & ~inner);
  }
  return frame;
}

std::size_t verticesWhere(const TsdfVolume& volume, const std::function<bool(const Eigen::Vector3f&)>& inside) {
  TriangleMesh mesh;
  MarchingCubes().extract(volume, mesh);
  std::size_t n = 0;
  for (const auto& v : mesh.vertices)
    n += inside(v);
  return n;
}

struct Counts {
  std::size_t car = 0, pole = 0;
};

/// The car seen once, then gone for three frames that see the façade through where it was, and
/// the pole 2 pixels narrower a side.
Counts afterTheCarDroveOn(bool far_carving) {
  const PinholeCamera camera = test::kittiCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.far_carving = far_carving;
  TsdfIntegrator integrator(volume, config);
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  for (int i = 0; i < 4; ++i) {
    const DepthFrame frame = frameOf(street(i == 0), camera, i == 0 ? 0 : 2);
    integrator.integrate(frame, pose);
    integrator.carveBeyondRange(frame, pose, 1111.f);
  }
  Counts c;
  c.car = verticesWhere(volume, [](const Eigen::Vector3f& v) { return std::abs(v.x()) < 1.f && v.z() < 17.f; });
  c.pole = verticesWhere(volume, [](const Eigen::Vector3f& v) { return v.x() < -1.3f && v.z() < 19.f; });
  return c;
}

TEST(FarCarving, ACarThatDroveOnIsClearedWhereTheFarFacadeShowsAPoleStays) {
  const Counts without = afterTheCarDroveOn(false), with = afterTheCarDroveOn(true);
  std::printf("  car %zu -> %zu vertices, pole %zu -> %zu\n", without.car, with.car, without.pole, with.pole);
  // Without, nothing clears the car's back: the façade behind is beyond the range, never integrated.
  EXPECT_GT(without.car, 200u);
  EXPECT_LT(with.car, without.car / 50);
  // The pole's silhouette stands against the same far rays every frame: it is left as it is
  // (carved where its voxels straddle the far rays, it would break into pieces).
  EXPECT_GT(without.pole, 100u);
  EXPECT_NEAR(static_cast<double>(with.pole), static_cast<double>(without.pole), without.pole / 20.0);
}

TEST(FarCarving, OffWithoutSpaceCarvingAndRefusesBadInput) {
  const PinholeCamera camera = test::kittiCamera();
  TsdfVolume volume(0.1, 0.3);
  TsdfIntegrator::Config config;
  config.space_carving = false;
  TsdfIntegrator integrator(volume, config);
  const Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  integrator.integrate(frameOf(street(true), camera), pose);
  const std::size_t before = verticesWhere(volume, [](const Eigen::Vector3f&) { return true; });
  integrator.carveBeyondRange(frameOf(street(false), camera), pose, 1111.f);
  EXPECT_EQ(verticesWhere(volume, [](const Eigen::Vector3f&) { return true; }), before);

  TsdfIntegrator carving(volume, TsdfIntegrator::Config());
  EXPECT_THROW(carving.carveBeyondRange(frameOf(street(false), camera), pose, 0.f), InvalidInputError);
  Eigen::Isometry3d sheared = pose;
  sheared.linear()(0, 1) = 0.5;
  EXPECT_THROW(carving.carveBeyondRange(frameOf(street(false), camera), sheared, 1111.f), InvalidInputError);
  DepthFrame bad = frameOf(street(false), camera);
  bad.weight = cv::Mat(2, 2, CV_32FC1, cv::Scalar(1.f));
  EXPECT_THROW(carving.carveBeyondRange(bad, pose, 1111.f), InvalidInputError);
}

} // namespace
} // namespace msf
