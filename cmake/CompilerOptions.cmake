# Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
# One place for the warnings every target of ours is built with (as errors).
option(MSF_WARNINGS_AS_ERRORS "Treat compiler warnings as errors" ON)

function(msf_set_compiler_options target)
  target_compile_options(${target} PRIVATE
    $<$<CXX_COMPILER_ID:GNU,Clang>:-Wall -Wextra -Wpedantic -Wshadow=local -Wnon-virtual-dtor
      -Wno-deprecated-declarations>)
  if(MSF_WARNINGS_AS_ERRORS)
    target_compile_options(${target} PRIVATE $<$<CXX_COMPILER_ID:GNU,Clang>:-Werror>)
  endif()
endfunction()
