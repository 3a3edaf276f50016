// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/mesh_view_scoring.h>

#include <algorithm>
#include <string>

namespace msf {

namespace {

bool sameCamera(const PinholeCamera& a, const PinholeCamera& b) {
  return a.fx == b.fx && a.fy == b.fy && a.cx == b.cx && a.cy == b.cy && a.width == b.width && a.height == b.height;
}

} // namespace

void MeshViewScoring::add(const PinholeCamera& camera, const std::map<std::size_t, Eigen::Isometry3d>& views,
                          Scorer scorer) {
  if (!camera.valid())
    throw InvalidInputError("mesh views: invalid camera (" + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " px, fx " + std::to_string(camera.fx) + ")");
  for (const auto& [frame, T_world_cam] : views)
    if (!T_world_cam.matrix().allFinite())
      throw InvalidInputError("mesh views: the pose of frame " + std::to_string(frame) + " is not finite");
  const std::size_t index = scorers_.size();
  scorers_.push_back(std::move(scorer));
  for (const auto& [frame, T_world_cam] : views) {
    std::vector<View>& at_frame = views_[frame];
    auto shared = std::find_if(at_frame.begin(), at_frame.end(), [&](const View& v) {
      return sameCamera(v.camera, camera) && v.T_world_cam.matrix() == T_world_cam.matrix();
    });
    if (shared == at_frame.end())
      shared = at_frame.insert(at_frame.end(), View{camera, T_world_cam, {}});
    shared->scorers.push_back(index);
  }
}

std::size_t MeshViewScoring::score(const TriangleMesh& mesh) {
  const MeshRasterizer::RunBounds bounds = MeshRasterizer::triangleRunBounds(mesh); // each view renders its part
  std::size_t rendered = 0;
  for (const auto& [frame, at_frame] : views_)
    for (const View& view : at_frame) {
      rasterizer_.render(mesh, view.camera, view.T_world_cam, rendered_, nullptr, &bounds);
      ++rendered;
      for (std::size_t s : view.scorers)
        scorers_[s](frame, rendered_);
    }
  return rendered;
}

std::size_t MeshViewScoring::views() const {
  std::size_t n = 0;
  for (const auto& [frame, at_frame] : views_)
    n += at_frame.size();
  return n;
}

} // namespace msf
