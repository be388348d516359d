// SPDX-License-Identifier: GPL-3.0-or-later
// The tool store: edges and parameters kept, every change audited, backups kept, restore, the
// LinuxCNC view the interpreter reads and G10 writes, another process's changes seen.
#include "opencnc/store/tool_store.hpp"

#include <gtest/gtest.h>

#include <fstream>

#include "opencnc/store/database.hpp"
#include "opencnc/tools/edge_mapping.hpp"
#include "temp_db.hpp"

namespace opencnc::store {
namespace {

using test::TempDb;
using tools::Param;

std::shared_ptr<ToolStore> open_store(const std::string& path) {
  std::string error;
  auto s = ToolStore::open(path, &error);
  EXPECT_NE(s, nullptr) << error;
  int n = 0;
  s->set_clock([n]() mutable { return "2026-11-26T03:00:" + std::to_string(10 + n++) + "Z"; });
  return s;
}

// T53 D1: a 193.225 mm long end mill of radius 8, a little wear.
void seed(ToolStore& s) {
  std::string e;
  ASSERT_TRUE(s.set_tool(53, 12, "D16 end mill", "test", &e)) << e;
  ASSERT_TRUE(s.set(53, 1, Param::Type, 120, "test", &e)) << e;
  ASSERT_TRUE(s.set(53, 1, Param::Length1, 193.225, "test", &e)) << e;
  ASSERT_TRUE(s.set(53, 1, Param::Radius, 8, "test", &e)) << e;
  ASSERT_TRUE(s.set(53, 1, Param::WearLength1, -0.02, "test", &e)) << e;
  ASSERT_TRUE(s.set(53, 2, Param::Length1, 150.5, "test", &e)) << e;
}

TEST(ToolStore, KeepsToolsEdgesAndParametersAcrossOpens) {
  TempDb dir;
  {
    auto s = open_store(dir.path());
    seed(*s);
  }
  auto s = open_store(dir.path());
  const auto live = s->live();
  ASSERT_TRUE(live);
  const tools::Tool* t = live->tool(53);
  ASSERT_NE(t, nullptr);
  EXPECT_EQ(t->pocket, 12);
  EXPECT_EQ(t->comment, "D16 end mill");
  ASSERT_EQ(t->edges.size(), 2u);
  EXPECT_EQ(t->edge(1)->get(Param::Length1), 193.225);
  EXPECT_EQ(t->edge(1)->get(Param::WearLength1), -0.02);
  EXPECT_DOUBLE_EQ(t->edge(1)->effective_length(1), 193.205);
  EXPECT_EQ(t->edge(2)->get(Param::Length1), 150.5);
}

TEST(ToolStore, AuditsEveryValueWithWhenWhoOldAndNew) {
  TempDb dir;
  auto s = open_store(dir.path());
  seed(*s);
  std::string e;
  ASSERT_TRUE(s->set(53, 1, Param::Length1, 139.225, "command line", &e)) << e;
  const auto audit = s->audit(1);
  ASSERT_EQ(audit.size(), 1u);
  EXPECT_EQ(audit[0].what, "T53 D1 length1");
  EXPECT_EQ(audit[0].old_value, "193.225");
  EXPECT_EQ(audit[0].new_value, "139.225");
  EXPECT_EQ(audit[0].interface, "command line");
  EXPECT_EQ(audit[0].reason, "set");
  EXPECT_FALSE(audit[0].at_utc.empty());
  // The same value again changes nothing and audits nothing.
  const std::size_t n = s->audit().size();
  ASSERT_TRUE(s->set(53, 1, Param::Length1, 139.225, "command line", &e));
  EXPECT_EQ(s->audit().size(), n);
}

TEST(ToolStore, RefusesInvalidValuesAndChangesNothing) {
  TempDb dir;
  auto s = open_store(dir.path());
  seed(*s);
  const auto before = s->live();
  const std::size_t n = s->audit().size();
  std::string e;
  EXPECT_FALSE(s->set(53, 1, Param::Length1, std::numeric_limits<double>::quiet_NaN(), "test", &e));
  EXPECT_NE(e.find("T53 D1 length1"), std::string::npos) << e;
  EXPECT_FALSE(s->set(53, 1, Param::Type, 1.5, "test", &e));
  EXPECT_FALSE(s->set(53, 10, Param::Length1, 1, "test", &e));
  EXPECT_FALSE(s->set(0, 1, Param::Length1, 1, "test", &e));
  EXPECT_EQ(s->live(), before);
  EXPECT_EQ(s->audit().size(), n);
}

TEST(ToolStore, BackupsAreAllKeptAndRestoreWritesTheChosenOne) {
  TempDb dir;
  auto s = open_store(dir.path());
  seed(*s);
  std::string e;
  const auto first = s->backup("test", "backup", &e);
  ASSERT_TRUE(first) << e;
  ASSERT_TRUE(s->set(53, 1, Param::WearLength1, -0.05, "test", &e));
  const auto second = s->backup("test", "accept", &e);
  ASSERT_TRUE(second) << e;
  ASSERT_TRUE(s->set(53, 1, Param::Length1, 139.225, "test", &e));

  const auto all = s->backups();
  ASSERT_EQ(all.size(), 2u);
  EXPECT_EQ(all[0].id, *first);
  EXPECT_EQ(all[1].reason, "accept");
  EXPECT_EQ(all[1].edges, 2);
  EXPECT_EQ(s->current_backup()->id, *second);
  EXPECT_EQ(s->backup_set(*first)->edge(53, 1)->get(Param::WearLength1), -0.02);

  ASSERT_TRUE(s->restore(*first, "test", &e)) << e;
  EXPECT_EQ(*s->live(), *s->backup_set(*first));
  EXPECT_EQ(s->backups().size(), 2u);  // restoring takes none away
  const auto last = s->audit(2);
  EXPECT_EQ(last[0].reason, "restore of backup 1");
  EXPECT_FALSE(s->restore(99, "test", &e));
  EXPECT_NE(e.find("no backup 99"), std::string::npos);
}

TEST(ToolStore, IsTheInterpretersToolTableWithEdgesAsToolNumbers) {
  TempDb dir;
  auto s = open_store(dir.path());
  seed(*s);
  const auto table = s->snapshot();
  ASSERT_EQ(table->size(), 2u);
  const tools::ToolEntry* d1 = table->tool(53);
  const tools::ToolEntry* d2 = table->tool(20053);
  ASSERT_NE(d1, nullptr);
  ASSERT_NE(d2, nullptr);
  EXPECT_DOUBLE_EQ(d1->offset[Axis::Z], 193.205);  // geometry + wear
  EXPECT_EQ(d1->diameter, 16);
  EXPECT_EQ(d1->pocket, 12);
  EXPECT_EQ(d2->offset[Axis::Z], 150.5);
}

TEST(ToolStore, G10WritesGeometryKeepsWearAndIsAudited) {
  TempDb dir;
  auto s = open_store(dir.path());
  seed(*s);
  const std::uint64_t v = s->version();
  tools::ToolEntry e = *s->snapshot()->tool(53);
  e.offset[Axis::Z] = 200.0;  // G10 L1 P53 Z200: the effective length becomes 200
  Diagnostics d;
  ASSERT_TRUE(s->update(*s->snapshot()->find(53), e, tools::ChangeSource::Program, d));
  EXPECT_GT(s->version(), v);
  const auto live = s->live();
  EXPECT_EQ(live->edge(53, 1)->get(Param::WearLength1), -0.02);
  EXPECT_DOUBLE_EQ(live->edge(53, 1)->effective_length(1), 200.0);
  EXPECT_EQ(live->edge(53, 1)->get(Param::Radius), 8);  // untouched: no rounding drift
  const auto a = s->audit(1);
  EXPECT_EQ(a[0].interface, "program");
  EXPECT_EQ(a[0].reason, "G10");
  EXPECT_EQ(a[0].what, "T53 D1 length1");
  // Offsets the store cannot hold are refused with a reason, the table unchanged.
  e.offset[Axis::A] = 1;
  EXPECT_FALSE(s->update(1, e, tools::ChangeSource::Program, d));
  EXPECT_NE(d.items().back().message.find("A"), std::string::npos);
  EXPECT_DOUBLE_EQ(s->live()->edge(53, 1)->effective_length(1), 200.0);
}

TEST(ToolStore, SeesAnotherConnectionsCommits) {
  TempDb dir;
  auto running = open_store(dir.path());
  seed(*running);
  const std::uint64_t v = running->version();
  auto cli = open_store(dir.path());
  std::string e;
  ASSERT_TRUE(cli->set(53, 1, Param::Length1, 139.225, "command line", &e)) << e;
  EXPECT_GT(running->version(), v);
  EXPECT_DOUBLE_EQ(running->snapshot()->tool(53)->offset[Axis::Z], 139.205);
}

TEST(ToolStore, RefusesAFileThatIsNoToolStore) {
  TempDb dir;
  std::ofstream(dir.path("notes.txt")) << "not a database at all, just some text that is long enough\n";
  std::string e;
  EXPECT_EQ(ToolStore::open(dir.path("notes.txt"), &e), nullptr);
  EXPECT_NE(e.find("notes.txt"), std::string::npos) << e;
  {
    Database other(dir.path("other.db"));
    other.exec("CREATE TABLE x(a)");
  }
  EXPECT_EQ(ToolStore::open(dir.path("other.db"), &e), nullptr);
  EXPECT_NE(e.find("not an opencnc tool store"), std::string::npos) << e;
  EXPECT_EQ(ToolStore::open(dir.path("missing.db"), &e, false), nullptr);
}

}  // namespace
}  // namespace opencnc::store
