#include <msf/common/parallel_for.h>

#include <gtest/gtest.h>
#include <omp.h>
#include <opencv2/core/utility.hpp>

#include <atomic>
#include <chrono>
#include <stdexcept>
#include <thread>
#include <vector>

namespace {

/// Calls f with `threads` as this thread's OpenMP team size, then restores it.
template <typename F>
void withTeam(int threads, F&& f) {
  const int saved = omp_get_max_threads();
  omp_set_num_threads(threads);
  f();
  omp_set_num_threads(saved);
}

TEST(ParallelFor, EveryIndexOnceWhateverTheStripes) {
  for (const double stripes : {-1.0, 0.0, 1.0, 3.0, 7.4, 1000.0}) {
    std::vector<std::atomic<int>> hits(101);
    msf::parallelFor(cv::Range(-50, 51), [&](const cv::Range& r) {
      ASSERT_LT(r.start, r.end);
      for (int i = r.start; i < r.end; ++i)
        ++hits[static_cast<std::size_t>(i + 50)];
    }, stripes);
    for (std::size_t i = 0; i < hits.size(); ++i)
      EXPECT_EQ(hits[i].load(), 1) << "index " << static_cast<int>(i) - 50 << ", stripes " << stripes;
  }
}

TEST(ParallelFor, EmptyRangeCallsNothing) {
  int calls = 0;
  msf::parallelFor(cv::Range(5, 5), [&](const cv::Range&) { ++calls; });
  msf::parallelFor(cv::Range(5, 2), [&](const cv::Range&) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, AnExceptionReachesTheCallerAfterEveryPiece) {
  std::atomic<int> done{0};
  withTeam(2, [&] {
    EXPECT_THROW(msf::parallelFor(cv::Range(0, 8), [&](const cv::Range& r) {
      ++done;
      if (r.start == 3)
        throw std::runtime_error("piece 3");
    }, 8), std::runtime_error);
  });
  EXPECT_EQ(done.load(), 8);
}

/// Runs `calls` calls of parallelFor at once, from as many threads, each cut into 2 pieces;
/// true when all their pieces ran at the same time (each waits up to 2 s for all to start).
template <typename For>
bool allPiecesOverlap(int calls, For&& parallel_for) {
  std::atomic<int> started{0};
  std::atomic<bool> overlapped{true};
  std::vector<std::thread> threads;
  for (int c = 0; c < calls; ++c)
    threads.emplace_back([&] {
      withTeam(2, [&] {
        parallel_for(cv::Range(0, 2), [&](const cv::Range&) {
          ++started;
          const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(2);
          while (started.load() < 2 * calls)
            if (std::chrono::steady_clock::now() > deadline) {
              overlapped = false;
              return;
            }
        });
      });
    });
  for (auto& t : threads)
    t.join();
  return overlapped.load();
}

// What cv::parallel_for_ does not do: two threads' calls at once both run in parallel
// (OpenCV's one process-wide flag runs the second serially in its caller).
TEST(ParallelFor, CallsFromTwoThreadsAtOnceAreBothParallel) {
  if (std::thread::hardware_concurrency() < 2)
    GTEST_SKIP() << "needs 2 cores";
  EXPECT_TRUE(allPiecesOverlap(1, [](const cv::Range& r, auto&& body) { msf::parallelFor(r, body, 2); }));
  EXPECT_TRUE(allPiecesOverlap(2, [](const cv::Range& r, auto&& body) { msf::parallelFor(r, body, 2); }));
}

} // namespace
