// SPDX-License-Identifier: GPL-3.0-or-later
// An append-only vector stored in fixed-size chunks: growth never copies, so peak memory
// stays at the data size (a doubling vector needs up to 3x while it reallocates).
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <vector>

namespace opencnc {

/// Append-only sequence with stable element addresses. Not thread-safe; non-real-time
/// (push_back allocates one chunk every `kChunk` elements).
template <typename T, std::size_t kChunkShift = 14>
class ChunkedVector {
 public:
  static constexpr std::size_t kChunk = std::size_t{1} << kChunkShift;

  T& push_back(const T& value) {
    if ((size_ & (kChunk - 1)) == 0 && (size_ >> kChunkShift) == chunks_.size()) {
      chunks_.push_back(std::make_unique_for_overwrite<T[]>(kChunk));
    }
    T& slot = chunks_[size_ >> kChunkShift][size_ & (kChunk - 1)];
    slot = value;
    ++size_;
    return slot;
  }
  /// Appends `n` values at once (one copy when they fit in the current chunk).
  void append(const T* values, std::size_t n) {
    const std::size_t offset = size_ & (kChunk - 1);
    if (offset != 0 && offset + n <= kChunk) {
      std::copy_n(values, n, chunks_.back().get() + offset);
      size_ += n;
      return;
    }
    for (std::size_t i = 0; i < n; ++i) push_back(values[i]);
  }
  const T& operator[](std::size_t i) const noexcept { return chunks_[i >> kChunkShift][i & (kChunk - 1)]; }
  T& operator[](std::size_t i) noexcept { return chunks_[i >> kChunkShift][i & (kChunk - 1)]; }
  const T& back() const noexcept { return (*this)[size_ - 1]; }
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  void clear() noexcept {
    chunks_.clear();
    size_ = 0;
  }
  /// Bytes held by the elements' chunks.
  std::size_t capacity_bytes() const noexcept { return chunks_.size() * kChunk * sizeof(T); }

 private:
  std::vector<std::unique_ptr<T[]>> chunks_;
  std::size_t size_ = 0;
};

}  // namespace opencnc
