# SPDX-License-Identifier: GPL-3.0-or-later
# opencnc_check_realtime_closure(target) — fails the configure step when the target's link closure
# reaches a library the real-time core must not link: fmt and opencnc_core (formatting, files:
# they allocate), threads, or any non-real-time layer. Only opencnc_traj, opencnc_motion and
# build-setting targets (opencnc_warnings, sanitizers) may appear.
set(OPENCNC_REALTIME_ALLOWED opencnc_rtcore opencnc_traj opencnc_motion opencnc_warnings opencnc_sanitizers)

function(_opencnc_collect_links target out_var)
  set(seen ${${out_var}})
  foreach(prop LINK_LIBRARIES INTERFACE_LINK_LIBRARIES)
    get_target_property(libs ${target} ${prop})
    if(NOT libs)
      continue()
    endif()
    foreach(lib IN LISTS libs)
      string(REGEX REPLACE "^\\$<LINK_ONLY:(.*)>$" "\\1" lib "${lib}")
      if(lib IN_LIST seen)
        continue()
      endif()
      list(APPEND seen ${lib})
      if(TARGET ${lib})
        _opencnc_collect_links(${lib} seen)
      endif()
    endforeach()
  endforeach()
  set(${out_var} ${seen} PARENT_SCOPE)
endfunction()

function(opencnc_check_realtime_closure target)
  set(links "")
  _opencnc_collect_links(${target} links)
  foreach(lib IN LISTS links)
    if(NOT lib IN_LIST OPENCNC_REALTIME_ALLOWED AND NOT lib MATCHES "^-fsanitize|^\\$<")
      message(FATAL_ERROR "${target} is the real-time core and must not link '${lib}' "
                          "(allowed: ${OPENCNC_REALTIME_ALLOWED}); see docs/code-overview.md")
    endif()
  endforeach()
endfunction()
