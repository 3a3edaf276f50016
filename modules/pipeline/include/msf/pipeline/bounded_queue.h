// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <chrono>
#include <condition_variable>
#include <cstddef>
#include <deque>
#include <mutex>
#include <optional>

namespace msf {

/// A FIFO of at most `capacity` items between two stages, so memory stays bounded however many
/// frames there are. When it is full, push() waits (a run over a dataset: every frame counts)
/// and pushNewest() drops the oldest item (a live stream: the newest frame counts).
/// close() ends it: pushes refuse, pops drain what is left, then return nothing.
template <typename T>
class BoundedQueue {
public:
  explicit BoundedQueue(std::size_t capacity) : capacity_(capacity > 0 ? capacity : 1) {}

  /// Blocks while full; false (item dropped) when the queue was closed.
  bool push(T item) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_full_.wait(lock, [&] { return closed_ || items_.size() < capacity_; });
    if (closed_)
      return false;
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return true;
  }

  /// Never blocks: when full, the oldest item waiting makes room. Returns whether one was
  /// dropped; false (item dropped) when the queue was closed.
  bool pushNewest(T item) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (closed_)
      return false;
    const bool full = items_.size() >= capacity_;
    if (full)
      items_.pop_front();
    items_.push_back(std::move(item));
    not_empty_.notify_one();
    return full;
  }

  /// Blocks while empty and open; nothing once closed and drained.
  std::optional<T> pop() {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait(lock, [&] { return closed_ || !items_.empty(); });
    return takeFront();
  }

  /// pop() that waits at most `timeout`: nothing when it ran out (or closed and drained).
  template <typename Rep, typename Period>
  std::optional<T> popFor(std::chrono::duration<Rep, Period> timeout) {
    std::unique_lock<std::mutex> lock(mutex_);
    not_empty_.wait_for(lock, timeout, [&] { return closed_ || !items_.empty(); });
    return takeFront();
  }

  /// Whether close() was called and every item taken.
  bool drained() const {
    std::lock_guard<std::mutex> lock(mutex_);
    return closed_ && items_.empty();
  }

  void close() {
    std::lock_guard<std::mutex> lock(mutex_);
    closed_ = true;
    not_full_.notify_all();
    not_empty_.notify_all();
  }

private:
  std::optional<T> takeFront() {
    if (items_.empty())
      return std::nullopt;
    T item = std::move(items_.front());
    items_.pop_front();
    not_full_.notify_one();
    return item;
  }

  const std::size_t capacity_;
  mutable std::mutex mutex_;
  std::condition_variable not_full_, not_empty_;
  std::deque<T> items_;
  bool closed_ = false;
};

} // namespace msf
