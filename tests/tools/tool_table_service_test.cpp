// SPDX-License-Identifier: GPL-3.0-or-later
// The live tool table: whole changes, snapshots that stay as they were, the .tbl file written back
// atomically, and a change that cannot be stored changes nothing.
#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "opencnc/tools/tool_table_service.hpp"

using namespace opencnc;
using namespace opencnc::tools;

namespace {

std::string read(const std::filesystem::path& p) {
  std::ifstream in(p);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

class TempDir {
 public:
  TempDir() {
    dir_ = std::filesystem::temp_directory_path() /
           ("opencnc-tools-" + std::to_string(::getpid()) + "-" +
            ::testing::UnitTest::GetInstance()->current_test_info()->name());
    std::filesystem::create_directories(dir_);
  }
  ~TempDir() {
    std::error_code ec;
    std::filesystem::permissions(dir_, std::filesystem::perms::owner_all, ec);
    std::filesystem::remove_all(dir_, ec);
  }
  const std::filesystem::path& path() const { return dir_; }

 private:
  std::filesystem::path dir_;
};

TEST(ToolTableFormat, ReadsBackWhatItWrites) {
  Diagnostics d;
  const ToolTable t = ToolTable::parse("T1 P3 Z45.125 D6 ;end mill\nT7 P1 X0.1 Z-2.5 D0.5 I10 J20 Q3\n", "t", d);
  ASSERT_FALSE(d.has_errors());
  const ToolTable again = ToolTable::parse(t.format(), "t", d);
  EXPECT_FALSE(d.has_errors());
  EXPECT_EQ(again, t);
  EXPECT_EQ(t.format(), "T1 P3 Z45.125 D6 ;end mill\nT7 P1 X0.1 Z-2.5 D0.5 I10 J20 Q3\n");
}

TEST(ToolTableService, ChangesAreWholeAndSnapshotsStay) {
  Diagnostics d;
  MemoryToolTable tools(ToolTable::parse("T1 P1 Z10\nT2 P2 Z20\n", "t", d));
  const auto before = tools.snapshot();
  ToolEntry e = before->at_index(1);
  e.offset[Axis::Z] = 11;
  ASSERT_TRUE(tools.update(1, e, ChangeSource::Operator, d));
  EXPECT_EQ(before->at_index(1).offset[Axis::Z], 10);  // the snapshot taken before is unchanged
  EXPECT_EQ(tools.snapshot()->at_index(1).offset[Axis::Z], 11);
  EXPECT_EQ(tools.version(), 1u);
  ASSERT_TRUE(tools.update(1, e, ChangeSource::Operator, d));  // the same values: no change
  EXPECT_EQ(tools.version(), 1u);
  e.tool = 2;  // tool 2 is entry 2
  Diagnostics refused;
  EXPECT_FALSE(tools.update(1, e, ChangeSource::Operator, refused));
  EXPECT_EQ(refused.items().front().code, "tools.duplicate-tool");
  EXPECT_FALSE(tools.update(9, e, ChangeSource::Operator, refused));
  EXPECT_EQ(tools.version(), 1u);
}

TEST(FileToolTable, WritesTheFileBackAndKeepsItWhenItCannot) {
  TempDir dir;
  const auto path = dir.path() / "tools.tbl";
  std::ofstream(path) << "T1 P1 Z10 ;probe\n";
  Diagnostics d;
  auto tools = FileToolTable::open(path.string(), d);
  ASSERT_TRUE(tools != nullptr);
  ToolEntry e = tools->snapshot()->at_index(1);
  e.offset[Axis::Z] = 12.5;
  ASSERT_TRUE(tools->update(1, e, ChangeSource::Program, d));
  EXPECT_EQ(read(path), "T1 P1 Z12.5 ;probe\n");
  // Where the file was there is now a folder with something in it: nothing can replace it, not
  // even as root.
  std::filesystem::remove(path);
  std::filesystem::create_directories(path / "in-the-way");
  e.offset[Axis::Z] = 99;
  Diagnostics refused;
  EXPECT_FALSE(tools->update(1, e, ChangeSource::Program, refused));
  ASSERT_FALSE(refused.items().empty());
  EXPECT_EQ(refused.items().front().code, "tools.cannot-write");
  EXPECT_EQ(tools->snapshot()->at_index(1).offset[Axis::Z], 12.5);  // nothing changed
  EXPECT_EQ(tools->version(), 1u);
  std::size_t left = 0;  // and no temporary file is left behind
  for (const auto& entry : std::filesystem::directory_iterator(dir.path())) left += entry.path() != path ? 1 : 0;
  EXPECT_EQ(left, 0u);
}

TEST(FileToolTable, AFileWithErrorsOpensNothing) {
  TempDir dir;
  const auto path = dir.path() / "bad.tbl";
  std::ofstream(path) << "T1 P1 Z10\nT1 P2 Z11\n";
  Diagnostics d;
  EXPECT_EQ(FileToolTable::open(path.string(), d), nullptr);
  EXPECT_TRUE(d.has_errors());
}

}  // namespace

namespace {

TEST(FileToolTable, WritesThroughASymlinkAndKeepsTheModeAndRefusesAReadOnlyTable) {
  TempDir dir;
  const auto real = dir.path() / "real.tbl";
  const auto link = dir.path() / "tools.tbl";
  std::ofstream(real) << "T1 P1 Z10\n";
  std::filesystem::permissions(real, std::filesystem::perms::owner_read | std::filesystem::perms::owner_write |
                                         std::filesystem::perms::group_read);
  std::filesystem::create_symlink(real.filename(), link);
  Diagnostics d;
  auto tools = FileToolTable::open(link.string(), d);
  ASSERT_TRUE(tools != nullptr);
  ToolEntry e = tools->snapshot()->at_index(1);
  e.offset[Axis::Z] = 11;
  ASSERT_TRUE(tools->update(1, e, ChangeSource::Operator, d));
  EXPECT_TRUE(std::filesystem::is_symlink(link));  // the link stays, its target changed
  EXPECT_EQ(read(real), "T1 P1 Z11\n");
  EXPECT_EQ(std::filesystem::status(real).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write | std::filesystem::perms::group_read);
  std::filesystem::permissions(real, std::filesystem::perms::owner_read);
  e.offset[Axis::Z] = 12;
  Diagnostics refused;
  EXPECT_FALSE(tools->update(1, e, ChangeSource::Operator, refused));
  EXPECT_EQ(tools->snapshot()->at_index(1).offset[Axis::Z], 11);
  EXPECT_EQ(read(real), "T1 P1 Z11\n");
}

}  // namespace
