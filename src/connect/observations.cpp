// SPDX-License-Identifier: GPL-3.0-or-later
// The agent's observation buffer: bounded, sequence-numbered, with the state at any retained point.
#include "opencnc/connect/observations.hpp"

#include <algorithm>
#include <stdexcept>

namespace opencnc::connect {

const char* to_string(Level l) noexcept {
  switch (l) {
    case Level::Unavailable:
      return "Unavailable";
    case Level::Normal:
      return "Normal";
    case Level::Warning:
      return "Warning";
    case Level::Fault:
      return "Fault";
  }
  return "Unavailable";
}

ObservationBuffer::ObservationBuffer(std::size_t items, std::size_t capacity)
    : capacity_(std::max<std::size_t>(capacity, 1)), current_(items), before_first_(items) {
  for (std::size_t i = 0; i < items; ++i) {
    current_[i].last.item = static_cast<std::uint32_t>(i);
    current_[i].last.value = "UNAVAILABLE";
  }
  before_first_ = current_;
}

void ObservationBuffer::apply(std::vector<ItemState>& state, const Observation& o) {
  ItemState& s = state[o.item];
  s.last = o;
  if (o.level == Level::Warning || o.level == Level::Fault) {
    auto same = std::find_if(s.active.begin(), s.active.end(),
                             [&](const Observation& a) { return a.native_code == o.native_code; });
    if (same != s.active.end())
      *same = o;
    else
      s.active.push_back(o);
  } else if (o.level == Level::Normal && !o.native_code.empty()) {
    std::erase_if(s.active, [&](const Observation& a) { return a.native_code == o.native_code; });
  } else {
    s.active.clear();  // a Normal without a code clears them all; Unavailable too
  }
}

std::uint64_t ObservationBuffer::add(Observation o) {
  if (o.item >= current_.size()) throw std::out_of_range("connect: observation of an unknown data item");
  o.sequence = next_++;
  apply(current_, o);
  if (buffer_.size() == capacity_) {
    apply(before_first_, buffer_.front());
    buffer_.pop_front();
    ++first_;
  }
  buffer_.push_back(std::move(o));
  return next_ - 1;
}

const Observation& ObservationBuffer::at(std::uint64_t sequence) const {
  if (sequence < first_ || sequence >= next_) throw std::out_of_range("connect: sequence not in the buffer");
  return buffer_[static_cast<std::size_t>(sequence - first_)];
}

std::vector<ItemState> ObservationBuffer::state_at(std::uint64_t sequence) const {
  if (sequence + 1 < first_ || sequence >= next_)
    throw std::out_of_range("connect: sequence not in the buffer");
  std::vector<ItemState> state = before_first_;
  for (std::uint64_t s = first_; s <= sequence; ++s) apply(state, at(s));
  return state;
}

}  // namespace opencnc::connect
