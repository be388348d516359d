// SPDX-License-Identifier: GPL-3.0-or-later
// The replaced global operator new/delete behind counting_new.hpp.
#include "counting_new.hpp"

#include <cstdlib>
#include <new>

namespace opencnc::test {
std::atomic<bool> g_armed{false};
std::atomic<long> g_allocations{0};
}  // namespace opencnc::test

namespace {
void* counted_alloc(std::size_t n) {
  if (opencnc::test::g_armed.load(std::memory_order_relaxed))
    opencnc::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
}  // namespace

void* operator new(std::size_t n) { return counted_alloc(n); }
void* operator new[](std::size_t n) { return counted_alloc(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
