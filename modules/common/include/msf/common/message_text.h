// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <opencv2/core/mat.hpp>

#include <cstddef>
#include <sstream>
#include <string>

/// How an error message shows the values it names.
namespace msf {

/// A value as a message quotes it: 'text' as given, or its first characters and its length
/// when it is long (a 5-million-digit number is named, not printed whole).
inline std::string quoted(const std::string& text) {
  constexpr std::size_t kLongest = 40, kShown = 24;
  if (text.size() <= kLongest)
    return "'" + text + "'";
  return "'" + text.substr(0, kShown) + "...' (" + std::to_string(text.size()) + " characters)";
}

/// A number as a message shows it: 6 significant digits, as %g (1e-09, 990000, 0.5).
inline std::string number(double value) {
  std::ostringstream s;
  s << value;
  return s.str();
}

/// An image's size as a message shows it: "1242x375" (width x height).
inline std::string sizeText(const cv::Size& size) {
  return std::to_string(size.width) + "x" + std::to_string(size.height);
}
inline std::string sizeText(const cv::Mat& image) { return sizeText(image.size()); }

} // namespace msf
