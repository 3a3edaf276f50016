// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/atomic_file.h>
#include <msf/common/checked_write.h>
#include <msf/common/elapsed.h>
#include <msf/common/exceptions.h>
#include <msf/common/limits.h>
#include <msf/common/line_plot.h>
#include <msf/reconstruction/lambda_study.h>
#include <msf/reconstruction/marching_cubes.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <chrono>
#include <cmath>
#include <fstream>
#include <iomanip>
#include <ostream>
#include <random>
#include <sstream>

namespace msf {

namespace {

/// Camera on an arc of +-15 degrees around the scene, 3 m away, a little above it.
Eigen::Isometry3d arcPose(int i, int n) {
  const Eigen::Vector3d target(0, 0.1, 3.0);
  const double a = n == 1 ? 0.0 : (-15.0 + 30.0 * i / (n - 1)) * M_PI / 180.0;
  const Eigen::Vector3d eye = target + Eigen::Vector3d(3.0 * std::sin(a), -0.6, -3.0 * std::cos(a));
  const Eigen::Vector3d z = (target - eye).normalized();
  const Eigen::Vector3d x = Eigen::Vector3d::UnitY().cross(z).normalized();
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = z.cross(x);
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

} // namespace

void LambdaStudy::Config::validate() const {
  checkKeyRanges(*this);
  TsdfVolume::validate(voxel_size_m, truncation_m, 0.0);
}

LambdaStudy::LambdaStudy(const Config& config) : config_((config.validate(), config)), scene_(scene()) {}

AnalyticScene LambdaStudy::scene() {
  AnalyticScene s;
  s.addHalfSpace(Eigen::Vector3d(0, -1, 0), -0.6);  // ground, 0.6 m below the scene centre
  s.addHalfSpace(Eigen::Vector3d(0, 0, -1), -4.3);  // back wall
  s.addSphere(Eigen::Vector3d(0.55, 0.2, 3.3), 0.4); // smooth
  s.addBox(Eigen::Vector3d(-0.6, 0.3, 3.1), Eigen::Vector3d(0.3, 0.3, 0.3),
           Eigen::AngleAxisd(0.6, Eigen::Vector3d::UnitY()).toRotationMatrix()); // edges and corners
  s.addBox(Eigen::Vector3d(0.0, -0.45, 2.5), Eigen::Vector3d(0.35, 0.15, 0.05)); // a plate in front: sharp boundaries
  return s;
}

LambdaStudy::Cell LambdaStudy::run(double noise_mm, double lambda) const {
  PinholeCamera camera;
  camera.width = config_.width;
  camera.height = config_.height;
  camera.fx = camera.fy = static_cast<float>(config_.focal_px);
  camera.cx = 0.5f * static_cast<float>(config_.width - 1);
  camera.cy = 0.5f * static_cast<float>(config_.height - 1);
  TsdfVolume volume(config_.voxel_size_m, config_.truncation_m);
  // The paper's TSDF (projective distance, every depth weighing the same, no free-space
  // updates), so that lambda alone varies: the scene is static and its noise uniform.
  TsdfIntegrator::Config ic;
  ic.signed_distance = TsdfIntegrator::SignedDistance::Projective;
  ic.weighting = TsdfIntegrator::Weighting::Constant;
  ic.truncation_sigmas = 0.0;
  ic.space_carving = false;
  ic.weight_dropoff = false;
  ic.lambda = lambda;
  ic.sweeps = config_.sweeps;
  ic.solve = config_.solve;
  TsdfIntegrator integrator(volume, ic);
  // The same noise for every lambda at a noise level: the lambdas are compared on equal data.
  std::mt19937 rng(config_.seed);
  std::normal_distribution<float> noise(0.f, static_cast<float>(noise_mm * 1e-3));
  double integrate_ms = 0, sweeps = 0;
  for (int i = 0; i < config_.frames; ++i) {
    const Eigen::Isometry3d pose = arcPose(i, config_.frames);
    DepthFrame frame;
    frame.camera = camera;
    frame.depth = scene_.renderDepth(camera, pose, 20.0);
    if (noise_mm > 0)
      for (int v = 0; v < frame.depth.rows; ++v) {
        float* row = frame.depth.ptr<float>(v);
        for (int u = 0; u < frame.depth.cols; ++u)
          if (row[u] > 0.f)
            row[u] = std::max(0.01f, row[u] + noise(rng));
      }
    const auto t0 = std::chrono::steady_clock::now();
    integrator.integrate(frame, pose);
    integrate_ms += msSince(t0);
    sweeps += integrator.lastStats().regularize_sweeps;
  }
  TriangleMesh mesh;
  MarchingCubes::Config every_voxel; // and eq. 7 in the integration alone: no smoothing at meshing
  every_voxel.min_weight = 0.f;
  every_voxel.smoothing_lambda = 0.f;
  MarchingCubes(every_voxel).extract(volume, mesh);
  Cell cell;
  cell.noise_mm = noise_mm;
  cell.lambda = lambda;
  cell.vertices = mesh.vertices.size();
  cell.integrate_ms = integrate_ms / config_.frames;
  cell.sweeps = sweeps / config_.frames;
  double sum = 0;
  for (const auto& p : mesh.vertices)
    sum += std::abs(scene_.signedDistance(p.cast<double>()));
  cell.mae_mm = mesh.vertices.empty() ? std::nan("") : 1e3 * sum / static_cast<double>(mesh.vertices.size());
  return cell;
}

std::vector<LambdaStudy::Cell> LambdaStudy::runAll() const {
  std::vector<Cell> cells;
  for (const double s : config_.noise_mm)
    for (const double l : config_.lambdas)
      cells.push_back(run(s, l));
  return cells;
}

void LambdaStudy::writeCsv(const std::string& path, const std::vector<Cell>& cells) {
  writeStreamAtomically(path, [&](std::ostream& out) {
    out << "noise_mm,lambda,mae_mm,vertices,integrate_ms_per_frame,sweeps_per_frame\n" << std::fixed;
    for (const Cell& c : cells)
      out << std::setprecision(1) << c.noise_mm << ',' << std::setprecision(2) << c.lambda << ',' << std::setprecision(3)
          << c.mae_mm << ',' << c.vertices << ',' << std::setprecision(2) << c.integrate_ms << ',' << std::setprecision(1)
          << c.sweeps << '\n';
  });
}

cv::Mat LambdaStudy::plot(const std::vector<Cell>& cells) {
  LinePlot chart("Surface error against lambda (eq. 7), one line per depth noise", "lambda",
                 "mean absolute surface error [mm]");
  chart.setLogY(true);
  std::vector<double> levels;
  for (const Cell& c : cells)
    if (std::find(levels.begin(), levels.end(), c.noise_mm) == levels.end())
      levels.push_back(c.noise_mm);
  for (const double s : levels) {
    std::vector<double> x, y;
    for (const Cell& c : cells)
      if (c.noise_mm == s) {
        x.push_back(c.lambda);
        y.push_back(c.mae_mm);
      }
    std::ostringstream name;
    name << "sigma " << s << " mm";
    chart.addSeries(name.str(), x, y);
  }
  return chart.render();
}

} // namespace msf
