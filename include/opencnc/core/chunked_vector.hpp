// SPDX-License-Identifier: GPL-3.0-or-later
// An append-only vector stored in fixed-size chunks: growth never copies, so peak memory
// stays at the data size (a doubling vector needs up to 3x while it reallocates). A stream
// that has consumed its front can release it chunk by chunk; indices stay what they were.
#pragma once

#include <algorithm>
#include <cstddef>
#include <memory>
#include <new>
#include <type_traits>
#include <vector>

#include "opencnc/core/prefault.hpp"

namespace opencnc {

/// Append-only sequence with stable element addresses and stable indices. The front can be
/// released (release_before): its elements are gone, the others keep their index. Not
/// thread-safe; non-real-time (push_back allocates one chunk every `kChunk` elements).
template <typename T, std::size_t kChunkShift = 14>
class ChunkedVector {
 public:
  static constexpr std::size_t kChunk = std::size_t{1} << kChunkShift;

  T& push_back(const T& value) {
    T& slot = append_slot();
    slot = value;
    return slot;
  }
  /// Appends an element and returns it to be filled in place; it holds whatever its storage
  /// held, so the caller assigns every member. (Filling in place spares copying a value the
  /// caller has just built member by member, a wide load of narrow stores still in flight.)
  T& append_slot() {
    if ((size_ & (kChunk - 1)) == 0 && (size_ >> kChunkShift) == chunks_.size()) add_chunk();
    T& slot = chunks_[size_ >> kChunkShift].get()[size_ & (kChunk - 1)];
    ++size_;
    return slot;
  }
  /// Appends the `n` values value_of(0) .. value_of(n - 1), written in place (in one run when
  /// they fit in the current chunk).
  template <typename ValueOf>
  void append_with(std::size_t n, ValueOf value_of) {
    const std::size_t offset = size_ & (kChunk - 1);
    if (offset != 0 && offset + n <= kChunk) {
      T* out = chunks_.back().get() + offset;
      for (std::size_t i = 0; i < n; ++i) out[i] = value_of(i);
      size_ += n;
      return;
    }
    for (std::size_t i = 0; i < n; ++i) push_back(value_of(i));
  }
  const T& operator[](std::size_t i) const noexcept { return chunks_[i >> kChunkShift].get()[i & (kChunk - 1)]; }
  T& operator[](std::size_t i) noexcept { return chunks_[i >> kChunkShift].get()[i & (kChunk - 1)]; }
  const T& back() const noexcept { return (*this)[size_ - 1]; }
  /// Elements appended so far (released ones included: the next index).
  std::size_t size() const noexcept { return size_; }
  bool empty() const noexcept { return size_ == 0; }
  void clear() noexcept {
    chunks_.clear();
    size_ = 0;
    released_chunks_ = 0;
    held_chunks_ = 0;
    spare_.reset();
  }
  /// Frees every chunk whose elements all lie before `index`; returns the first index still
  /// held (a multiple of kChunk, at most `index`). Reading a released element is undefined.
  std::size_t release_before(std::size_t index) noexcept {
    const std::size_t last = std::min(index, size_) >> kChunkShift;
    // The chunk being filled stays, even when every element before `index` is in it.
    while (released_chunks_ < last && released_chunks_ + 1 < chunks_.size()) {
      // One freed chunk is kept for the next append: a stream then cycles through the same
      // memory instead of asking the allocator (and the kernel's page faults) every chunk.
      if (!spare_) {
        spare_ = std::move(chunks_[released_chunks_]);
      } else {
        chunks_[released_chunks_].reset();
      }
      ++released_chunks_;
      --held_chunks_;
    }
    return first_held();
  }
  /// The first index not released.
  std::size_t first_held() const noexcept { return released_chunks_ << kChunkShift; }
  /// Bytes held by the elements' chunks (released ones not counted).
  std::size_t capacity_bytes() const noexcept { return held_chunks_ * kChunk * sizeof(T); }

 private:
  static_assert(std::is_trivially_destructible_v<T>, "chunks are freed without running destructors");
  struct FreeChunk {
    void operator()(T* chunk) const noexcept { ::operator delete(chunk); }
  };
  using Chunk = std::unique_ptr<T, FreeChunk>;

  void add_chunk() {
    if (spare_) {
      chunks_.push_back(std::move(spare_));
      ++held_chunks_;
      return;
    }
    Chunk chunk(static_cast<T*>(::operator new(kChunk * sizeof(T))));
    // A vector that has filled a chunk will likely fill the next: map its pages in one system
    // call rather than fault them in one by one (-20 % of the faulting time).
    if (!chunks_.empty()) prefault_for_write(chunk.get(), kChunk * sizeof(T));
    std::uninitialized_default_construct_n(chunk.get(), kChunk);
    chunks_.push_back(std::move(chunk));
    ++held_chunks_;
  }

  std::vector<Chunk> chunks_;  ///< released chunks are null
  std::size_t size_ = 0;
  std::size_t released_chunks_ = 0;
  std::size_t held_chunks_ = 0;
  Chunk spare_;  ///< a released chunk kept for reuse
};

}  // namespace opencnc
