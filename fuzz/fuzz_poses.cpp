// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// KITTI odometry poses (poses/XX.txt) and raw OXTS records (oxts/data/*.txt, one a file).
#include "fuzz_input.h"

#include <msf/io/poses.h>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  if (data[0] & 1) {
    const std::string path = msf::fuzz::writeInput("poses.txt", data + 1, size - 1);
    msf::fuzz::expectOnlyLibraryErrors([&] { msf::loadOdometryPoses(path); });
  } else {
    msf::fuzz::writeInput("oxts/0000000000.txt", data + 1, size - 1);
    msf::fuzz::expectOnlyLibraryErrors([&] { msf::loadOxts((msf::fuzz::folder() / "oxts").string()); });
  }
  return 0;
}
