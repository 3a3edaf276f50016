// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// What the host charges for memory a process touches for the first time: one byte written per
// 4 KiB of a fresh 64 MiB anonymous mapping, on 4 KiB pages and on 2 MiB pages
// (MADV_HUGEPAGE), into memory new to the process (every mapping kept until the process ends,
// over the repetitions too: pages the kernel has not handed this process before) and into
// memory it has just given back (unmapped then mapped again: the same pages, at once).
// The TSDF volume's new blocks and the images of a run's first frames are memory of the first
// kind; a host whose hypervisor backs guest memory lazily makes it far dearer than the second,
// and a short run's frame rate feels it. Rates in bytes_per_second; name the host (`lscpu`)
// beside them.
//
//   bench_first_touch [--benchmark_repetitions=5]
#include <benchmark/benchmark.h>

#include <sys/mman.h>

#include <cstddef>
#include <cstdint>
#include <stdexcept>
#include <vector>

namespace {

constexpr std::size_t kHugePage = std::size_t(2) << 20;
constexpr std::size_t kRegion = std::size_t(64) << 20;
constexpr std::size_t kPage = 4096;
constexpr int kNewRegions = 4; // 256 MiB new to the process per repetition

/// A region of kRegion bytes aligned to 2 MiB, on huge pages when asked; the mapping (with its
/// unaligned slack) to unmap.
struct Region {
  void* mapping = nullptr;
  std::size_t mapped = 0;
  char* start = nullptr;

  explicit Region(bool huge) : mapped(kRegion + kHugePage) {
    mapping = mmap(nullptr, mapped, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
    if (mapping == MAP_FAILED)
      throw std::runtime_error("bench_first_touch: mmap failed");
    const auto at = reinterpret_cast<std::uintptr_t>(mapping);
    start = reinterpret_cast<char*>((at + kHugePage - 1) / kHugePage * kHugePage);
    madvise(start, kRegion, huge ? MADV_HUGEPAGE : MADV_NOHUGEPAGE);
  }
  Region(const Region&) = delete;
  Region& operator=(const Region&) = delete;
  Region(Region&& other) noexcept : mapping(other.mapping), mapped(other.mapped), start(other.start) {
    other.mapping = nullptr;
  }
  ~Region() {
    if (mapping)
      munmap(mapping, mapped);
  }

  void touch() {
    for (std::size_t offset = 0; offset < kRegion; offset += kPage)
      start[offset] = 1;
    benchmark::ClobberMemory();
  }
};

/// Each iteration touches a region new to the process; all stay mapped until it ends, so that
/// a repetition does not get back the pages of the one before.
void BM_TouchNewMemory(benchmark::State& state) {
  const bool huge = state.range(0) != 0;
  static std::vector<Region> kept;
  for (auto _ : state) {
    kept.emplace_back(huge);
    kept.back().touch();
  }
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * kRegion));
  state.SetLabel(huge ? "2 MiB pages" : "4 KiB pages");
}

/// Each iteration touches a region mapped afresh where the previous one was just unmapped.
void BM_TouchMemoryGivenBack(benchmark::State& state) {
  const bool huge = state.range(0) != 0;
  Region(huge).touch(); // the pages the loop then gets back
  for (auto _ : state)
    Region(huge).touch();
  state.SetBytesProcessed(static_cast<std::int64_t>(state.iterations() * kRegion));
  state.SetLabel(huge ? "2 MiB pages" : "4 KiB pages");
}

} // namespace

BENCHMARK(BM_TouchNewMemory)->Arg(0)->Arg(1)->Iterations(kNewRegions)->Unit(benchmark::kMillisecond);
BENCHMARK(BM_TouchMemoryGivenBack)->Arg(0)->Arg(1)->Iterations(kNewRegions)->Unit(benchmark::kMillisecond);
BENCHMARK_MAIN();
