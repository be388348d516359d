# SPDX-License-Identifier: GPL-3.0-or-later
# ASan + UBSan for the whole tree when OPENCNC_SANITIZE is on (CI runs the suite this way too).
if(OPENCNC_SANITIZE)
  add_compile_options(-fsanitize=address,undefined -fno-omit-frame-pointer -fno-sanitize-recover=undefined)
  add_link_options(-fsanitize=address,undefined)
endif()
