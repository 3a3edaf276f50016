// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
// A configuration file, read as every tool reads one: the whole file checked (sections, keys,
// values) and PipelineConfig read from it. Inputs reach yaml-cpp's depth guard (see make fuzz's
// max_len for this target).
#include "fuzz_input.h"

#include <msf/pipeline/config_catalog.h>
#include <msf/pipeline/pipeline_config.h>

#include <string>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string text(reinterpret_cast<const char*>(data), size);
  msf::fuzz::expectOnlyLibraryErrors([&] {
    msf::PipelineConfig config;
    config.read(msf::openConfigText(text, "fuzz.yaml"));
  });
  return 0;
}
