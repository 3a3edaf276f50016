// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A program that makes a real sanitizer report, built with -fsanitize=address,undefined in every
// build (tests/CMakeLists.txt), so that the tests of the report check (sanitizerReport, runCommand,
// bad_inputs.sh --sanitizer-report) read what AddressSanitizer, LeakSanitizer and
// UndefinedBehaviorSanitizer print, not a text written to look like it.
//
//   msf_sanitizer_report_helper ubsan|heap-overflow|leak|clean
//
// ubsan: a signed integer overflow; built with -fsanitize-recover=undefined, it carries on and
// exits 0 unless UBSAN_OPTIONS says halt_on_error=1. heap-overflow: a write past a heap block
// (ASan stops the program). leak: a block never freed (LSan reports it at exit). clean: nothing.
#include <climits>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>

int main(int argc, char** argv) {
  const std::string mode = argc > 1 ? argv[1] : "";
  std::fprintf(stderr, "msf_sanitizer_report_helper: %s\n", mode.c_str());
  if (mode == "ubsan") {
    volatile int largest = INT_MAX;
    const int sum = largest + argc; // overflows: argc >= 2
    std::printf("%d\n", sum);
  } else if (mode == "heap-overflow") {
    char* volatile block = static_cast<char*>(std::malloc(8));
    volatile int past = 8;
    block[past] = 1; // one byte past the block
    std::printf("%d\n", block[0]);
    std::free(block);
  } else if (mode == "leak") {
    void* volatile block = std::malloc(4096);
    std::printf("%p\n", block);
    block = nullptr;
  } else if (mode != "clean") {
    std::fprintf(stderr, "usage: msf_sanitizer_report_helper ubsan|heap-overflow|leak|clean\n");
    return 2;
  }
  return 0;
}
