// SPDX-License-Identifier: GPL-3.0-or-later
// A PathIndex filled from a preflight scan: a MoveCheck that takes every move instead of judging it.
#include "opencnc/retrace/path_scan.hpp"

namespace opencnc::recovery {

namespace {

/// Adds the moves of the scan to the index. A preflight of a program with sync points scans it
/// twice (the second time beside a scan with other answers): the second pass starts again at
/// move 0 and replaces the first.
class IndexingCheck final : public controller::MoveCheck {
 public:
  bool check(const canon::Program& program, canon::SegmentId move, Diagnostics& /*diags*/) override {
    if (move < next_) index_ = PathIndex{};
    index_.add(program, move);
    next_ = move + 1;
    return true;
  }
  PathIndex take() { return std::move(index_); }

 private:
  PathIndex index_;
  canon::SegmentId next_ = 0;
};

}  // namespace

PathIndex scan_path(controller::ProgramSource& source, const std::string& path, const Pose& start,
                    const controller::LoadOptions& options, Diagnostics& diags) {
  IndexingCheck check;
  const controller::Preflight p = source.preflight(path, start, options, check);
  for (const Diagnostic& d : p.diagnostics.items()) diags.add(d);
  PathIndex index = check.take();
  index.finish();
  return index;
}

}  // namespace opencnc::recovery
