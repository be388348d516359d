// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc run --journal DIR`: what the journal feature wrote, in the report.
#include "run_journal.hpp"

#include <fmt/format.h>

#include "opencnc/broaching/sim_bore.hpp"

namespace opencnc::cli {

nlohmann::json finish_run_journal(recovery::BreakpointJournal& journal, const std::string& dir,
                                  const std::vector<float>& sim_bore) {
  journal.flush();
  nlohmann::json j;
  const std::optional<recovery::BreakpointRecord> r = journal.last_written();
  const std::vector<double> latencies = journal.latencies_ms();
  const std::string error = journal.last_error();
  j["written"] = r.has_value() && !latencies.empty();
  j["error"] = error.empty() ? nlohmann::json(nullptr) : nlohmann::json(error);
  j["storage"] = journal.writer_status();
  if (!error.empty()) fmt::print(stderr, "error: journal: {}\n", error);
  if (!r || latencies.empty()) {
    fmt::print("journal             no breakpoint written (no power failure during the program)\n");
    return j;
  }
  j["valid"] = r->valid;
  j["stage"] = to_string(r->stage);
  j["segment"] = r->segment;
  j["file"] = r->source_file;
  j["line"] = r->line;
  j["segment_offset_mm"] = r->segment_offset_mm;
  j["move_remaining_mm"] = r->move_remaining_mm;
  j["program_hash"] = fmt::format("{:016x}", r->program_hash);
  j["modal_digest"] = fmt::format("{:016x}", r->modal_digest);
  j["record_latency_ms"] = latencies.front();
  fmt::print("journal             {}\n", describe(*r));
  fmt::print("journal latency     {:.3f} ms from the signal to the durable record\n", latencies.front());
  fmt::print("journal storage     {}\n", journal.writer_status());
  j["sim_bore"] = false;
  if (!sim_bore.empty()) {
    // The simulated workpiece keeps its groove across the restart, as a real one does.
    std::string bore_error;
    if (recovery::save_sim_bore(dir, {r->program_hash, r->signal_time_s, sim_bore}, &bore_error)) {
      j["sim_bore"] = true;
    } else {
      fmt::print(stderr, "warning: journal: the simulated bore was not kept: {}\n", bore_error);
    }
  }
  return j;
}

}  // namespace opencnc::cli
