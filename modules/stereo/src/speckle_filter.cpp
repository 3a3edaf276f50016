// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/parallel.h>
#include <msf/common/exceptions.h>
#include <msf/stereo/speckle_filter.h>

#include <opencv2/core.hpp>
#include <opencv2/core/utility.hpp>

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <vector>

namespace msf {

namespace {

// Rows per band: the joins across band borders are serial, a row of runs each.
constexpr int kRowsPerBand = 24;

/// Pixels [begin, end) of a row, each connected to the next, in the region `label`.
struct Run {
  std::int32_t begin, end, label;
};

/// Regions as runs with union-find over labels. A label is the index of the pixel that
/// opened it (the first pixel of its first run), so bands label without coordination;
/// `parent` and `size` are indexed by label and only touched where a band opened one.
/// Every link goes to the smaller label, so a root is its set's minimum and parent[l] <= l.
/// A band's runs are stored from its first pixel's index on.
struct Regions {
  std::int32_t* parent;
  std::int32_t* size; // pixels of a label, then (at a root) of its set
  Run* runs;
  std::int32_t* row_first; // per row: index of its first run
  std::int32_t* row_count; // per row: its runs

  std::int32_t find(std::int32_t l) const {
    while (parent[l] != l) {
      parent[l] = parent[parent[l]]; // path halving
      l = parent[l];
    }
    return l;
  }
  std::int32_t root(std::int32_t l) const {
    while (parent[l] != l)
      l = parent[l];
    return l;
  }
  /// Joins two sets without moving sizes (a band's sizes are summed once, in flatten()).
  void link(std::int32_t a, std::int32_t b) const {
    a = find(a);
    b = find(b);
    if (a != b)
      parent[std::max(a, b)] = std::min(a, b);
  }
};

/// Whether some pixel of columns [begin, end) connects row `d` to row `up` (both hold
/// disparities there: they are runs).
bool touches(const std::int16_t* d, const std::int16_t* up, int begin, int end, int max_diff) {
  for (int u = begin; u < end; ++u)
    if (std::abs(d[u] - up[u]) <= max_diff)
      return true;
  return false;
}

/// left[u] = 1 where pixel u connects to pixel u - 1 (a loop the compiler vectorises);
/// left[0] and left[width] are 0, so that a run ends there.
void findLeftLinks(const std::int16_t* d, int width, int new_value, int max_diff, std::uint8_t* left) {
  left[0] = 0;
  for (int u = 1; u < width; ++u)
    left[u] = static_cast<std::uint8_t>((d[u] != new_value) & (d[u - 1] != new_value) &
                                        (std::abs(d[u] - d[u - 1]) <= max_diff));
  left[width] = 0;
}

/// Cuts rows [begin, end) into runs and labels them on their own: a run takes the label of
/// the first run above it that it connects to and joins the others' (a new label if none).
void labelBand(const cv::Mat& image, const Regions& r, int begin, int end, int new_value, int max_diff) {
  const int width = image.cols;
  std::vector<std::uint8_t> left(static_cast<std::size_t>(width) + 1);
  std::int32_t next_run = static_cast<std::int32_t>(static_cast<std::ptrdiff_t>(begin) * width);
  for (int v = begin; v < end; ++v) {
    const std::int16_t* d = image.ptr<std::int16_t>(v);
    const std::int16_t* up = v > begin ? image.ptr<std::int16_t>(v - 1) : nullptr;
    findLeftLinks(d, width, new_value, max_diff, left.data());
    const Run* above = up ? r.runs + r.row_first[v - 1] : nullptr;
    const int above_count = up ? r.row_count[v - 1] : 0;
    int j = 0; // first run above that may overlap the current one
    r.row_first[v] = next_run;
    for (int u = 0; u < width;) {
      if (d[u] == new_value) {
        ++u;
        continue;
      }
      const auto* stop = static_cast<const std::uint8_t*>(std::memchr(left.data() + u + 1, 0, width - u));
      const int run_end = static_cast<int>(stop - left.data());
      std::int32_t l = -1;
      while (j < above_count && above[j].end <= u)
        ++j;
      for (int k = j; k < above_count && above[k].begin < run_end; ++k) {
        const std::int32_t l_above = above[k].label;
        if (l_above == l || !touches(d, up, std::max(u, above[k].begin), std::min(run_end, above[k].end), max_diff))
          continue;
        if (l < 0)
          l = l_above;
        else
          r.link(l, l_above);
      }
      if (l < 0) {
        l = static_cast<std::int32_t>(static_cast<std::ptrdiff_t>(v) * width + u);
        r.parent[l] = l;
        r.size[l] = 0;
      }
      r.size[l] += run_end - u;
      r.runs[next_run++] = Run{u, run_end, l};
      u = run_end;
    }
    r.row_count[v] = next_run - r.row_first[v];
  }
}

/// Points each label the band opened at its root and sums the sizes into the roots: in
/// run order the labels opened come in increasing order, so a label's parent, smaller,
/// already points at its root.
void flatten(const Regions& r, int begin, int end, int width) {
  for (int v = begin; v < end; ++v) {
    const Run* run = r.runs + r.row_first[v];
    for (int i = 0; i < r.row_count[v]; ++i) {
      const std::int32_t l = run[i].label;
      if (l != static_cast<std::int32_t>(static_cast<std::ptrdiff_t>(v) * width + run[i].begin))
        continue; // opened above
      const std::int32_t root = r.parent[r.parent[l]];
      r.parent[l] = root;
      if (root != l)
        r.size[root] += r.size[l];
    }
  }
}

/// Joins the regions that cross from row v - 1 to row v (the first of a band), summing
/// their sizes once.
void joinAcross(const cv::Mat& image, const Regions& r, int v, int max_diff) {
  const std::int16_t* d = image.ptr<std::int16_t>(v);
  const std::int16_t* up = image.ptr<std::int16_t>(v - 1);
  const Run* above = r.runs + r.row_first[v - 1];
  const Run* below = r.runs + r.row_first[v];
  const int above_count = r.row_count[v - 1], below_count = r.row_count[v];
  for (int i = 0, j = 0; i < below_count; ++i) {
    while (j < above_count && above[j].end <= below[i].begin)
      ++j;
    for (int k = j; k < above_count && above[k].begin < below[i].end; ++k) {
      const std::int32_t a = r.find(below[i].label), b = r.find(above[k].label);
      if (a == b || !touches(d, up, std::max(below[i].begin, above[k].begin), std::min(below[i].end, above[k].end),
                             max_diff))
        continue;
      const std::int32_t keep = std::min(a, b), gone = std::max(a, b);
      r.parent[gone] = keep;
      r.size[keep] += r.size[gone];
    }
  }
}

} // namespace

void filterSpecklesParallel(cv::Mat& disparity, int new_value, int max_speckle_size, int max_diff, cv::Mat& buffer) {
  if (disparity.empty() || disparity.type() != CV_16SC1)
    throw InvalidInputError("filterSpecklesParallel: the disparity image must be a non-empty CV_16SC1 image");
  const int rows = disparity.rows, width = disparity.cols;
  const std::size_t pixels = disparity.total();
  static_assert(sizeof(Run) == 3 * sizeof(std::int32_t), "runs are stored as three ints");
  const std::size_t ints = 5 * pixels + 2 * static_cast<std::size_t>(rows);
  if (ints > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidInputError("filterSpecklesParallel: the image is too large");
  buffer.create(1, static_cast<int>(ints), CV_32SC1);
  std::int32_t* base = buffer.ptr<std::int32_t>();
  const Regions r{base, base + pixels, reinterpret_cast<Run*>(base + 2 * pixels), base + 5 * pixels,
                  base + 5 * pixels + rows};

  const int bands = (rows + kRowsPerBand - 1) / kRowsPerBand;
  parallelFor(cv::Range(0, bands), [&](const cv::Range& range) {
    for (int b = range.start; b < range.end; ++b) {
      const int begin = b * kRowsPerBand, end = std::min(begin + kRowsPerBand, rows);
      labelBand(disparity, r, begin, end, new_value, max_diff);
      flatten(r, begin, end, width);
    }
  });
  for (int b = 1; b < bands; ++b)
    joinAcross(disparity, r, b * kRowsPerBand, max_diff);

  parallelFor(cv::Range(0, bands), [&](const cv::Range& range) {
    const int end = std::min(range.end * kRowsPerBand, rows);
    for (int v = range.start * kRowsPerBand; v < end; ++v) {
      std::int16_t* d = disparity.ptr<std::int16_t>(v);
      const Run* run = r.runs + r.row_first[v];
      for (int i = 0; i < r.row_count[v]; ++i)
        if (r.size[r.root(run[i].label)] <= max_speckle_size)
          std::fill(d + run[i].begin, d + run[i].end, static_cast<std::int16_t>(new_value));
    }
  });
}

} // namespace msf
