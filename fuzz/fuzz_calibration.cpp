// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// The calibration parsers: KITTI odometry calib.txt, object calib/NNNNNN.txt, raw date folder
// (calib_cam_to_cam.txt + calib_velo_to_cam.txt [+ calib_imu_to_velo.txt]) and the YAML
// camera or rig file (a rig file, detected by its keys, is read with yaml-cpp). The first byte
// picks the format; for a raw folder the rest is split at the bytes "\n===\n" into its files.
#include "fuzz_input.h"

#include <msf/io/calibration.h>

#include <filesystem>
#include <string_view>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1)
    return 0;
  const int format = data[0] % 4;
  const std::string_view body(reinterpret_cast<const char*>(data + 1), size - 1);
  const auto bytes = [](std::string_view s) { return reinterpret_cast<const std::uint8_t*>(s.data()); };
  std::string path;
  if (format == 0) {
    path = msf::fuzz::writeInput("odometry/calib.txt", bytes(body), body.size());
  } else if (format == 1) {
    path = msf::fuzz::writeInput("object/calib/000000.txt", bytes(body), body.size());
  } else if (format == 2) {
    const char* names[] = {"calib_cam_to_cam.txt", "calib_velo_to_cam.txt", "calib_imu_to_velo.txt"};
    std::error_code ec;
    std::filesystem::remove(msf::fuzz::folder() / "raw" / names[2], ec);
    std::string_view rest = body;
    for (int i = 0; i < 3; ++i) {
      const std::size_t cut = rest.find("\n===\n");
      const std::string_view part = rest.substr(0, cut);
      if (i < 2 || !part.empty())
        msf::fuzz::writeInput(std::string("raw/") + names[i], bytes(part), part.size());
      rest = cut == std::string_view::npos ? std::string_view() : rest.substr(cut + 5);
    }
    path = (msf::fuzz::folder() / "raw").string();
  } else {
    path = msf::fuzz::writeInput("camera.yaml", bytes(body), body.size());
  }
  msf::fuzz::expectOnlyLibraryErrors([&] { msf::loadCalibration(path); });
  return 0;
}
