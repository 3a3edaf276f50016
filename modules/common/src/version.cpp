// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#include <msf/common/version.h>

const char* msf::versionString() { return MSF_VERSION_STRING; }
