# SPDX-License-Identifier: GPL-3.0-or-later
# Warning flags shared by every opencnc target.
add_library(opencnc_warnings INTERFACE)
target_compile_options(opencnc_warnings INTERFACE -Wall -Wextra -Wpedantic -Wnon-virtual-dtor
  -Wimplicit-fallthrough)
if(CMAKE_CXX_COMPILER_ID STREQUAL "GNU")
  target_compile_options(opencnc_warnings INTERFACE -Wshadow=local)
else()
  target_compile_options(opencnc_warnings INTERFACE -Wshadow-uncaptured-local)
endif()
if(OPENCNC_WERROR)
  target_compile_options(opencnc_warnings INTERFACE -Werror)
endif()

# opencnc_add_library(name SOURCES...) — a layer library with the project's include root.
function(opencnc_add_library name)
  add_library(${name} STATIC ${ARGN})
  target_include_directories(${name} PUBLIC ${PROJECT_SOURCE_DIR}/include PRIVATE ${CMAKE_CURRENT_SOURCE_DIR})
  target_link_libraries(${name} PRIVATE opencnc_warnings)
endfunction()
