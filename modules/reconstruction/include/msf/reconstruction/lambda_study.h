// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/reconstruction/analytic_scene.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <opencv2/core/mat.hpp>
#include <opencv2/core/persistence.hpp>

#include <cstddef>
#include <iosfwd>
#include <string>
#include <vector>

namespace msf {

/// The study of paper Fig. 5: the error of the fused surface against the regularization
/// weight lambda (eq. 7) and the depth noise. A synthetic scene with smooth parts (a sphere,
/// the ground), edges and corners (a rotated box) and sharp boundaries (a plate floating in
/// front of a wall) is seen by a virtual camera on an arc; each frame's exact depth gets
/// Gaussian noise of sigma, the frames are fused with a given lambda, and the mesh's mean
/// absolute distance to the true surface is measured.
class LambdaStudy {
public:
  struct Config {
    std::vector<double> noise_mm{0, 5, 10, 20, 40, 80};
    std::vector<double> lambdas{0, 1, 2, 5, 10, 20};
    int frames = 10;
    double voxel_size_m = 0.05;
    double truncation_m = 0.25;  ///< 3 sigma of the largest noise, so noise is averaged, not clipped
    int sweeps = 1;
    /// argmin: eq. 7 solved to its minimizer every frame (the paper), not `sweeps` sweeps
    TsdfIntegrator::Solve solve = TsdfIntegrator::Solve::Sweeps;
    int width = 320, height = 240;
    double focal_px = 300.0;
    unsigned seed = 1;

    /// YAML section `lambda_study`: noise_mm and lambdas (sequences), frames, voxel_size_m,
    /// truncation_m, sweeps, solve (sweeps | argmin), width, height, focal_px, seed.
    void read(const cv::FileNode& node);
    void print(std::ostream& out) const;
  };

  struct Cell {
    double noise_mm = 0, lambda = 0;
    double mae_mm = 0;           ///< mean |true signed distance| of the mesh vertices
    std::size_t vertices = 0;
    double integrate_ms = 0;     ///< per frame
    double sweeps = 0;           ///< Gauss-Seidel sweeps of eq. 7 per frame, mean
  };

  explicit LambdaStudy(const Config& config);

  /// The scene (world y points down, the camera looks along +z).
  static AnalyticScene scene();

  /// One cell of the table.
  Cell run(double noise_mm, double lambda) const;
  /// Every (noise, lambda) pair, noise-major.
  std::vector<Cell> runAll() const;

  /// CSV: noise_mm,lambda,mae_mm,vertices,integrate_ms_per_frame. Atomic.
  static void writeCsv(const std::string& path, const std::vector<Cell>& cells);
  /// Error against lambda, one line per noise level (log y).
  static cv::Mat plot(const std::vector<Cell>& cells);

private:
  Config config_;
  AnalyticScene scene_;
};

} // namespace msf
