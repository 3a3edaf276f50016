// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/exceptions.h>
#include <msf/evaluation/fusion_loss.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numeric>
#include <sstream>

namespace msf {

namespace {

constexpr float kNearInput = 0.01f; ///< "gave that input": within this share of its depth

bool near(float fused, float input) { return input > 0.f && std::abs(fused - input) <= kNearInput * input; }

FusionLoss::Gave whatWasGiven(float fused, float wrong_input, float right_input) {
  if (!(fused > 0.f))
    return FusionLoss::Nothing;
  if (near(fused, wrong_input))
    return FusionLoss::TheOtherInput;
  if (wrong_input > 0.f && fused > std::min(wrong_input, right_input) && fused < std::max(wrong_input, right_input))
    return FusionLoss::Between;
  return FusionLoss::Elsewhere;
}

std::string share(std::size_t count, std::size_t total) {
  char text[16];
  std::snprintf(text, sizeof(text), "%.2f", total ? 100.0 * static_cast<double>(count) / total : 0.0);
  return text;
}

} // namespace

void FusionLoss::add(const cv::Mat& ground_truth_depth, const cv::Mat& first, const cv::Mat& second,
                     const cv::Mat& fused, double focal_baseline, const D1Threshold& d1) {
  for (const cv::Mat* image : {&ground_truth_depth, &first, &second, &fused})
    if (image->type() != CV_32FC1 || image->size() != ground_truth_depth.size())
      throw InvalidInputError("fusion loss: the ground truth, both inputs and the fusion must be CV_32FC1 images "
                              "of one size");
  const auto right = [&](float z, double true_px) {
    return z > 0.f && !d1.exceeded(std::abs(focal_baseline / z - true_px), true_px);
  };
  for (int v = 0; v < ground_truth_depth.rows; ++v) {
    const float* gt = ground_truth_depth.ptr<float>(v);
    const float* a = first.ptr<float>(v);
    const float* b = second.ptr<float>(v);
    const float* f = fused.ptr<float>(v);
    for (int u = 0; u < ground_truth_depth.cols; ++u) {
      if (!(gt[u] > 0.f))
        continue;
      ++ground_truth;
      const double true_px = focal_baseline / gt[u];
      const bool a_right = right(a[u], true_px), b_right = right(b[u], true_px);
      // A choice: both inputs have a depth, one of them right.
      const bool both = a[u] > 0.f && b[u] > 0.f;
      gave_first_right += both && a_right && !b_right && near(f[u], a[u]);
      gave_second_right += both && b_right && !a_right && near(f[u], b[u]);
      if (right(f[u], true_px) || !(a_right || b_right))
        continue;
      if (a_right && b_right)
        ++both_right;
      else if (a_right)
        ++first_right[whatWasGiven(f[u], b[u], a[u])];
      else
        ++second_right[whatWasGiven(f[u], a[u], b[u])];
    }
  }
}

std::size_t FusionLoss::lost() const {
  return std::accumulate(first_right.begin(), first_right.end(), std::size_t{0}) +
         std::accumulate(second_right.begin(), second_right.end(), std::size_t{0}) + both_right;
}

std::string formatFusionLoss(const std::vector<std::pair<std::string, FusionLoss>>& rows, const std::string& first,
                             const std::string& second) {
  std::ostringstream out;
  out << "Lost to bound_select: % of the ground truth where a method is bad (D1) and an input right, by what it\n"
      << "gave there: the other input / a value between them / none / elsewhere\n";
  const auto gave = [&](const std::array<std::size_t, FusionLoss::kGaveCount>& counts, std::size_t total) {
    std::string text;
    for (std::size_t k = 0; k < counts.size(); ++k)
      text += (k ? " / " : "") + share(counts[k], total);
    return text;
  };
  char line[256];
  std::snprintf(line, sizeof(line), "%-20s %6s   %-30s %-30s %s\n", "method", "lost", (first + " right").c_str(),
                (second + " right").c_str(), "both right");
  out << line;
  for (const auto& [name, loss] : rows) {
    const std::size_t total = loss.ground_truth;
    std::snprintf(line, sizeof(line), "%-20s %5s%%   %-30s %-30s %s\n", name.c_str(), share(loss.lost(), total).c_str(),
                  gave(loss.first_right, total).c_str(), gave(loss.second_right, total).c_str(),
                  share(loss.both_right, total).c_str());
    out << line;
  }
  out << "Where both inputs have a depth and one is right, % of the ground truth where the method gave each input:\n"
      << "right / wrong\n";
  std::snprintf(line, sizeof(line), "%-20s %-24s %s\n", "method", ("gave " + first).c_str(),
                ("gave " + second).c_str());
  out << line;
  for (const auto& [name, loss] : rows) {
    const std::size_t total = loss.ground_truth;
    const std::string gave_first = share(loss.gave_first_right, total) + " / " +
                                   share(loss.second_right[FusionLoss::TheOtherInput], total);
    const std::string gave_second = share(loss.gave_second_right, total) + " / " +
                                    share(loss.first_right[FusionLoss::TheOtherInput], total);
    std::snprintf(line, sizeof(line), "%-20s %-24s %s\n", name.c_str(), gave_first.c_str(), gave_second.c_str());
    out << line;
  }
  return out.str();
}

} // namespace msf
