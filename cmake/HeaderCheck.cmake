# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# With MSF_CHECK_HEADERS, the target msf_header_check compiles each public header of the modules
# built, alone in a file of its own and without the precompiled headers: a header that does not
# include what it uses fails there, as it would in a consumer's file (make test-sanitize-fast
# builds it).
option(MSF_CHECK_HEADERS "Add the target msf_header_check: each public header compiled alone" OFF)

# Call it once every module's target exists.
function(msf_add_header_check)
  if(NOT MSF_CHECK_HEADERS)
    return()
  endif()
  set(sources)
  set(modules)
  foreach(module ${MSF_MODULES})
    if(NOT TARGET msf_${module})
      continue()
    endif()
    list(APPEND modules msf_${module})
    set(include_dir ${PROJECT_SOURCE_DIR}/modules/${module}/include)
    file(GLOB_RECURSE headers RELATIVE ${include_dir} CONFIGURE_DEPENDS ${include_dir}/msf/*.h)
    foreach(header ${headers})
      string(MAKE_C_IDENTIFIER ${header} name)
      set(source ${PROJECT_BINARY_DIR}/header_check/${name}.cpp)
      file(CONFIGURE OUTPUT ${source} CONTENT "#include <${header}>\n")
      list(APPEND sources ${source})
    endforeach()
  endforeach()
  add_library(msf_header_check OBJECT EXCLUDE_FROM_ALL ${sources})
  # The modules' usage requirements (include folders, definitions), not their builds.
  target_link_libraries(msf_header_check PRIVATE ${modules})
  set_target_properties(msf_header_check PROPERTIES DISABLE_PRECOMPILE_HEADERS ON OPTIMIZE_DEPENDENCIES ON)
  msf_set_warnings(msf_header_check)
endfunction()
