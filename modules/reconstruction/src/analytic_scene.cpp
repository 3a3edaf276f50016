// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/reconstruction/analytic_scene.h>

#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

namespace msf {

namespace {
constexpr double kInf = std::numeric_limits<double>::infinity();
}

void AnalyticScene::addHalfSpace(const Eigen::Vector3d& normal, double offset) {
  const double n = normal.norm();
  solids_.push_back({Solid::Kind::HalfSpace, normal / n, Eigen::Vector3d(offset / n, 0, 0), Eigen::Matrix3d::Identity()});
}

void AnalyticScene::addSphere(const Eigen::Vector3d& center, double radius) {
  solids_.push_back({Solid::Kind::Sphere, center, Eigen::Vector3d(radius, 0, 0), Eigen::Matrix3d::Identity()});
}

void AnalyticScene::addBox(const Eigen::Vector3d& center, const Eigen::Vector3d& half, const Eigen::Matrix3d& rotation) {
  solids_.push_back({Solid::Kind::Box, center, half, rotation});
}

double AnalyticScene::hit(const Solid& s, const Eigen::Vector3d& o, const Eigen::Vector3d& d) {
  switch (s.kind) {
  case Solid::Kind::HalfSpace: {
    const double nd = s.a.dot(d);
    if (nd >= 0)
      return kInf;
    const double t = (s.b.x() - s.a.dot(o)) / nd;
    return t > 0 ? t : kInf;
  }
  case Solid::Kind::Sphere: {
    const Eigen::Vector3d oc = o - s.a;
    const double a = d.squaredNorm(), b = oc.dot(d), c = oc.squaredNorm() - s.b.x() * s.b.x();
    const double disc = b * b - a * c;
    if (disc < 0)
      return kInf;
    const double t = (-b - std::sqrt(disc)) / a;
    return t > 0 ? t : kInf;
  }
  case Solid::Kind::Box: {
    // Slabs in the box frame.
    const Eigen::Vector3d lo = s.R.transpose() * (o - s.a), ld = s.R.transpose() * d;
    double t0 = -kInf, t1 = kInf;
    for (int i = 0; i < 3; ++i) {
      if (std::abs(ld[i]) < 1e-15) {
        if (std::abs(lo[i]) > s.b[i])
          return kInf;
        continue;
      }
      double ta = (-s.b[i] - lo[i]) / ld[i], tb = (s.b[i] - lo[i]) / ld[i];
      if (ta > tb)
        std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    return (t0 <= t1 && t0 > 0) ? t0 : kInf;
  }
  }
  return kInf;
}

double AnalyticScene::distance(const Solid& s, const Eigen::Vector3d& p) {
  switch (s.kind) {
  case Solid::Kind::HalfSpace:
    return s.a.dot(p) - s.b.x();
  case Solid::Kind::Sphere:
    return (p - s.a).norm() - s.b.x();
  case Solid::Kind::Box: {
    const Eigen::Vector3d q = (s.R.transpose() * (p - s.a)).cwiseAbs() - s.b;
    return q.cwiseMax(0.0).norm() + std::min(q.maxCoeff(), 0.0);
  }
  }
  return kInf;
}

cv::Mat AnalyticScene::renderDepth(const PinholeCamera& camera, const Eigen::Isometry3d& T_world_cam,
                                   double max_depth) const {
  cv::Mat depth(camera.height, camera.width, CV_32FC1, cv::Scalar(0));
  const Eigen::Vector3d o = T_world_cam.translation();
  const Eigen::Matrix3d R = T_world_cam.linear();
  parallelFor(cv::Range(0, camera.height), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v) {
      float* row = depth.ptr<float>(v);
      for (int u = 0; u < camera.width; ++u) {
        // Direction with unit z in the camera, so the ray parameter is the depth.
        const Eigen::Vector3d d = R * Eigen::Vector3d((u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, 1.0);
        double t = kInf;
        for (const Solid& s : solids_)
          t = std::min(t, hit(s, o, d));
        row[u] = t <= max_depth ? static_cast<float>(t) : 0.f;
      }
    }
  });
  return depth;
}

double AnalyticScene::signedDistance(const Eigen::Vector3d& p) const {
  double d = kInf;
  for (const Solid& s : solids_)
    d = std::min(d, distance(s, p));
  return d;
}

} // namespace msf
