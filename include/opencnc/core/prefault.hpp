// SPDX-License-Identifier: GPL-3.0-or-later
// Prefaulting: fresh memory that will all be written, mapped in one system call.
#pragma once

#include <cstddef>

namespace opencnc {

/// Has the kernel map the whole pages inside [p, p + bytes) for writing at once (Linux's
/// MADV_POPULATE_WRITE), which costs less than the page fault per 4 KiB that writing them
/// one by one takes. A hint: does nothing where unsupported. Any thread; not real-time safe.
void prefault_for_write(void* p, std::size_t bytes) noexcept;

}  // namespace opencnc
