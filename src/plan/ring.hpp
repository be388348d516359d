// SPDX-License-Identifier: GPL-3.0-or-later
// Ring — a first-in first-out sequence in one growing array, for the planner's windows.
#pragma once

#include <cstddef>
#include <utility>
#include <vector>

namespace opencnc::plan::detail {

/// Appends at the back, removes at the front, indexes from the front, and (rarely) inserts in
/// the middle. Unlike std::deque, which gives an element of more than 512 bytes a node of its
/// own (an allocation per block), it allocates only when it grows past its largest size so far.
/// Non-real-time (growing allocates).
template <typename T>
class Ring {
 public:
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }

  T& operator[](std::size_t i) noexcept { return slots_[(head_ + i) & mask_]; }
  const T& operator[](std::size_t i) const noexcept { return slots_[(head_ + i) & mask_]; }
  T& front() noexcept { return (*this)[0]; }
  const T& front() const noexcept { return (*this)[0]; }
  T& back() noexcept { return (*this)[size_ - 1]; }
  const T& back() const noexcept { return (*this)[size_ - 1]; }

  /// The slot after the last element, holding whatever it held before, to be filled in place
  /// and then added with commit_spare().
  T& spare() {
    if (size_ == slots_.size()) grow();
    return (*this)[size_];
  }
  void commit_spare() noexcept { ++size_; }
  /// A new last element, holding whatever the slot held before: the caller sets every field.
  T& append() {
    T& slot = spare();
    commit_spare();
    return slot;
  }
  void push_back(const T& v) { append() = v; }
  void pop_front() noexcept {
    head_ = (head_ + 1) & mask_;
    --size_;
  }
  /// Inserts `v` before element `pos` (pos ≤ size()), moving the later elements back by one.
  void insert(std::size_t pos, const T& v) {
    append();
    for (std::size_t i = size_ - 1; i > pos; --i) (*this)[i] = (*this)[i - 1];
    (*this)[pos] = v;
  }
  void clear() noexcept { head_ = size_ = 0; }

 private:
  void grow() {
    std::vector<T> bigger(slots_.empty() ? 16 : 2 * slots_.size());
    for (std::size_t i = 0; i < size_; ++i) bigger[i] = std::move((*this)[i]);
    slots_.swap(bigger);
    head_ = 0;
    mask_ = slots_.size() - 1;
  }

  std::vector<T> slots_;  // a power of two in size
  std::size_t head_ = 0, size_ = 0, mask_ = 0;
};

}  // namespace opencnc::plan::detail
