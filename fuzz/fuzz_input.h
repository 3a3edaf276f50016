// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
// The readers take paths: each input is written to a file in a private folder on tmpfs
// (/dev/shm when it exists), named as the reader expects.
#include <msf/common/exceptions.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <unistd.h>

namespace msf::fuzz {

inline const std::filesystem::path& folder() {
  static const std::filesystem::path dir = [] {
    const char* base = std::filesystem::is_directory("/dev/shm") ? "/dev/shm" : "/tmp";
    std::filesystem::path p = std::filesystem::path(base) / ("msf_fuzz_" + std::to_string(::getpid()));
    std::filesystem::create_directories(p);
    std::atexit([] {
      std::error_code ec;
      std::filesystem::remove_all(folder(), ec);
    });
    return p;
  }();
  return dir;
}

/// Writes `size` bytes to folder()/name and returns the path.
inline std::string writeInput(const std::string& name, const std::uint8_t* data, std::size_t size) {
  const std::filesystem::path p = folder() / name;
  std::filesystem::create_directories(p.parent_path());
  std::ofstream(p, std::ios::binary | std::ios::trunc).write(reinterpret_cast<const char*>(data),
                                                            static_cast<std::streamsize>(size));
  return p.string();
}

/// Runs `read`; the library's own errors are the expected outcome of a bad input. Anything
/// else (a crash, a sanitizer report, a foreign exception) is a finding.
template <typename F>
void expectOnlyLibraryErrors(F&& read) {
  try {
    read();
  } catch (const msf::Error&) {
  }
}

} // namespace msf::fuzz
