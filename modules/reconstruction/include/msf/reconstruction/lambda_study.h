// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/config_keys.h>
#include <msf/common/limits.h>
#include <msf/reconstruction/analytic_scene.h>
#include <msf/reconstruction/tsdf_integrator.h>

#include <opencv2/core/mat.hpp>

#include <cstddef>
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
  /// Section `lambda_study` of a config file.
  struct Config {
    static constexpr const char* kSection = "lambda_study";
    static constexpr const char* kAbout =
        "msf_lambda_study (the paper's Fig. 5): the fused surface's error against lambda and the depth noise";
    std::vector<double> noise_mm{0, 5, 10, 20, 40, 80};
    std::vector<double> lambdas{0, 1, 2, 5, 10, 20};
    int frames = 10;
    double voxel_size_m = 0.05;
    double truncation_m = 0.25; ///< 3 sigma of the largest noise, so noise is averaged, not clipped
    int sweeps = 1;
    TsdfIntegrator::Solve solve = TsdfIntegrator::Solve::Sweeps;
    int width = 320, height = 240;
    double focal_px = 300.0;
    unsigned seed = 1;

    template <class Keys>
    void keys(Keys& k) {
      k("noise_mm", noise_mm, atLeast(0), "sigmas of the Gaussian noise added to the exact depth, mm");
      k("lambdas", lambdas, atLeast(0), "eq. 7's lambdas tried at each noise");
      k("frames", frames, between(1, 10000), "frames fused, on an arc around the scene");
      k("voxel_size_m", voxel_size_m, between(TsdfVolume::kMinVoxelSizeM, TsdfVolume::kMaxVoxelSizeM),
        "edge of a voxel, m");
      k("truncation_m", truncation_m, above(0), "the volume's truncation, m");
      k("sweeps", sweeps, between(0, TsdfIntegrator::Config::kMaxSweeps), "Gauss-Seidel sweeps of eq. 7 per frame");
      k("solve", solve, TsdfIntegrator::kSolves,
        "sweeps: that many per frame | argmin: eq. 7 solved to its minimizer every frame (the paper)");
      k("width", width, between(2, limits::kMaxImageSide), "the virtual camera's image width, px");
      k("height", height, between(2, limits::kMaxImageSide), "its height, px");
      k("focal_px", focal_px, above(0), "its focal length, px");
      k("seed", seed, anyNumber(), "seed of the noise");
    }
    /// Throws ConfigError naming the key of a value out of range.
    void validate() const;
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
