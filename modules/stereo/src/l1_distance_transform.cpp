// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/l1_distance_transform.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cstring>
#include <string>

namespace msf {

namespace {
// Columns per task of the column pass: 256 B of each row, so a task's rows stay in L2 for
// the backward scan; wide enough to fill whole vectors.
constexpr int kColumnChunk = 128;
} // namespace

namespace l1_distance {

void rowPass(const std::uint8_t* mask_row, int width, std::uint16_t* distance_row) {
  // Between two zeros (or a zero and the row's end, which is no zero) the distance is a
  // tent; a run of nonzero is found with memchr and filled in one vectorised loop.
  constexpr int kFar = 2 * kL1DistanceCap; // stands for "no zero on this side"
  int zero = -kFar;                         // the last zero on the left
  for (int u = 0; u < width;) {
    if (!mask_row[u]) {
      distance_row[u] = 0;
      zero = u++;
      continue;
    }
    const void* next = std::memchr(mask_row + u, 0, static_cast<std::size_t>(width - u));
    const int end = next ? static_cast<int>(static_cast<const std::uint8_t*>(next) - mask_row) : width;
    const int next_zero = next ? end : width + kFar;
    for (int k = u; k < end; ++k)
      distance_row[k] = static_cast<std::uint16_t>(std::min(std::min(k - zero, next_zero - k), kL1DistanceCap));
    u = end;
  }
}

namespace {
// min over rows v' of (row distance at v' + |v - v'|): a forward then a backward scan, each
// a row-to-row recurrence that is independent across columns.
template <typename Out>
void columnScans(cv::Mat& rows, cv::Mat& out, int begin, int end) {
  const int height = rows.rows;
  for (int v = 1; v < height; ++v) {
    const std::uint16_t* above = rows.ptr<std::uint16_t>(v - 1);
    std::uint16_t* here = rows.ptr<std::uint16_t>(v);
    for (int u = begin; u < end; ++u)
      here[u] = std::min<std::uint16_t>(here[u], static_cast<std::uint16_t>(above[u] + 1));
  }
  {
    const std::uint16_t* last = rows.ptr<std::uint16_t>(height - 1);
    Out* o = out.ptr<Out>(height - 1);
    for (int u = begin; u < end; ++u)
      o[u] = static_cast<Out>(last[u]);
  }
  for (int v = height - 2; v >= 0; --v) {
    const std::uint16_t* below = rows.ptr<std::uint16_t>(v + 1);
    std::uint16_t* here = rows.ptr<std::uint16_t>(v);
    Out* o = out.ptr<Out>(v);
    for (int u = begin; u < end; ++u) {
      const std::uint16_t d = std::min<std::uint16_t>(here[u], static_cast<std::uint16_t>(below[u] + 1));
      here[u] = d;
      o[u] = static_cast<Out>(d);
    }
  }
}
} // namespace

void columnPass(cv::Mat& row_distance, cv::Mat& distance, int type) {
  if (row_distance.type() != CV_16UC1 || row_distance.empty())
    throw InvalidInputError("l1 distance column pass: the row distances must be a non-empty CV_16UC1 image");
  if (type != CV_32F && type != CV_16U)
    throw InvalidInputError("l1 distance transform: the output type must be CV_32F or CV_16U");
  if (type == CV_16U && distance.data != row_distance.data)
    distance.create(row_distance.size(), CV_16UC1);
  else if (type == CV_32F)
    distance.create(row_distance.size(), CV_32FC1);
  const int chunks = (row_distance.cols + kColumnChunk - 1) / kColumnChunk;
  parallelFor(cv::Range(0, chunks), [&](const cv::Range& range) {
    const int begin = range.start * kColumnChunk, end = std::min(range.end * kColumnChunk, row_distance.cols);
    if (type == CV_32F)
      columnScans<float>(row_distance, distance, begin, end);
    else
      columnScans<std::uint16_t>(row_distance, distance, begin, end);
  });
}

} // namespace l1_distance

void l1DistanceTransform(const cv::Mat& mask, cv::Mat& distance, int type) {
  if (mask.empty() || mask.type() != CV_8UC1)
    throw InvalidInputError("l1DistanceTransform: the mask must be a non-empty CV_8UC1 image");
  if (type != CV_32F && type != CV_16U)
    throw InvalidInputError("l1DistanceTransform: the output type must be CV_32F or CV_16U, not " +
                            std::to_string(type));
  cv::Mat rows(mask.size(), CV_16UC1);
  parallelFor(cv::Range(0, mask.rows), [&](const cv::Range& range) {
    for (int v = range.start; v < range.end; ++v)
      l1_distance::rowPass(mask.ptr<std::uint8_t>(v), mask.cols, rows.ptr<std::uint16_t>(v));
  });
  if (type == CV_16U) {
    l1_distance::columnPass(rows, rows, CV_16U);
    distance = rows;
  } else {
    l1_distance::columnPass(rows, distance, CV_32F);
  }
}

} // namespace msf
