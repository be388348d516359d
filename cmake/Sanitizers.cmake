# SPDX-License-Identifier: GPL-3.0-or-later
# ASan + UBSan for the whole tree when OPENCNC_SANITIZE is on (CI runs the suite this way too).
if(OPENCNC_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()

# opencnc_plain_twin(target) — under the sanitizers, the library once more without instrumentation,
# as <target>_plain (same sources, definitions, include folders and optimisation; its links to our
# libraries mapped to their twins). rtapi_app cannot load an instrumented module, so the HAL component links
# the real-time core's twins: one sanitized build then runs the HAL tests too, against the
# sanitized controller. Elsewhere it does nothing.
function(opencnc_plain_twin target)
  if(NOT OPENCNC_SANITIZE)
    return()
  endif()
  get_target_property(sources ${target} SOURCES)
  add_library(${target}_plain STATIC ${sources})
  foreach(p INCLUDE_DIRECTORIES INTERFACE_INCLUDE_DIRECTORIES COMPILE_DEFINITIONS COMPILE_OPTIONS
            POSITION_INDEPENDENT_CODE)
    get_target_property(value ${target} ${p})
    if(value)
      set_property(TARGET ${target}_plain PROPERTY ${p} "${value}")
    endif()
  endforeach()
  opencnc_strip_sanitizers(${target}_plain)
  # Links to our libraries become links to their twins, which may be made later (every library the
  # real-time core links has one: its closure is checked); build settings stay.
  foreach(p LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
    get_target_property(links ${target} ${p})
    if(links)
      list(TRANSFORM links REPLACE "(opencnc_[a-z_]+)" "\\1_plain")
      list(TRANSFORM links REPLACE "opencnc_warnings_plain" "opencnc_warnings")
      set_property(TARGET ${target}_plain PROPERTY ${p} "${links}")
    endif()
  endforeach()
endfunction()

# opencnc_strip_sanitizers(target) — the sanitizers' compile and link flags off for one target.
function(opencnc_strip_sanitizers target)
  get_target_property(options ${target} COMPILE_OPTIONS)
  if(options)
    list(FILTER options EXCLUDE REGEX "sanitize")
    set_property(TARGET ${target} PROPERTY COMPILE_OPTIONS "${options}")
  endif()
  get_target_property(options ${target} LINK_OPTIONS)
  if(options)
    list(FILTER options EXCLUDE REGEX "sanitize")
    set_property(TARGET ${target} PROPERTY LINK_OPTIONS "${options}")
  endif()
endfunction()
