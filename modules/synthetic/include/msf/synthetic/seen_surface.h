// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/io/sequence.h>

#include <Eigen/Core>

#include <cstddef>
#include <vector>

namespace msf::synthetic {

/// The true static surface that the frames of synthetic sequences saw, as points in their
/// world: what a mesh's completeness is measured against (evaluateMesh's seen_truth), and the
/// depth each point was seen at (nearestViewDistance).
struct SeenSurface {
  std::vector<Eigen::Vector3f> points;
  std::vector<float> depths;

  /// Adds every `stride`-th pixel (along rows and columns) of camera 0's exact depth
  /// (gt/depth_0) of `frames` of `sequence`, up to `max_depth_m` and where no moving object is
  /// (gt/moving_0), back-projected at the frame's pose. Throws IOError when the sequence has no
  /// synthetic ground truth or no poses, InvalidInputError for a stride below 1.
  void add(const Sequence& sequence, const std::vector<std::size_t>& frames, double max_depth_m, int stride = 4);
};

} // namespace msf::synthetic
