#pragma once
#include <msf/common/exceptions.h>

#include <string>

namespace msf::test {

/// The message of the msf::Error that `f` throws, or "(no error)": tests of hostile inputs
/// check that the message names the option, key or file at fault.
template <typename F>
std::string errorOf(F&& f) {
  try {
    f();
  } catch (const msf::Error& e) {
    return e.what();
  }
  return "(no error)";
}

} // namespace msf::test
