#pragma once
// parallelFor: cv::parallel_for_'s contract on OpenMP threads.
#include <opencv2/core/types.hpp>

#include <omp.h>

#include <algorithm>
#include <cmath>
#include <exception>
#include <mutex>

namespace msf {

/// Calls body(piece) for the pieces of `range` cut into `stripes` (16 per thread when <= 0),
/// in parallel on this thread's OpenMP team, as cv::parallel_for_ does on OpenCV's pool.
/// Why not cv::parallel_for_: OpenCV keeps one flag for the whole process, so a call made
/// while another thread's call runs is run serially by its caller. In the pipeline, TSDF
/// integration on one thread and SGBM on another would then take turns at one core each,
/// and leave the other core idle once one of them ends; a team per calling thread lets both
/// spread over the cores. Guided scheduling: neighbouring pieces (neighbouring memory) in
/// large chunks first, small ones at the end for the balance. The first exception a piece
/// throws is rethrown here, once every piece has ended.
template <typename Body>
void parallelFor(const cv::Range& range, Body&& body, double stripes = -1.0) {
  const long long length = static_cast<long long>(range.end) - range.start;
  if (length <= 0)
    return;
  const double wanted = stripes > 0.0 ? std::round(stripes) : 16.0 * omp_get_max_threads();
  const int pieces = static_cast<int>(std::clamp<double>(wanted, 1.0, static_cast<double>(length)));
  std::exception_ptr failure;
  std::mutex failure_mutex;
#pragma omp parallel for schedule(guided) if (pieces > 1)
  for (int i = 0; i < pieces; ++i) {
    const cv::Range piece(range.start + static_cast<int>(length * i / pieces),
                          range.start + static_cast<int>(length * (i + 1) / pieces));
    try {
      body(piece);
    } catch (...) {
      const std::lock_guard<std::mutex> lock(failure_mutex);
      if (!failure)
        failure = std::current_exception();
    }
  }
  if (failure)
    std::rethrow_exception(failure);
}

} // namespace msf
