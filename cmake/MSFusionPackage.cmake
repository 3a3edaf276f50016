# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# Installs and exports the CMake package: find_package(MSFusion), or find_package(msfusion),
# gives MSFusion::<module>.
include(CMakePackageConfigHelpers)
get_property(MSF_EXPORTED_MODULES GLOBAL PROPERTY MSF_MODULE_TARGETS)
string(REPLACE "msf_" "" MSF_EXPORTED_MODULES "${MSF_EXPORTED_MODULES}")

install(EXPORT MSFusionTargets NAMESPACE MSFusion:: DESTINATION lib/cmake/MSFusion)
configure_package_config_file(${PROJECT_SOURCE_DIR}/cmake/MSFusionConfig.cmake.in
  ${PROJECT_BINARY_DIR}/MSFusionConfig.cmake INSTALL_DESTINATION lib/cmake/MSFusion)
write_basic_package_version_file(${PROJECT_BINARY_DIR}/MSFusionConfigVersion.cmake
  VERSION ${PROJECT_VERSION} COMPATIBILITY SameMajorVersion)
install(FILES ${PROJECT_BINARY_DIR}/MSFusionConfig.cmake
  ${PROJECT_BINARY_DIR}/MSFusionConfigVersion.cmake DESTINATION lib/cmake/MSFusion)
# find_package(msfusion) too: CMake matches the folder's name in any case, the file's exactly.
install(FILES ${PROJECT_SOURCE_DIR}/cmake/msfusion-config.cmake DESTINATION lib/cmake/MSFusion)
install(FILES ${PROJECT_BINARY_DIR}/MSFusionConfigVersion.cmake DESTINATION lib/cmake/MSFusion
  RENAME msfusion-config-version.cmake)
install(DIRECTORY ${PROJECT_SOURCE_DIR}/config/ DESTINATION share/msfusion/config)
