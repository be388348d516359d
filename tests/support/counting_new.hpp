// SPDX-License-Identifier: GPL-3.0-or-later
// Counts heap allocations while armed: the global operator new of a no-allocation test binary
// (link counting_new.cpp into it), so a test can assert that a real-time path allocates nothing.
#pragma once

#include <atomic>

namespace opencnc::test {

/// True while allocations are counted (the test thread arms it around the code under test).
extern std::atomic<bool> g_armed;
/// Allocations made while armed.
extern std::atomic<long> g_allocations;

}  // namespace opencnc::test
