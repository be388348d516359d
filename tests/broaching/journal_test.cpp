// SPDX-License-Identifier: GPL-3.0-or-later
// The breakpoint journal's storage: records read back after reopening (each way of writing), slots
// of whole blocks allocated when opened, a file that is not a slot refused untouched, a torn or
// corrupt newest slot falls back to the last good record, both slots bad read as none, and a writer
// process SIGKILLed at random moments never loses a record it had reported durable.
#include <gtest/gtest.h>

#include <linux/ioprio.h>
#include <signal.h>
#include <sys/stat.h>
#include <sys/syscall.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <thread>

#include "opencnc/broaching/journal.hpp"

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

// Each way of writing keeps the same slots: what one wrote, a journal opened another way reads.
TEST(Journal, EveryWayOfWritingReadsBackAcrossReopening) {
  const auto dir = fresh_dir();
  std::string error;
  std::uint64_t seq = 0;
  for (JournalSync sync : {JournalSync::Direct, JournalSync::Fdatasync, JournalSync::Dsync}) {
    auto j = Journal::open(dir.string(), &error, {sync});
    ASSERT_TRUE(j) << error;
    EXPECT_EQ(j->sequence(), seq) << to_string(sync);
    for (int k = 0; k < 3; ++k)
      ASSERT_TRUE(j->write(payload(++seq), &error)) << to_string(sync) << ": " << error;
    // Where the file system refuses a way the journal says it fell back to fdatasync.
    EXPECT_TRUE(j->sync() == sync ||
                (j->sync() == JournalSync::Fdatasync && j->how().find("refused") != std::string::npos))
        << to_string(sync) << ": " << j->how();
    const auto r = j->read();  // through the page cache, after O_DIRECT writes too
    ASSERT_TRUE(r.has_value());
    EXPECT_EQ(r->sequence, seq);
    EXPECT_TRUE(matches(*r));
  }
  const auto r = Journal::open(dir.string(), &error)->read();
  ASSERT_TRUE(r.has_value());
  EXPECT_EQ(r->sequence, 9u);
  EXPECT_TRUE(matches(*r));
  std::filesystem::remove_all(dir);
}

std::vector<char> bytes_of(const std::filesystem::path& path) {
  std::ifstream f(path, std::ios::binary);
  return {std::istreambuf_iterator<char>(f), std::istreambuf_iterator<char>()};
}

// A record longer than a block grows its slot by whole blocks; a shorter one after it is written as
// its own block, zeros past its checksum (the longer one's second block stays, never read).
TEST(Journal, ARecordIsWrittenAsWholeBlocks) {
  const auto dir = fresh_dir();
  std::string error;
  auto j = Journal::open(dir.string(), &error);
  ASSERT_TRUE(j) << error;
  std::vector<std::byte> big(5000, std::byte{0x5A});
  ASSERT_TRUE(j->write(big, &error)) << error;         // slot a
  ASSERT_TRUE(j->write(payload(2), &error)) << error;  // slot b
  ASSERT_TRUE(j->write(payload(3), &error)) << error;  // slot a again, over the big one
  EXPECT_EQ(std::filesystem::file_size(dir / "slot-a.jrn"), 8192u);
  EXPECT_EQ(std::filesystem::file_size(dir / "slot-b.jrn"), 4096u);
  const std::vector<char> a = bytes_of(dir / "slot-a.jrn");
  const std::size_t record = 24 + payload(3).size() + 4;
  ASSERT_EQ(a.size(), 8192u);
  EXPECT_TRUE(std::all_of(a.begin() + static_cast<std::ptrdiff_t>(record), a.begin() + 4096,
                          [](char c) { return c == 0; }));
  EXPECT_EQ(a[4096], 0x5A);
  EXPECT_EQ(j->read()->sequence, 3u);
  EXPECT_TRUE(matches(*j->read()));
  std::filesystem::remove_all(dir);
}

// A file in a slot's place that no journal writes (too large, or not a regular file) is refused
// with its name, before either slot is created or written.
TEST(Journal, AFileThatIsNotASlotIsRefusedAndLeftAsItIs) {
  const auto dir = fresh_dir();
  std::filesystem::create_directories(dir);
  {
    std::ofstream f(dir / "slot-a.jrn", std::ios::binary);
    std::string text(Journal::kMaxSlotBytes + 1, 'x');
    f << text;
  }
  const std::vector<char> before = bytes_of(dir / "slot-a.jrn");
  std::string error;
  EXPECT_FALSE(Journal::open(dir.string(), &error));
  EXPECT_NE(error.find("slot-a.jrn"), std::string::npos) << error;
  EXPECT_NE(error.find("not a journal slot"), std::string::npos) << error;
  EXPECT_TRUE(bytes_of(dir / "slot-a.jrn") == before);
  EXPECT_FALSE(std::filesystem::exists(dir / "slot-b.jrn"));
  // A folder where slot b belongs: refused too, slot a (a good one now) untouched.
  std::filesystem::remove(dir / "slot-a.jrn");
  {
    auto j = Journal::open(dir.string(), &error);
    ASSERT_TRUE(j) << error;
    ASSERT_TRUE(j->write(payload(1), &error));
  }
  std::filesystem::remove(dir / "slot-b.jrn");
  std::filesystem::create_directory(dir / "slot-b.jrn");
  const std::vector<char> good = bytes_of(dir / "slot-a.jrn");
  error.clear();
  EXPECT_FALSE(Journal::open(dir.string(), &error));
  EXPECT_NE(error.find("slot-b.jrn is not a regular file"), std::string::npos) << error;
  EXPECT_TRUE(bytes_of(dir / "slot-a.jrn") == good);
  std::filesystem::remove_all(dir);
}

// The writer's I/O priority: raised to the real-time class where permitted (it is, or the call
// says it is not), and put back.
TEST(Journal, TheWritersIoPriorityIsRaisedWherePermitted) {
  const auto priority = [] { return ::syscall(SYS_ioprio_get, IOPRIO_WHO_PROCESS, 0); };
  std::thread([&] {
    if (raise_io_priority())
      EXPECT_EQ(IOPRIO_PRIO_CLASS(priority()), IOPRIO_CLASS_RT);
    else
      EXPECT_NE(IOPRIO_PRIO_CLASS(priority()), IOPRIO_CLASS_RT);
    reset_io_priority();
    EXPECT_NE(IOPRIO_PRIO_CLASS(priority()), IOPRIO_CLASS_RT);
  }).join();
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
  // An older journal's slot that a long record left at 5000 bytes: rounded up to two blocks, kept.
  std::vector<std::byte> big(4900, std::byte{0x33});
  ASSERT_TRUE(j->write(big, &error)) << error;  // slot b
  j.reset();
  std::filesystem::resize_file(dir / "slot-b.jrn", 24 + big.size() + 4);
  j = Journal::open(dir.string(), &error);
  ASSERT_TRUE(j) << error;
  EXPECT_EQ(std::filesystem::file_size(dir / "slot-b.jrn"), 8192u);
  EXPECT_EQ(j->read()->sequence, 2u);
  EXPECT_TRUE(j->read()->payload == big);
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
