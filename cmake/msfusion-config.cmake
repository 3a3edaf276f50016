# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# find_package(msfusion): on a case-sensitive file system CMake looks for this name, not
# MSFusionConfig.cmake, when the package is spelled in lower case. The same package.
include("${CMAKE_CURRENT_LIST_DIR}/MSFusionConfig.cmake")
