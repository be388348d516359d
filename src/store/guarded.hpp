// SPDX-License-Identifier: GPL-3.0-or-later
// The stores' calls that answer with an error text instead of throwing.
#pragma once

#include <exception>
#include <string>

namespace opencnc::store::detail {

/// f()'s value; on an exception, its text in `error` (if given) and an empty value (nullopt, false).
template <class F>
auto guarded(std::string* error, F&& f) -> decltype(f()) {
  try {
    return f();
  } catch (const std::exception& ex) {
    if (error != nullptr) *error = ex.what();
    return {};
  }
}

}  // namespace opencnc::store::detail
