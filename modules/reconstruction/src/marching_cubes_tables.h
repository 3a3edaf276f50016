#pragma once

namespace msf::detail {
extern const unsigned int kEdgeTable[256];
extern const int kTriTable[256][16];
} // namespace msf::detail
