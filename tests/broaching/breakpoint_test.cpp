// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint record: its serialisation (round trip, checksum, version, truncation), the journal
// feature writing it through the whole controller when the mains fail on the broach (at the signal,
// completed at rest, the modal digest), and records that survive torn slots, corrupt slots and a
// writer SIGKILLed mid-write.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include "../control/test_profiles.hpp"
#include "opencnc/broaching/breakpoint.hpp"
#include "opencnc/broaching/breakpoint_journal.hpp"
#include "opencnc/broaching/journal.hpp"
#include "opencnc/broaching/modal_digest.hpp"
#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/features/features.hpp"

namespace opencnc::recovery {
namespace {

using control::CommandKind;
using control::State;
using controller::Request;
using controller::SimRig;

std::filesystem::path fresh_dir() {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-breakpoint-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
       "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

/// A record with every field set to something distinct.
BreakpointRecord sample(std::uint64_t move) {
  BreakpointRecord r;
  r.valid = true;
  r.stage = BreakpointStage::AtRest;
  r.program_path = "/work/jobs/broach-constant.ngc";
  r.program_hash = 0x1234567890abcdefULL;
  r.program_size = 4321;
  r.program_start.v = {1, 2, 3, 4, 5, 6, 7, 8, 9};
  r.segment = 17 + move;
  r.job_move = move;
  r.segment_offset_mm = 12.5;
  r.source_file = "/work/jobs/broach-constant.ngc";
  r.line = 42;
  r.move_kind = 1;
  r.move_start.v[2] = -10;
  r.move_end.v[2] = 1000;
  r.move_remaining_mm = 997.5;
  r.commanded.v[2] = 2.5;
  r.commanded.v[5] = 1.5;
  r.actual.v[2] = 2.4999;
  r.actual.v[5] = 1.4999;
  r.modal_digest = 0xfeedfacecafebeefULL;
  r.tool = 3;
  r.spindle_rpm = 120;
  r.spindle_direction = -1;
  r.flood = true;
  r.coupling = {1, 2, 5, 0, 600, 0, -10, 0};
  r.signal_time_s = 3.2;
  r.rest_time_s = 3.31;
  return r;
}

TEST(BreakpointRecord, RoundTripsEveryField) {
  const BreakpointRecord r = sample(5);
  std::string error;
  const auto back = decode(encode(r), &error);
  ASSERT_TRUE(back.has_value()) << error;
  EXPECT_EQ(*back, r);
  EXPECT_NE(describe(r).find(":42"), std::string::npos);
}

TEST(BreakpointRecord, RefusesCorruptTruncatedAndForeignBytes) {
  const std::vector<std::byte> bytes = encode(sample(5));
  std::string error;
  for (std::size_t i = 0; i < bytes.size(); i += 7) {  // a flipped bit anywhere
    std::vector<std::byte> bad = bytes;
    bad[i] ^= std::byte{0x10};
    EXPECT_FALSE(decode(bad, &error).has_value()) << i;
  }
  EXPECT_FALSE(decode(std::span(bytes).first(bytes.size() - 1), &error).has_value());
  EXPECT_FALSE(decode(std::span(bytes).first(10), &error).has_value());
  EXPECT_NE(error.find("truncated"), std::string::npos);
  // A newer format version, with a checksum that holds: refused by its version.
  std::vector<std::byte> v2 = bytes;
  v2[4] = std::byte{2};
  v2.resize(v2.size() - 4);
  const std::uint32_t crc = crc32(v2);
  for (int k = 0; k < 4; ++k) v2.push_back(static_cast<std::byte>((crc >> (8 * k)) & 0xff));
  EXPECT_FALSE(decode(v2, &error).has_value());
  EXPECT_NE(error.find("version"), std::string::npos);
}

// A torn newest slot (the write cut short) and a corrupt one (a bit flipped on the disk) each
// leave the record before it, whole.
TEST(BreakpointRecord, TornOrCorruptSlotLeavesTheLastGoodRecord) {
  for (const bool torn : {true, false}) {
    const auto dir = fresh_dir();
    std::string error;
    {
      auto j = Journal::open(dir.string(), &error);
      ASSERT_TRUE(j) << error;
      ASSERT_TRUE(j->write(encode(sample(1)), &error));  // slot a
      ASSERT_TRUE(j->write(encode(sample(2)), &error));  // slot b, the newest
    }
    const auto slot_b = dir / "slot-b.jrn";
    const std::uintmax_t middle = encode(sample(2)).size() / 2;  // inside the record
    if (torn) {
      std::filesystem::resize_file(slot_b, middle);
    } else {
      std::fstream f(slot_b, std::ios::in | std::ios::out | std::ios::binary);
      f.seekp(static_cast<std::streamoff>(middle));
      const char c = static_cast<char>(f.peek() ^ 0x5a);
      f.seekp(static_cast<std::streamoff>(middle));
      f.put(c);
    }
    auto j = Journal::open(dir.string(), &error);
    const auto raw = j->read();
    ASSERT_TRUE(raw.has_value()) << torn;
    const auto r = decode(raw->payload, &error);
    ASSERT_TRUE(r.has_value()) << error;
    EXPECT_EQ(*r, sample(1)) << torn;
  }
}

// A writer of breakpoint records SIGKILLed at random moments (fixed seed), 12 times: the journal
// then decodes to the last record the writer had reported durable, or a later one.
TEST(BreakpointRecord, AKilledWriterNeverLosesTheLastGoodRecord) {
  const auto dir = fresh_dir();
  std::mt19937 rng(9);
  std::uniform_int_distribution<int> delay_us(0, 4000);
  for (int run = 0; run < 12; ++run) {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      std::string error;
      auto j = Journal::open(dir.string(), &error);
      if (!j) ::_exit(2);
      for (std::uint64_t move = j->sequence() + 1;; ++move) {
        if (!j->write(encode(sample(move)), &error)) ::_exit(3);
        if (::write(fds[1], &move, sizeof move) != sizeof move) ::_exit(4);
      }
    }
    ::close(fds[1]);
    std::this_thread::sleep_for(std::chrono::microseconds(delay_us(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    std::uint64_t reported = 0, m = 0;
    while (::read(fds[0], &m, sizeof m) == sizeof m) reported = m;
    ::close(fds[0]);
    std::string error;
    auto j = Journal::open(dir.string(), &error);
    ASSERT_TRUE(j) << error;
    const auto raw = j->read();
    if (reported == 0 && !raw) continue;  // killed before its first record
    ASSERT_TRUE(raw.has_value()) << run;
    const auto r = decode(raw->payload, &error);
    ASSERT_TRUE(r.has_value()) << error;
    EXPECT_GE(r->job_move, reported) << run;
    EXPECT_EQ(*r, sample(r->job_move));
  }
}

config::MachineProfile broach() {
  return control::test::loaded(config::load_profile(OPENCNC_SOURCE_DIR "/configs/broach-zc.toml", {}));
}

// The mains fail while the broach cuts the constant-pitch demo job: the journal holds the record
// written at the signal within milliseconds, then the completed one — valid, at rest where the
// status says, on the move the machine was on, coupled with the law's origin, the program's hash
// and the modal digest a replay to the segment gives.
TEST(BreakpointJournal, WritesTheRecordWhenTheMainsFail) {
  const auto dir = fresh_dir();
  const config::MachineProfile p = broach();
  const std::string program = OPENCNC_SOURCE_DIR "/examples/broach-constant.ngc";
  Diagnostics d;
  auto machine =
      features::machine_setup(p, d, controller::MachineSetup::Options::with("journal", dir.string()));
  ASSERT_TRUE(machine) << (d.items().empty() ? "" : d.items()[0].format());
  auto source = machine->source();
  SimRig rig(p, *machine);
  auto journal = std::dynamic_pointer_cast<BreakpointJournal>(machine->feature("journal"));
  ASSERT_TRUE(journal);
  std::string error;
  rig.step();
  ASSERT_TRUE(rig.request(Request::simple(CommandKind::MachineOn)).accepted);
  ASSERT_TRUE(rig.request(Request::set_mode(control::Mode::Auto)).accepted);
  ASSERT_TRUE(rig.request(Request::open(program), 100000).accepted);
  ASSERT_TRUE(rig.request(Request::simple(CommandKind::CycleStart)).accepted);
  ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.time_s >= 3.2; }, 20000));
  const std::uint32_t line_before = rig.status().location.line;
  rig.machine().set_mains_ok(false);
  ASSERT_TRUE(rig.run_until([&] { return rig.status().servo.state == State::Faulted; }, 5000));
  rig.run(3);
  journal->flush();
  EXPECT_EQ(journal->last_error(), "");
  // The writer says how it writes and what priority it got (or that it was not permitted).
  const std::string status = journal->writer_status();
  EXPECT_NE(status.find("; writer thread "), std::string::npos) << status;
  EXPECT_NE(status.find("; I/O priority "), std::string::npos) << status;
  EXPECT_EQ(status.find("starting"), std::string::npos) << status;
  const auto r = journal->last_written();
  ASSERT_TRUE(r.has_value());
  EXPECT_TRUE(r->valid);
  EXPECT_EQ(r->stage, BreakpointStage::AtRest);
  EXPECT_EQ(r->program_path, program);
  const auto h = hash_file(program);
  ASSERT_TRUE(h.has_value());
  EXPECT_EQ(r->program_hash, h->hash);
  EXPECT_EQ(r->program_size, h->size);
  EXPECT_EQ(r->line, line_before);
  // At rest: the command stood still before the drives went off (it then follows the feedback).
  EXPECT_NEAR(r->commanded.v[2], rig.status().servo.commanded.v[2], 0.05);
  EXPECT_NEAR(r->actual.v[2], r->commanded.v[2], 0.05);
  EXPECT_LE(r->rest_time_s - r->signal_time_s, 0.2);
  EXPECT_EQ(r->coupling.kind, 1);  // constant pitch
  EXPECT_EQ(r->coupling.pitch_mm, 600.0);
  // The rest position is on the interrupted move: offset + remaining = its length.
  double len = 0;  // the planner's length of a line: over every axis, C's degrees included
  for (std::size_t a = 0; a < r->move_end.v.size(); ++a)
    len += (r->move_end.v[a] - r->move_start.v[a]) * (r->move_end.v[a] - r->move_start.v[a]);
  len = std::sqrt(len);
  EXPECT_NEAR(r->segment_offset_mm + r->move_remaining_mm, len, 1e-6);
  EXPECT_NEAR(r->move_start.v[2] + (r->move_end.v[2] - r->move_start.v[2]) * r->segment_offset_mm / len,
              r->commanded.v[2], 1e-6);
  EXPECT_NE(r->modal_digest, 0u);
  EXPECT_EQ(r->modal_digest,
            modal_digest_at(source->options_for(program, {}), program, r->program_start, r->segment, &error));
  EXPECT_EQ(journal->latencies_ms().size(), 1u);
  // What the journal holds on the disk is that record.
  auto j = Journal::open(dir.string(), &error);
  const auto raw = j->read();
  ASSERT_TRUE(raw.has_value());
  EXPECT_EQ(decode(raw->payload, &error), r);
}

}  // namespace
}  // namespace opencnc::recovery
