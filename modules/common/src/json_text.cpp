// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/json_text.h>

#include <cstdio>

namespace msf {

std::string jsonString(const std::string& s) {
  std::string out = "\"";
  for (char c : s) {
    if (c == '"' || c == '\\')
      out += '\\', out += c;
    else if (static_cast<unsigned char>(c) < 0x20) {
      char buf[8];
      std::snprintf(buf, sizeof buf, "\\u%04x", c);
      out += buf;
    } else
      out += c;
  }
  return out + "\"";
}

} // namespace msf
