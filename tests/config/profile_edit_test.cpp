// SPDX-License-Identifier: GPL-3.0-or-later
// Editing one key of a profile's text (comments, layout and other values kept; what cannot be
// edited safely refused) and a whole profile edit validated by the profile's own loader.
#include <gtest/gtest.h>

#include <unistd.h>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "../support/drill_comp_file.hpp"
#include "opencnc/config/comp_file_edit.hpp"
#include "opencnc/config/profile_edit.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/config/toml_edit.hpp"
#include "opencnc/core/atomic_file.hpp"

namespace opencnc::config {
namespace {

const char* kText =
    "# a machine\n"
    "name = \"m\"\n"
    "\n"
    "[axis.X]   # the table\n"
    "  max_velocity = 100.0   # mm/s, the drive's limit\n"
    "max_acceleration=1000.0\n"
    "tags = [1, 2]  # an array\n"
    "\n"
    "# Y follows\n"
    "[axis.y]\n"
    "max_velocity = 50.0\n";

std::string set(std::string_view text, std::string_view key, std::string_view value,
                std::string* why = nullptr) {
  std::string error;
  const auto out = with_toml_value(text, key, value, error);
  if (why) *why = error;
  return out ? *out : "";
}

TEST(TomlEdit, OneValueChangesAndEveryCommentAndBlankStays) {
  std::string expected = kText;
  expected.replace(expected.find("100.0"), 5, "80.5");
  EXPECT_EQ(set(kText, "axis.x.max_velocity", "80.5"), expected);
  expected = kText;
  expected.replace(expected.find("=1000.0") + 1, 6, "250.0");
  EXPECT_EQ(set(kText, "axis.X.max_acceleration", "250.0"), expected);
  expected = kText;
  expected.replace(expected.find("[1, 2]"), 6, "[3]");
  EXPECT_EQ(set(kText, "axis.x.tags", "[3]"), expected);
}

TEST(TomlEdit, AKeyTheTableLacksIsAddedAfterItsLastKey) {
  const std::string out = set(kText, "axis.x.max_jerk", "5000.0");
  EXPECT_NE(out.find("tags = [1, 2]  # an array\nmax_jerk = 5000.0\n\n# Y follows\n"), std::string::npos)
      << out;
  EXPECT_NE(set(kText, "axis.y.min_limit", "-1.0").find("max_velocity = 50.0\nmin_limit = -1.0\n"),
            std::string::npos);
}

TEST(TomlEdit, RefusesWhatItCannotEditSafely) {
  std::string why;
  EXPECT_EQ(set(kText, "axis.z.max_velocity", "1.0", &why), "");
  EXPECT_NE(why.find("no [axis.z] table of its own"), std::string::npos) << why;
  EXPECT_EQ(set("[a]\nv = [1,\n 2]\n", "a.v", "[3]", &why), "");
  EXPECT_NE(why.find("spans more than one line"), std::string::npos) << why;
  EXPECT_EQ(set("[a]\ns = \"\"\"x\ny\"\"\"\n", "a.s", "\"z\"", &why), "");
  EXPECT_NE(why.find("spans more than one line"), std::string::npos) << why;
  EXPECT_EQ(set("[a]\nb.c = 1\n[a.b]\n", "a.b.c", "2", &why), "");  // a dotted key elsewhere
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(set("[a]\nb = { c = 1 }\n", "a.b.c", "2", &why), "");  // an inline table
  EXPECT_NE(why.find("no [a.b] table"), std::string::npos) << why;
  EXPECT_EQ(set(kText, "axis.x.max_velocity", "fast", &why), "");
  EXPECT_NE(why.find("not a TOML value"), std::string::npos) << why;
  EXPECT_EQ(set(kText, "axis.x.max_velocity", "1.0 # x\nname = 2", &why), "");
  EXPECT_EQ(set(kText, "max_velocity", "1.0", &why), "");
  EXPECT_NE(why.find("not a key inside a table"), std::string::npos) << why;
  EXPECT_EQ(set(kText, "axis.x.\"v\"", "1.0", &why), "");
  EXPECT_EQ(set("[a]\nv = 1\n[b]\n[a.c]\n", "a.v", "2"), "[a]\nv = 2\n[b]\n[a.c]\n");
}

TEST(TomlEdit, NumbersReadBackAsTheSameDouble) {
  EXPECT_EQ(toml_number(80), "80.0");
  EXPECT_EQ(toml_number(-0.0), "0.0");
  EXPECT_EQ(toml_number(1e-5), "1e-05");
  EXPECT_EQ(toml_number(0.1), "0.1");
}

class ProfileEditFile : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("opencnc-profile-edit-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    path_ = (dir_ / "mill.toml").string();
    std::ifstream in(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml");
    std::stringstream s;
    s << in.rdbuf();
    original_ = s.str();
    std::ofstream(path_) << original_;
    std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/mill-3axis.tbl", dir_ / "mill-3axis.tbl",
                               std::filesystem::copy_options::overwrite_existing);
    ProfileLoad load = load_profile(path_);
    ASSERT_TRUE(load.ok());
    live_ = *load.profile;
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  /// A copy of configs/<name>.toml and its tool table in a folder of its own (`tag`), loaded.
  void copy_profile(const std::string& tag, const std::string& name) {
    dir_ = std::filesystem::temp_directory_path() / (tag + "-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    for (const std::string& f : {name + ".toml", name + ".tbl"})
      std::filesystem::copy_file(std::string(OPENCNC_SOURCE_DIR "/configs/") + f, dir_ / f);
    path_ = (dir_ / (name + ".toml")).string();
    std::ifstream in(path_);
    std::stringstream s;
    s << in.rdbuf();
    original_ = s.str();
    ProfileLoad load = load_profile(path_);
    ASSERT_TRUE(load.ok());
    live_ = *load.profile;
  }
  std::filesystem::path dir_;
  std::string path_, original_;
  MachineProfile live_;
};

TEST_F(ProfileEditFile, AGoodValueGivesTheNewProfileAndTextWithOnlyThatLineChanged) {
  const ProfileKeyEdit edits[] = {{"axis.x.max_velocity", "80.0"}, {"axis.y.max_limit", "500.0"}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.profile->axes[0].max_velocity, 80.0);
  EXPECT_EQ(r.profile->axes[1].max_limit, 500.0);
  EXPECT_EQ(r.profile->source, path_);
  ASSERT_EQ(r.changes.size(), 2u);
  EXPECT_EQ(r.changes[0].key, "axis.x.max_velocity");
  EXPECT_EQ(r.changes[0].old_value, "100.0");
  EXPECT_EQ(r.changes[0].new_value, "80.0");
  std::string expected = original_;
  expected.replace(expected.find("max_velocity = 100.0"), 20, "max_velocity = 80.0");
  const std::size_t y = expected.find("[axis.y]");
  expected.replace(expected.find("max_limit = 2000.0", y), 18, "max_limit = 500.0");
  EXPECT_EQ(r.text, expected);
  EXPECT_EQ(r.profile->source_digest, text_digest(expected));
}

TEST_F(ProfileEditFile, ABadValueGetsTheLoadersMessageAtTheEditedLine) {
  const ProfileKeyEdit edits[] = {{"axis.x.max_velocity", "-5.0"}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_FALSE(r.ok());
  EXPECT_TRUE(r.error.empty());
  ASSERT_FALSE(r.diagnostics.items().empty());
  const Diagnostic& d = r.diagnostics.items().front();
  EXPECT_EQ(d.file, path_);
  const std::size_t at = original_.find("max_velocity = 100.0");
  EXPECT_EQ(d.line, 1 + std::count(original_.begin(), original_.begin() + static_cast<long>(at), '\n'));
  EXPECT_NE(d.format().find(path_ + ":" + std::to_string(d.line) + ":"), std::string::npos) << d.format();
  const ProfileKeyEdit inverted[] = {{"axis.z.min_limit", "3000.0"}};
  EXPECT_FALSE(edit_profile(live_, inverted).ok());
}

// Soft limits narrowed past the tool-change position would let M6 move outside them: the edit
// is refused with the loader's message at the position's axis.
TEST_F(ProfileEditFile, LimitsThatLeaveTheToolChangePositionOutsideAreRefusedAtThePosition) {
  std::ofstream(path_) << original_ << "\n[tool_change]\nposition = { X = 0.0, Z = 150.0 }\n";
  const ProfileLoad load = load_profile(path_);
  ASSERT_TRUE(load.ok());
  const ProfileKeyEdit edits[] = {{"axis.z.max_limit", "100.0"}};
  const ProfileEditResult r = edit_profile(*load.profile, edits);
  ASSERT_FALSE(r.ok());
  ASSERT_FALSE(r.diagnostics.items().empty());
  const Diagnostic& d = r.diagnostics.items().front();
  EXPECT_EQ(d.code, "config.range");
  EXPECT_EQ(d.file, path_);
  EXPECT_EQ(d.line, 3 + std::count(original_.begin(), original_.end(), '\n'));
  EXPECT_EQ(d.col, 27u);
  EXPECT_NE(d.message.find("tool_change.position.Z = 150 mm is outside Z's soft limits"), std::string::npos)
      << d.message;
  const ProfileKeyEdit wider[] = {{"axis.z.max_limit", "150.0"}};  // on the limit is inside
  EXPECT_TRUE(edit_profile(*load.profile, wider).ok());
}

TEST_F(ProfileEditFile, KeysThatAreNotEditableOrOverriddenAndAChangedFileAreRefused) {
  const ProfileKeyEdit homing[] = {{"axis.x.homing.position", "1.0"}};
  EXPECT_NE(edit_profile(live_, homing).error.find("not a parameter that can be changed here"),
            std::string::npos);
  const ProfileKeyEdit period[] = {{"servo_period_s", "0.002"}};
  EXPECT_FALSE(edit_profile(live_, period).error.empty());
  ProfileLoad over = load_profile(path_, std::vector<std::string>{"axis.X.max_velocity=50"});
  ASSERT_TRUE(over.ok());
  const ProfileKeyEdit v[] = {{"axis.x.max_velocity", "80.0"}};
  EXPECT_NE(edit_profile(*over.profile, v).error.find("override"), std::string::npos);
  std::ofstream(path_, std::ios::app) << "# touched\n";
  EXPECT_NE(edit_profile(live_, v).error.find("changed on disk"), std::string::npos);
}

TEST(TomlEdit, AKeyIsRemovedWithItsLineOnly) {
  std::string why;
  const auto out = without_toml_key(kText, "axis.x.tags", why);
  ASSERT_TRUE(out) << why;
  std::string expected = kText;
  expected.erase(expected.find("tags = [1, 2]  # an array\n"), 26);
  EXPECT_EQ(*out, expected);
  EXPECT_FALSE(without_toml_key(kText, "axis.x.none", why));
  EXPECT_NE(why.find("no none"), std::string::npos) << why;
}

/// The drill's profile: X's pitch table written as `errors` (both directions), Y's per direction.
class ProfileEditTable : public ProfileEditFile {
 protected:
  void SetUp() override { copy_profile("opencnc-table-edit", "drill-retrofit"); }
};

TEST_F(ProfileEditTable, EqualDirectionsKeepTheOneTableAndItsComments) {
  const std::string errors =
      "[0.0, 0.003, 0.006, 0.012, 0.015, 0.018, 0.022, 0.027, 0.028, 0.030, 0.033, 0.037, 0.040]";
  const ProfileKeyEdit edits[] = {{"axis.x.compensation.forward", errors},
                                  {"axis.x.compensation.reverse", errors}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.profile->axes[0].compensation.forward[3], 0.012);
  EXPECT_TRUE(r.profile->axes[0].compensation.one_table);
  std::string expected = original_;
  const std::size_t at = expected.find("errors = [");
  expected.replace(at, expected.find('\n', at) - at, "errors = " + errors);
  EXPECT_EQ(r.text, expected);
  ASSERT_EQ(r.changes.size(), 2u);
  EXPECT_EQ(r.changes[0].old_value, "13 points");
  EXPECT_EQ(r.changes[0].new_value, "13 points, 1 changed (largest 0.01 → 0.012 at 150.0)");
}

TEST_F(ProfileEditTable, DifferentDirectionsReplaceErrorsAndAnotherLengthMovesThePoints) {
  const ProfileKeyEdit edits[] = {{"axis.x.compensation.forward", "[0.0, 0.01, 0.02]"},
                                  {"axis.x.compensation.reverse", "[0.005, 0.015, 0.025]"},
                                  {"axis.x.compensation.interval", "100.0"}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error;
  const CompensationProfile& c = r.profile->axes[0].compensation;
  EXPECT_FALSE(c.one_table);
  EXPECT_EQ(c.positions, (std::vector<double>{0, 100, 200}));
  EXPECT_EQ(c.reverse[2], 0.025);
  EXPECT_EQ(r.text.find("errors = ["), std::string::npos);
  EXPECT_NE(r.text.find("forward = [0.0, 0.01, 0.02]\n"), std::string::npos);
  EXPECT_NE(r.text.find("# The seed's table as it entered it"), std::string::npos);  // comments stay
  EXPECT_EQ(r.changes[2].new_value, "100.0");
  EXPECT_EQ(r.changes[0].new_value, "3 points");
}

TEST_F(ProfileEditTable, ABadTableGetsTheLoadersMessageAndOneDirectionOfOneTableIsRefused) {
  const ProfileKeyEdit steep[] = {
      {"axis.y.compensation.forward", "[0, -0.002, -0.004, -0.0045, -0.005, -0.007, -0.009, -0.0105, 0.9]"}};
  const ProfileEditResult r = edit_profile(live_, steep);
  ASSERT_FALSE(r.ok());
  ASSERT_FALSE(r.diagnostics.items().empty());
  const Diagnostic& d = r.diagnostics.items().front();
  EXPECT_EQ(d.file, path_);
  const std::size_t at = original_.find("forward = [0, -0.002");
  EXPECT_EQ(d.line, 1 + std::count(original_.begin(), original_.begin() + static_cast<long>(at), '\n'));
  const ProfileKeyEdit unequal[] = {{"axis.y.compensation.reverse", "[0.015, 0.013]"}};
  EXPECT_FALSE(edit_profile(live_, unequal).ok());
  const ProfileKeyEdit one[] = {{"axis.x.compensation.forward", "[0.0, 0.01]"}};
  EXPECT_NE(edit_profile(live_, one).error.find("give forward and reverse together"), std::string::npos);
  const ProfileKeyEdit none[] = {{"axis.z.compensation.forward", "[0.0]"}};
  EXPECT_NE(edit_profile(live_, none).error.find("no [axis.z.compensation]"), std::string::npos);
  EXPECT_TRUE(is_pitch_table_key("axis.x.compensation.interval"));
  EXPECT_FALSE(is_pitch_table_key("axis.x.compensation.errors"));
}

/// The drill's profile with Y's table in a LinuxCNC comp file (type 0) beside it.
class ProfileEditCompFile : public ProfileEditFile {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() / ("opencnc-comp-edit-" + std::to_string(::getpid()));
    std::filesystem::create_directories(dir_);
    std::string text;
    ASSERT_TRUE(read_file(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.toml", text, nullptr));
    original_ = opencnc::test::drill_with_y_comp_file(text);
    ASSERT_FALSE(original_.empty());
    path_ = (dir_ / "drill-retrofit.toml").string();
    comp_ = (dir_ / opencnc::test::kDrillYCompName).string();
    ASSERT_TRUE(write_file_atomically(path_, original_, nullptr));
    ASSERT_TRUE(write_file_atomically(comp_, opencnc::test::kDrillYComp, nullptr));
    std::filesystem::copy_file(OPENCNC_SOURCE_DIR "/configs/drill-retrofit.tbl", dir_ / "drill-retrofit.tbl");
    ProfileLoad load = load_profile(path_);
    ASSERT_TRUE(load.ok()) << (load.diagnostics.items().empty() ? "" : load.diagnostics.items()[0].format());
    live_ = *load.profile;
  }
  std::string comp_;
};

// The table written into the comp file (the profile's text unchanged, the comment lines where
// they were, a point added after the last); the file as written loads to the same table.
TEST_F(ProfileEditCompFile, TheTableIsWrittenIntoTheCompFileAndLoadsBackTheSame) {
  const CompensationProfile& was = live_.axes[1].compensation;
  ASSERT_EQ(was.comp_file, opencnc::test::kDrillYCompName);
  EXPECT_EQ(was.comp_path, comp_);
  EXPECT_NEAR(was.forward[4], -0.005, 1e-12);
  const ProfileKeyEdit edits[] = {
      {"axis.y.compensation.forward",
       "[0, -0.002, -0.004, -0.0045, -0.006, -0.007, -0.009, -0.0105, -0.012, -0.013]"},
      {"axis.y.compensation.reverse",
       "[0.015, 0.013, 0.011, 0.0105, 0.01, 0.008, 0.006, 0.0045, 0.003, 0.002]"},
      {"axis.y.compensation.positions", "[0, 50, 100, 150, 200, 250, 300, 350, 400, 440]"}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error << (r.diagnostics.items().empty() ? "" : r.diagnostics.items()[0].format());
  EXPECT_EQ(r.text, original_);
  ASSERT_EQ(r.files.size(), 1u);
  EXPECT_EQ(r.files[0].path, comp_);
  const std::string expected =
      "# Y's lead screw by laser: nominal, reached moving up, reached moving down (mm)\n"
      "0 0 0.015\n50 49.998 50.013\n100 99.996 100.011\n150 149.9955 150.0105\n"
      "# the middle of the screw\n"
      "200 199.994 200.01\n250 249.993 250.008\n300 299.991 300.006\n350 349.9895 350.0045\n"
      "400 399.988 400.003\n440 439.987 440.002\n";
  EXPECT_EQ(r.files[0].text, expected);
  ASSERT_EQ(r.changes.size(), 3u);
  EXPECT_EQ(r.changes[0].old_value, "9 points");
  EXPECT_EQ(r.changes[0].new_value, "10 points");
  ASSERT_TRUE(write_file_atomically(comp_, r.files[0].text, nullptr));
  const ProfileLoad again = load_profile(path_);
  ASSERT_TRUE(again.ok());
  const CompensationProfile& now = again.profile->axes[1].compensation;
  const CompensationProfile& edited = r.profile->axes[1].compensation;
  EXPECT_EQ(now.positions, edited.positions);
  EXPECT_EQ(now.forward, edited.forward);
  EXPECT_EQ(now.reverse, edited.reverse);
  EXPECT_NEAR(now.forward[4], -0.006, 1e-12);  // type 0 holds positions: the error is x' − x
  EXPECT_NEAR(now.reverse[9], 0.002, 1e-12);
  EXPECT_EQ(now.positions.back(), 440.0);
  // The same table again: each point unchanged.
  const ProfileKeyEdit same[] = {
      {"axis.y.compensation.forward",
       "[0, -0.002, -0.004, -0.0045, -0.006, -0.007, -0.009, -0.0105, -0.012, -0.013]"}};
  const ProfileEditResult r2 = edit_profile(*again.profile, same);
  ASSERT_TRUE(r2.ok()) << r2.error;
  EXPECT_EQ(r2.files[0].text, expected);
  EXPECT_EQ(r2.changes[0].new_value, "10 points, unchanged");
}

// Type 1 holds the trims (−error), written back exactly; fewer points drop the number lines past
// them and keep every comment line.
TEST(CompFileText, TrimsAreTheNegativeErrorAndCommentsStay) {
  const double x[] = {-10, 0}, f[] = {0.005, -0.002}, r[] = {-0.005, 0.003};
  EXPECT_EQ(comp_file_with_table("# head\n-10 1 1\n\n# mid\n0 1 1\n10 1 1\n# tail", 1, x, f, r),
            "# head\n-10 -0.005 0.005\n\n# mid\n0 0.002 -0.003\n# tail\n");
}

// A table the loader refuses gets its message at the comp file's line; refusals of the request
// itself; nothing is written by edit_profile.
TEST_F(ProfileEditCompFile, ABadTableGetsTheLoadersMessageAtTheCompFilesLine) {
  const ProfileKeyEdit back[] = {
      {"axis.y.compensation.positions", "[0, 50, 100, 150, 150, 250, 300, 350, 400]"}};
  const ProfileEditResult r = edit_profile(live_, back);
  ASSERT_FALSE(r.ok());
  ASSERT_FALSE(r.diagnostics.items().empty());
  const Diagnostic& d = r.diagnostics.items().front();
  EXPECT_EQ(d.file, comp_);
  EXPECT_EQ(d.line, 7u);  // the fifth point, after the head comment and the middle one
  EXPECT_EQ(d.col, 1u);
  EXPECT_NE(d.message.find("nominal positions must increase"), std::string::npos) << d.message;
  const ProfileKeyEdit steep[] = {{"axis.y.compensation.forward", "[0, 0, 0, 0, 0, 0, 0, 0, 2]"}};
  const ProfileEditResult s = edit_profile(live_, steep);
  ASSERT_FALSE(s.ok());
  EXPECT_EQ(s.diagnostics.items().front().file, path_);  // the slope: at the profile's comp_file
  const ProfileKeyEdit interval[] = {{"axis.y.compensation.interval", "100"}};
  EXPECT_NE(edit_profile(live_, interval).error.find("give positions"), std::string::npos);
  const ProfileKeyEdit longer[] = {{"axis.y.compensation.forward", "[0, 0]"}};
  EXPECT_NE(edit_profile(live_, longer).error.find("2 forward"), std::string::npos);
  const ProfileKeyEdit text[] = {{"axis.y.compensation.reverse", "[0, \"a\"]"}};
  EXPECT_NE(edit_profile(live_, text).error.find("finite numbers"), std::string::npos);
  const ProfileKeyEdit x_positions[] = {{"axis.x.compensation.positions", "[0, 1]"}};
  EXPECT_NE(edit_profile(live_, x_positions).error.find("give start and interval"), std::string::npos);
  std::string now;
  ASSERT_TRUE(read_file(comp_, now, nullptr));
  EXPECT_EQ(now, opencnc::test::kDrillYComp);
  ASSERT_TRUE(write_file_atomically(comp_, now + "# touched\n", nullptr));
  EXPECT_NE(edit_profile(live_, steep).error.find("changed on disk"), std::string::npos);
}

const char* kConditions =
    "[edm]\n"
    "tool_axis = \"Z\"\n"
    "\n"
    "# roughing\n"
    "[[edm.condition]]\n"
    "number = 1\n"
    "on_time_us = 100.0   # long pulses\n"
    "\n"
    "[[ edm.condition ]]  # finishing\n"
    "number = 3\n"
    "on_time_us = 15.0\n"
    "\n"
    "# the sim\n"
    "[edm.sim]\n"
    "surface_mm = -20.0\n";

std::string set_element(std::string_view text, int element, std::string_view key, std::string_view value,
                        std::string* why = nullptr) {
  std::string error;
  const auto out = with_toml_element_value(text, "edm.condition", element, key, value, error);
  if (why) *why = error;
  return out ? *out : "";
}

TEST(TomlEdit, AnElementOfAnArrayOfTablesIsEditedInItsOwnLinesOnly) {
  std::string expected = kConditions;
  expected.replace(expected.find("15.0"), 4, "20.0");
  EXPECT_EQ(set_element(kConditions, 1, "on_time_us", "20.0"), expected);
  expected = kConditions;
  expected.replace(expected.find("100.0"), 5, "60.0");  // the comment stays
  EXPECT_EQ(set_element(kConditions, 0, "ON_TIME_US", "60.0"), expected);
  expected = kConditions;  // a key the element lacks: after its last key, before the blank line
  expected.insert(expected.find("on_time_us = 15.0\n") + 18, "polarity = \"-\"\n");
  EXPECT_EQ(set_element(kConditions, 1, "polarity", "\"-\""), expected);
  std::string why;
  const auto out = without_toml_element_key(kConditions, "edm.condition", 0, "on_time_us", why);
  ASSERT_TRUE(out) << why;
  expected = kConditions;
  expected.erase(expected.find("on_time_us = 100.0"), 35);
  EXPECT_EQ(*out, expected);
}

TEST(TomlEdit, AnElementThatIsNotWrittenUnderAHeaderOfItsOwnIsRefused) {
  std::string why;
  EXPECT_EQ(set_element(kConditions, 2, "on_time_us", "1.0", &why), "");
  EXPECT_NE(why.find("no [[edm.condition]] #3 table"), std::string::npos) << why;
  EXPECT_EQ(set_element(kConditions, -1, "on_time_us", "1.0", &why), "");
  EXPECT_FALSE(why.empty());
  // Two elements of an inline array then one under a header: the header is element 3, not 1.
  const char* mixed = "[edm]\ncondition = [{number = 1}, {number = 2}]\n";
  EXPECT_EQ(set_element(mixed, 0, "number", "5", &why), "");
  EXPECT_FALSE(why.empty());
  EXPECT_EQ(set_element(kConditions, 0, "on_time_us", "[1,\n2]", &why), "");
  EXPECT_NE(why.find("not one TOML value on one line"), std::string::npos) << why;
}

TEST(TomlEdit, AnElementIsCopiedAfterTheLastOneWithItsKeysAndNoComments) {
  std::string why;
  const auto out = with_toml_element_copy(kConditions, "edm.condition", 0, "number", "7", "a copy", why);
  ASSERT_TRUE(out) << why;
  std::string expected = kConditions;  // after condition 3, before the comment that leads into the sim
  expected.insert(expected.find("\n# the sim"),
                  "\n# a copy\n[[edm.condition]]\nnumber = 7\non_time_us = 100.0\n");
  EXPECT_EQ(*out, expected);
  const auto last = with_toml_element_copy(kConditions, "edm.condition", 1, "jump", "true", "", why);
  ASSERT_TRUE(last) << why;  // a key the source lacks comes after its own; no comment line
  expected = kConditions;
  expected.insert(expected.find("\n# the sim"),
                  "\n[[ edm.condition ]]\nnumber = 3\non_time_us = 15.0\njump = true\n");
  EXPECT_EQ(*last, expected);
  EXPECT_FALSE(with_toml_element_copy(kConditions, "edm.condition", 2, "number", "7", "", why));
  EXPECT_NE(why.find("not written under a [[edm.condition]] header"), std::string::npos) << why;
  EXPECT_FALSE(with_toml_element_copy("[edm]\ncondition = [{number = 1}]\n", "edm.condition", 0, "number", "7",
                                      "", why));
  EXPECT_FALSE(with_toml_element_copy("[[edm.condition]]\nnumber = 1\nlist = [1, 2]\n", "edm.condition", 0,
                                      "number", "7", "", why));
  EXPECT_NE(why.find("list is not a number"), std::string::npos) << why;
}

TEST(TomlEdit, AnElementIsRemovedWithTheCommentAboveItAndEveryOtherLineStays) {
  std::string why;
  const auto first = without_toml_element(kConditions, "edm.condition", 0, why);
  ASSERT_TRUE(first) << why;
  std::string expected = kConditions;
  expected.erase(expected.find("\n# roughing"), std::string_view("\n# roughing\n[[edm.condition]]\nnumber = 1\n"
                                                                  "on_time_us = 100.0   # long pulses\n")
                                                     .size());
  EXPECT_EQ(*first, expected);
  const auto second = without_toml_element(kConditions, "edm.condition", 1, why);
  ASSERT_TRUE(second) << why;
  expected = kConditions;  // its header's own comment goes with it; the sim's comment stays
  expected.erase(expected.find("\n[[ edm.condition ]]"),
                 std::string_view("\n[[ edm.condition ]]  # finishing\nnumber = 3\non_time_us = 15.0\n").size());
  EXPECT_EQ(*second, expected);
  EXPECT_FALSE(without_toml_element(kConditions, "edm.condition", 2, why));
  // A sub-table of the element would be left to the one before: refused.
  EXPECT_FALSE(without_toml_element("[[a.b]]\nx = 1\n[[a.b]]\nx = 2\n[a.b.c]\ny = 1\n", "a.b", 1, why));
  EXPECT_NE(why.find("remove it by hand"), std::string::npos) << why;
}

/// The EDM's profile (four conditions) and its tool table in a directory of their own.
class ProfileEditConditions : public ProfileEditFile {
 protected:
  void SetUp() override { copy_profile("opencnc-condition-edit", "edm-5axis"); }
};

TEST_F(ProfileEditConditions, AConditionsFieldsChangeInItsElementAndTheAuditSaysWhichAndHow) {
  const ProfileKeyEdit edits[] = {{"edm.condition.3.on_time_us", "20.0"},
                                  {"edm.condition.9.polarity", "\"-\""},
                                  {"edm.condition.2.orbit", "\"star\""}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error;
  EXPECT_EQ(r.profile->edm.config.find(3)->on_time_us, 20.0);
  EXPECT_EQ(r.profile->edm.config.find(1)->on_time_us, 100.0);  // the other conditions' stay
  EXPECT_EQ(r.profile->edm.config.find(9)->polarity, -1);
  EXPECT_EQ(r.profile->edm.config.find(2)->orbit, machine::OrbitKind::Star);
  ASSERT_EQ(r.changes.size(), 3u);
  EXPECT_EQ(r.changes[0].key, "edm.condition.3.on_time_us");
  EXPECT_EQ(r.changes[0].old_value, "15.0");
  EXPECT_EQ(r.changes[0].new_value, "20.0");
  EXPECT_EQ(r.changes[1].old_value, "+");
  EXPECT_EQ(r.changes[1].new_value, "-");
  EXPECT_EQ(r.changes[2].new_value, "star");
  std::string expected = original_;
  expected.replace(expected.find("on_time_us = 15.0"), 17, "on_time_us = 20.0");
  expected.replace(expected.find("orbit = \"circle\""), 16, "orbit = \"star\"");
  const std::size_t nine = expected.find("number = 9");
  const std::size_t after = expected.find("max_retract_mm_s = 3.0\n", nine) + 23;
  expected.insert(after, "polarity = \"-\"\n");
  EXPECT_EQ(r.text, expected);
}

// Issue 28's keys: the finishing cycle, its time limit, the lateral servo, adaptive control and its
// bounds are edited as the others (a boolean as a TOML boolean); bounds that no longer enclose the
// condition's value get the loader's message and change nothing.
TEST_F(ProfileEditConditions, TheFinishingAndAdaptiveKeysAreEditedAsTheOthers) {
  const ProfileKeyEdit edits[] = {{"edm.condition.3.adaptive", "false"},
                                  {"edm.condition.3.finish_timeout_s", "30.0"},
                                  {"edm.condition.3.gain_max_mm_s_per_v", "0.1"},
                                  {"edm.condition.2.orbit_finish", "true"},
                                  {"edm.condition.2.lateral_servo", "false"}};
  const ProfileEditResult r = edit_profile(live_, edits);
  ASSERT_TRUE(r.ok()) << r.error;
  const machine::EdmCondition& three = *r.profile->edm.config.find(3);
  EXPECT_FALSE(three.adaptive);
  EXPECT_EQ(three.finish_timeout_s, 30.0);
  EXPECT_EQ(three.gain_max_mm_s_per_v, 0.1);
  EXPECT_TRUE(r.profile->edm.config.find(2)->orbit_finish);
  EXPECT_FALSE(r.profile->edm.config.find(2)->lateral_servo);
  ASSERT_EQ(r.changes.size(), 5u);
  EXPECT_EQ(r.changes[0].old_value, "true");
  EXPECT_EQ(r.changes[0].new_value, "false");
  EXPECT_EQ(r.changes[1].old_value, "60.0");
  EXPECT_EQ(r.changes[1].new_value, "30.0");
  EXPECT_NE(r.text.find("adaptive = false"), std::string::npos);
  EXPECT_NE(r.text.find("finish_timeout_s = 30.0"), std::string::npos);
  // A bound that leaves the condition's own value outside: the loader's words at its line.
  const ProfileKeyEdit bound[] = {{"edm.condition.3.gain_min_mm_s_per_v", "0.5"}};
  const ProfileEditResult refused = edit_profile(live_, bound);
  ASSERT_FALSE(refused.ok());
  ASSERT_FALSE(refused.diagnostics.items().empty());
  EXPECT_NE(refused.diagnostics.items().front().message.find("must enclose the condition's own value"),
            std::string::npos)
      << refused.diagnostics.items().front().message;
  // A boolean written as a word is not one.
  const ProfileKeyEdit word[] = {{"edm.condition.3.adaptive", "\"yes\""}};
  EXPECT_FALSE(edit_profile(live_, word).ok());
  EXPECT_TRUE(is_condition_key("edm.condition.3.jump_height_max_mm"));
}

TEST_F(ProfileEditConditions, ABadValueGetsTheLoadersMessageAndUnknownConditionsOrFieldsAreRefused) {
  const ProfileKeyEdit high[] = {{"edm.condition.1.servo_reference_v", "120.0"}};  // above voltage_v
  const ProfileEditResult r = edit_profile(live_, high);
  ASSERT_FALSE(r.ok());
  ASSERT_FALSE(r.diagnostics.items().empty());
  const Diagnostic& d = r.diagnostics.items().front();
  EXPECT_EQ(d.file, path_);
  const std::size_t at = original_.find("servo_reference_v = 45.0");
  EXPECT_EQ(d.line, 1 + std::count(original_.begin(), original_.begin() + static_cast<long>(at), '\n'));
  EXPECT_NE(d.message.find("must be below voltage_v"), std::string::npos) << d.message;
  const ProfileKeyEdit word[] = {{"edm.condition.1.polarity", "\"x\""}};
  EXPECT_FALSE(edit_profile(live_, word).ok());
  const ProfileKeyEdit missing[] = {{"edm.condition.4.on_time_us", "1.0"}};
  EXPECT_NE(edit_profile(live_, missing).error.find("no machining condition 4"), std::string::npos);
  const ProfileKeyEdit field[] = {{"edm.condition.1.side_gap_mm", "0.1"}};
  EXPECT_NE(edit_profile(live_, field).error.find("not a field of a machining condition"), std::string::npos);
  EXPECT_TRUE(is_condition_key("edm.condition.12.jump_mode"));
  EXPECT_FALSE(is_condition_key("edm.condition.0.jump_mode"));
  EXPECT_FALSE(is_condition_key("edm.condition.x.on_time_us"));
}

TEST_F(ProfileEditConditions, AConditionIsAddedAsACopyAndAnotherDeletedWithTheAuditOfEach) {
  const ConditionChange changes[] = {{4, false, 3}, {9, true, 0}};
  const ProfileEditResult r = edit_profile(live_, {}, changes);
  ASSERT_TRUE(r.ok()) << r.error;
  const machine::EdmConfig& edm = r.profile->edm.config;
  ASSERT_EQ(edm.condition_count, 4);
  EXPECT_EQ(edm.find(9), nullptr);
  ASSERT_NE(edm.find(4), nullptr);
  const machine::EdmCondition& copy = *edm.find(4);
  const machine::EdmCondition& three = *live_.edm.config.find(3);
  for (const ConditionField& f : condition_fields())
    EXPECT_EQ(condition_field_text(copy, f.key), condition_field_text(three, f.key)) << f.key;
  EXPECT_EQ(copy.side_gap_mm, three.side_gap_mm);
  EXPECT_EQ(copy.electrode_wear_ratio, three.electrode_wear_ratio);
  ASSERT_EQ(r.changes.size(), 2u);
  EXPECT_EQ(r.changes[0].key, "edm.condition.4");
  EXPECT_EQ(r.changes[0].new_value, "a copy of condition 3");
  EXPECT_EQ(r.changes[1].key, "edm.condition.9");
  EXPECT_EQ(r.changes[1].new_value, "deleted");
  // Condition 9 and its comment are gone, 4 stands where 9 stood; the others' comments stay.
  EXPECT_EQ(r.text.find("a test's condition"), std::string::npos);
  EXPECT_NE(r.text.find("# Finishing: 2 A"), std::string::npos);
  EXPECT_NE(r.text.find("# Condition 4: a copy of condition 3.\n[[edm.condition]]\nnumber = 4\n"), std::string::npos);
  EXPECT_LT(r.text.find("number = 4"), r.text.find("[edm.sim]"));
}

TEST_F(ProfileEditConditions, AddsAndDeletesThatCannotBeAreRefusedWithWhy) {
  const auto refusal = [&](std::vector<ConditionChange> c, std::vector<ProfileKeyEdit> e = {}) {
    const ProfileEditResult r = edit_profile(live_, e, c);
    EXPECT_FALSE(r.ok());
    return r.error;
  };
  EXPECT_NE(refusal({{3, false, 1}}).find("condition 3 exists already"), std::string::npos);
  EXPECT_NE(refusal({{100, false, 1}}).find("1 to 99, not 100"), std::string::npos);
  EXPECT_NE(refusal({{5, false, 6}}).find("no condition 6 to copy"), std::string::npos);
  EXPECT_NE(refusal({{5, false, 1}, {5, false, 2}}).find("condition 5 exists already"), std::string::npos);
  EXPECT_NE(refusal({{6, true}}).find("no machining condition 6 to delete"), std::string::npos);
  EXPECT_NE(refusal({{3, true}}, {{"edm.condition.3.on_time_us", "20.0"}}).find("deleted and changed"),
            std::string::npos);
  EXPECT_NE(refusal({{1, true}, {2, true}, {3, true}, {9, true}}).find("last machining condition"),
            std::string::npos);
  std::vector<ConditionChange> many;  // 4 + 28 fill the table; one more does not fit
  for (int n = 10; n < 10 + machine::kMaxEdmConditions - 3; ++n) many.push_back({n, false, 1});
  EXPECT_NE(refusal(many).find("at most 32 machining conditions"), std::string::npos);
  many.pop_back();
  EXPECT_TRUE(edit_profile(live_, {}, many).ok());
  EXPECT_EQ(condition_to_copy(live_.edm.config, 5), 3);
  EXPECT_EQ(condition_to_copy(live_.edm.config, 1), 1);
  EXPECT_EQ(condition_to_copy(live_.edm.config, 99), 9);
}

TEST(ProfileEdit, TheEditableParametersAreEachAxisLimits) {
  ProfileLoad load = load_profile(OPENCNC_SOURCE_DIR "/configs/mill-3axis.toml");
  ASSERT_TRUE(load.ok());
  const auto params = editable_parameters(*load.profile);
  ASSERT_EQ(params.size(), 15u);
  EXPECT_EQ(params[0].key, "axis.x.max_velocity");
  EXPECT_EQ(params[0].value, 100.0);
  EXPECT_EQ(params[0].unit, "mm/s");
  EXPECT_EQ(params[14].key, "axis.z.max_following_error");
}

}  // namespace
}  // namespace opencnc::config
