// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <msf/common/exceptions.h>

#include <atomic>
#include <string>
#include <thread>

namespace msf {

/// Held through a call of an object that takes one call at a time (Reconstructor): takes the
/// object for this thread, and throws Error naming the call when another thread holds it, or
/// when this one does and the call may not nest (`nests`: mesh(), which run()'s callback may call).
class OneCaller {
public:
  OneCaller(std::atomic<std::thread::id>& holder, const char* call, bool nests = false) {
    const std::thread::id me = std::this_thread::get_id();
    std::thread::id held_by;
    if (holder.compare_exchange_strong(held_by, me)) {
      holder_ = &holder;
      return;
    }
    const std::string what = std::string("msf::Reconstructor::") + call + " was called ";
    if (held_by != me)
      throw Error(what + "while another thread is in a call of the same engine: it takes one call at a time; guard "
                         "it with a mutex, or give each thread its own engine");
    if (!nests)
      throw Error(what + "within another call of the same engine (run()'s callback): only mesh() may be");
  }
  ~OneCaller() {
    if (holder_)
      holder_->store(std::thread::id());
  }
  OneCaller(const OneCaller&) = delete;
  OneCaller& operator=(const OneCaller&) = delete;

private:
  std::atomic<std::thread::id>* holder_ = nullptr; // set when this call took the object
};

} // namespace msf
