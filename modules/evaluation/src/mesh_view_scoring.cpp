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
                          Scorer scorer, const std::map<std::size_t, int>& top_rows) {
  if (!camera.valid())
    throw InvalidInputError("mesh views: invalid camera (" + std::to_string(camera.width) + "x" +
                            std::to_string(camera.height) + " px, fx " + std::to_string(camera.fx) + ")");
  for (const auto& [frame, T_world_cam] : views)
    if (!T_world_cam.matrix().allFinite())
      throw InvalidInputError("mesh views: the pose of frame " + std::to_string(frame) + " is not finite");
  for (const auto& [frame, rows] : top_rows)
    if (rows < 1 || rows > camera.height)
      throw InvalidInputError("mesh views: frame " + std::to_string(frame) + "'s scorer reads " + std::to_string(rows) +
                              " rows, not 1.." + std::to_string(camera.height));
  const std::size_t index = scorers_.size();
  scorers_.push_back(std::move(scorer));
  for (const auto& [frame, T_world_cam] : views) {
    std::vector<View>& at_frame = views_[frame];
    auto shared = std::find_if(at_frame.begin(), at_frame.end(), [&](const View& v) {
      return sameCamera(v.camera, camera) && v.T_world_cam.matrix() == T_world_cam.matrix();
    });
    if (shared == at_frame.end())
      shared = at_frame.insert(at_frame.end(), View{camera, T_world_cam, 0, {}});
    const auto rows = top_rows.find(frame);
    shared->rows = std::max(shared->rows, rows == top_rows.end() ? camera.height : rows->second);
    shared->scorers.push_back(index);
  }
}

std::size_t MeshViewScoring::score(const TriangleMesh& mesh) {
  const MeshRasterizer::RunBounds bounds = MeshRasterizer::triangleRunBounds(mesh); // each view renders its part
  std::size_t rendered = 0;
  for (const auto& [frame, at_frame] : views_)
    for (const View& view : at_frame) {
      // The top rows alone: the same camera cut short sees the same surface at each of its pixels.
      PinholeCamera top = view.camera;
      top.height = view.rows;
      rasterizer_.render(mesh, top, view.T_world_cam, rendered_, nullptr, &bounds);
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
