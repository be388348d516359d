// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's storage: records read back after reopening, a torn or corrupt newest
// slot falls back to the last good record, both slots bad read as none, and a writer process
// SIGKILLed at random moments never loses a record it had reported durable.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <random>
#include <string>
#include <thread>

#include "opencnc/recovery/journal.hpp"

namespace opencnc::recovery {
namespace {

std::filesystem::path fresh_dir() {
  const auto dir =
      std::filesystem::temp_directory_path() /
      ("opencnc-journal-" + std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()) +
       "-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  return dir;
}

/// The payload of record `seq`: its number, then bytes that depend on it (a few hundred).
std::vector<std::byte> payload(std::uint64_t seq) {
  std::vector<std::byte> p(200 + seq % 300);
  std::memcpy(p.data(), &seq, sizeof seq);
  for (std::size_t i = sizeof seq; i < p.size(); ++i)
    p[i] = static_cast<std::byte>((seq * 31 + i * 7) & 0xFF);
  return p;
}

bool matches(const JournalRecord& r) {
  return r.payload == payload(r.sequence);
}

/// Newest slot's file: the one holding `seq` (records alternate, the first goes to slot a).
std::filesystem::path slot_of(const std::filesystem::path& dir, std::uint64_t seq) {
  return dir / (seq % 2 == 1 ? "slot-a.jrn" : "slot-b.jrn");
}

TEST(Journal, RecordsSurviveReopening) {
  const auto dir = fresh_dir();
  std::string error;
  {
    auto j = Journal::open(dir.string(), &error);
    ASSERT_TRUE(j) << error;
    EXPECT_FALSE(j->read().has_value());
    for (std::uint64_t s = 1; s <= 5; ++s) ASSERT_TRUE(j->write(payload(s), &error)) << error;
  }
  auto j = Journal::open(dir.string(), &error);
  ASSERT_TRUE(j) << error;
  const auto r = j->read();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sequence, 5u);
  EXPECT_TRUE(matches(*r));
  ASSERT_TRUE(j->write(payload(6), &error));  // numbering goes on
  EXPECT_EQ(j->read()->sequence, 6u);
  std::filesystem::remove_all(dir);
}

/// Bytes the file system has allocated to `path` (a hole has none).
std::uintmax_t allocated_bytes(const std::filesystem::path& path) {
  struct stat st {};
  return ::stat(path.c_str(), &st) == 0 ? static_cast<std::uintmax_t>(st.st_blocks) * 512 : 0;
}

// The slots are written out when opened, so a record's fdatasync has no block to allocate; a
// short slot holding a record (an older journal's) keeps the record while it is filled out.
TEST(Journal, SlotsAreAllocatedWhenOpenedAndKeepTheirRecord) {
  const auto dir = fresh_dir();
  std::string error;
  {
    auto j = Journal::open(dir.string(), &error);
    ASSERT_TRUE(j) << error;
    for (const char* slot : {"slot-a.jrn", "slot-b.jrn"}) {
      EXPECT_EQ(std::filesystem::file_size(dir / slot), 4096u) << slot;
      EXPECT_GE(allocated_bytes(dir / slot), 4096u) << slot;
    }
    ASSERT_TRUE(j->write(payload(1), &error)) << error;
  }
  // slot-a cut down to the record alone, as a journal that did not fill its slots left it.
  const std::size_t record_bytes = 24 + payload(1).size() + 4;
  std::filesystem::resize_file(dir / "slot-a.jrn", record_bytes);
  auto j = Journal::open(dir.string(), &error);
  ASSERT_TRUE(j) << error;
  EXPECT_EQ(std::filesystem::file_size(dir / "slot-a.jrn"), 4096u);
  EXPECT_GE(allocated_bytes(dir / "slot-a.jrn"), 4096u);
  const auto r = j->read();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sequence, 1u);
  EXPECT_TRUE(matches(*r));
  std::filesystem::remove_all(dir);
}

TEST(Journal, ATornOrCorruptSlotFallsBackToTheLastGoodRecord) {
  const auto dir = fresh_dir();
  std::string error;
  auto j = Journal::open(dir.string(), &error);
  ASSERT_TRUE(j) << error;
  for (std::uint64_t s = 1; s <= 4; ++s) ASSERT_TRUE(j->write(payload(s), &error));
  // One flipped bit in the newest record's payload: its checksum fails, record 3 is read.
  {
    std::fstream f(slot_of(dir, 4), std::ios::in | std::ios::out | std::ios::binary);
    f.seekp(100);
    char c = 0;
    f.read(&c, 1);
    f.seekp(100);
    c = static_cast<char>(c ^ 0x10);
    f.write(&c, 1);
  }
  auto r = j->read();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sequence, 3u);
  EXPECT_TRUE(matches(*r));
  // The next write goes over the corrupt slot (b), not over record 3; torn there after 40 bytes,
  // record 3 is still what the journal holds.
  ASSERT_TRUE(j->write(payload(5), &error));
  EXPECT_EQ(j->read()->sequence, 5u);
  std::filesystem::resize_file(dir / "slot-b.jrn", 40);
  r = Journal::open(dir.string(), &error)->read();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sequence, 3u);
  EXPECT_TRUE(matches(*r));
  // Both slots bad: nothing to offer.
  std::filesystem::resize_file(dir / "slot-a.jrn", 3);
  EXPECT_FALSE(Journal::open(dir.string(), &error)->read().has_value());
  std::filesystem::remove_all(dir);
}

// A child process writes records as fast as it can and reports each one once write() returned
// (durable); it is SIGKILLed at a random moment, 25 times with a fixed seed. The journal then
// holds the last reported record or the one after it, whole.
TEST(Journal, KilledWritersNeverLoseADurableRecord) {
  const auto dir = fresh_dir();
  std::mt19937 rng(20261126);
  std::uniform_int_distribution<int> delay_us(0, 3000);
  std::uint64_t lost = 0, corrupt = 0;
  for (int run = 0; run < 25; ++run) {
    std::uint64_t before = 0;  // what the journal held before this writer
    {
      std::string error;
      const auto j = Journal::open(dir.string(), &error);
      ASSERT_TRUE(j) << error;
      before = j->sequence();
    }
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t child = ::fork();
    ASSERT_GE(child, 0);
    if (child == 0) {
      ::close(fds[0]);
      std::string error;
      auto j = Journal::open(dir.string(), &error);
      if (!j) ::_exit(2);
      for (;;) {
        const std::uint64_t seq = j->sequence() + 1;
        if (!j->write(payload(seq), &error)) ::_exit(3);
        if (::write(fds[1], &seq, sizeof seq) != sizeof seq) ::_exit(4);
      }
    }
    ::close(fds[1]);
    std::this_thread::sleep_for(std::chrono::microseconds(500 + delay_us(rng)));
    ::kill(child, SIGKILL);
    int status = 0;
    ::waitpid(child, &status, 0);
    std::uint64_t acked = 0, seq = 0;
    while (::read(fds[0], &seq, sizeof seq) == sizeof seq) acked = seq;
    ::close(fds[0]);
    std::string error;
    auto j = Journal::open(dir.string(), &error);
    ASSERT_TRUE(j) << error;
    const auto r = j->read();
    const std::uint64_t durable = std::max(acked, before);
    if (durable > 0 && (!r || r->sequence < durable)) ++lost;
    if (r && (!matches(*r) || r->sequence > durable + 1)) ++corrupt;
  }
  EXPECT_EQ(lost, 0u);
  EXPECT_EQ(corrupt, 0u);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace opencnc::recovery
