// SPDX-License-Identifier: GPL-3.0-or-later
// Fault injection: a process killed (SIGKILL) in the middle of its updates and backups leaves
// the tool store consistent: every change whole or absent, every backup whole, nothing lost
// that was reported as committed.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cstdio>

#include "opencnc/store/database.hpp"
#include "opencnc/store/tool_store.hpp"
#include "temp_db.hpp"

namespace opencnc::store {
namespace {

using tools::Param;

constexpr int kTools = 20;

// Every edge of the set carries generation `n` in length1 and wear: a half-written update
// would mix generations.
tools::ToolSet generation(int n) {
  tools::ToolSet set;
  for (int t = 1; t <= kTools; ++t) {
    set.tool_or_add(t).pocket = t;
    for (int d = 1; d <= 2; ++d) {
      tools::Edge& e = set.edge_or_add(t, d);
      e.set(Param::Length1, 100 + n);
      e.set(Param::WearLength1, -0.001 * n);
    }
  }
  return set;
}

// Writes generations 1, 2, 3 … (a backup after every third) and reports each commit on `fd`.
[[noreturn]] void writer(const std::string& path, int fd) {
  std::string error;
  auto s = ToolStore::open(path, &error);
  if (!s) _exit(2);
  for (int n = 1;; ++n) {
    if (!s->write(generation(n), "test", "kill test", &error)) _exit(3);
    if (n % 3 == 0 && !s->backup("test", "backup", &error)) _exit(4);
    if (::write(fd, &n, sizeof n) != sizeof n) _exit(5);
  }
}

// The generation of a set if every edge agrees on it, else -1.
int generation_of(const tools::ToolSet& set) {
  if (set.tools.size() != kTools) return -1;
  const int n = static_cast<int>(set.tools[0].edges.at(0).get(Param::Length1)) - 100;
  return set == generation(n) ? n : -1;
}

TEST(ToolStoreKill, AProcessKilledMidUpdateLeavesTheStoreConsistent) {
  test::TempDb dir;
  const std::string path = dir.path();
  int committed = 0;
  // Three writers in turn, each killed after a different number of commits: the kill lands
  // inside a write, a backup or between them.
  for (int round = 0; round < 3; ++round) {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const pid_t pid = ::fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      ::close(fds[0]);
      writer(path, fds[1]);
    }
    ::close(fds[1]);
    int n = 0, seen = 0;
    while (seen < 4 + 3 * round && ::read(fds[0], &n, sizeof n) == sizeof n) ++seen;
    ASSERT_EQ(::kill(pid, SIGKILL), 0);
    int status = 0;
    ::waitpid(pid, &status, 0);
    ASSERT_TRUE(WIFSIGNALED(status)) << "the writer stopped by itself: " << status;
    while (::read(fds[0], &n, sizeof n) == sizeof n) ++seen;  // commits reported before the kill
    ::close(fds[0]);
    committed = n;

    {
      Database db(path);
      Statement check = db.prepare("PRAGMA integrity_check");
      ASSERT_TRUE(check.step());
      EXPECT_EQ(check.text(0), "ok");
    }
    std::string error;
    auto s = ToolStore::open(path, &error);
    ASSERT_NE(s, nullptr) << error;
    const int live = generation_of(*s->live());
    // Whole, and nothing reported as committed is lost (the kill may land after a commit
    // before its report).
    EXPECT_GE(live, committed) << "round " << round;
    EXPECT_LE(live, committed + 1) << "round " << round;
    for (const BackupInfo& b : s->backups())
      EXPECT_GT(generation_of(*s->backup_set(b.id)), 0) << "backup " << b.id;
    // The store goes on: the next writer starts from generation 1 again over a whole table.
  }
}

}  // namespace
}  // namespace opencnc::store
