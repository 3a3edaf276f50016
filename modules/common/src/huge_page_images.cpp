// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/huge_page_images.h>

#include <opencv2/core.hpp>

#include <sys/mman.h>

#include <algorithm>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <string>
#include <vector>

namespace msf {

namespace {
constexpr std::size_t kHugePage = std::size_t(2) << 20;
// A smaller image would leave most of its 2 MiB page unused: a camera's float image is 1.8 MiB.
constexpr std::size_t kMinBytes = std::size_t(1) << 20;
// Enough for the images a frame's stages free and the next frames allocate again; more would
// hold memory without being reused.
constexpr std::size_t kCachedBytes = std::size_t(64) << 20;

std::size_t roundUpToHugePages(std::size_t bytes) { return (bytes + kHugePage - 1) / kHugePage * kHugePage; }

/// A mapping of `bytes` (a multiple of 2 MiB) aligned to 2 MiB, or nullptr: a larger one, its
/// unaligned head and tail given back.
void* mapAligned(std::size_t bytes) {
  void* raw = mmap(nullptr, bytes + kHugePage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (raw == MAP_FAILED)
    return nullptr;
  const auto start = reinterpret_cast<std::uintptr_t>(raw);
  const std::uintptr_t aligned = (start + kHugePage - 1) / kHugePage * kHugePage;
  if (aligned > start)
    munmap(raw, aligned - start);
  if (const std::size_t tail = start + kHugePage - aligned; tail > 0)
    munmap(reinterpret_cast<void*>(aligned + bytes), tail);
  void* p = reinterpret_cast<void*>(aligned);
  madvise(p, bytes, MADV_HUGEPAGE);
  return p;
}

/// Freed images' mappings, kept for the next images of their size: a mapping reused costs
/// neither a fault nor the kernel's zeroing of its pages. At most kCachedBytes in all.
class MappingCache {
public:
  void* take(std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    const auto it = std::find_if(free_.begin(), free_.end(), [bytes](const auto& m) { return m.bytes == bytes; });
    if (it == free_.end())
      return nullptr;
    void* p = it->address;
    cached_ -= bytes;
    *it = free_.back();
    free_.pop_back();
    return p;
  }
  /// False when the cache is full: the caller unmaps it.
  bool keep(void* address, std::size_t bytes) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (cached_ + bytes > kCachedBytes)
      return false;
    free_.push_back({address, bytes});
    cached_ += bytes;
    return true;
  }

private:
  struct Mapping {
    void* address;
    std::size_t bytes;
  };
  std::mutex mutex_;
  std::vector<Mapping> free_;
  std::size_t cached_ = 0;
};

/// cv::Mat's allocator for large images; the others, and user data, go to OpenCV's own.
class HugePageAllocator final : public cv::MatAllocator {
public:
  cv::UMatData* allocate(int dims, const int* sizes, int type, void* data, std::size_t* step, cv::AccessFlag flags,
                         cv::UMatUsageFlags usage) const override {
    std::size_t bytes = CV_ELEM_SIZE(type);
    for (int i = 0; i < dims; ++i)
      bytes *= static_cast<std::size_t>(sizes[i]);
    void* mapped = nullptr;
    if (!data && bytes >= kMinBytes) {
      const std::size_t mapping = roundUpToHugePages(bytes);
      mapped = cache_.take(mapping);
      if (!mapped)
        mapped = mapAligned(mapping);
    }
    if (!mapped)
      return std_->allocate(dims, sizes, type, data, step, flags, usage);
    if (step)
      for (std::size_t i = static_cast<std::size_t>(dims), stride = CV_ELEM_SIZE(type); i-- > 0;) {
        step[i] = stride;
        stride *= static_cast<std::size_t>(sizes[i]);
      }
    auto* u = new cv::UMatData(this);
    u->data = u->origdata = static_cast<uchar*>(mapped);
    u->size = bytes;
    return u;
  }

  bool allocate(cv::UMatData* u, cv::AccessFlag, cv::UMatUsageFlags) const override { return u != nullptr; }

  void deallocate(cv::UMatData* u) const override {
    if (!u)
      return;
    const std::size_t mapping = roundUpToHugePages(u->size);
    if (!cache_.keep(u->origdata, mapping))
      munmap(u->origdata, mapping);
    delete u;
  }

private:
  cv::MatAllocator* std_ = cv::Mat::getStdAllocator();
  mutable MappingCache cache_;
};

bool transparentHugePagesOnRequest() {
  std::ifstream file("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(file, modes);
  return modes.find("[always]") != std::string::npos || modes.find("[madvise]") != std::string::npos;
}
} // namespace

void useHugePagesForLargeImages() {
  if (!transparentHugePagesOnRequest())
    return;
  // Never destroyed: an image freed during the process's exit still finds its allocator.
  static auto* allocator = new HugePageAllocator;
  cv::Mat::setDefaultAllocator(allocator);
}

} // namespace msf
