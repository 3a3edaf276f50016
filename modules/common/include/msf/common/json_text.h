// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <string>

namespace msf {

/// `s` as a JSON string literal (quotes, backslashes and control characters escaped), for the
/// summary.json files the tools write by hand.
std::string jsonString(const std::string& s);

} // namespace msf
