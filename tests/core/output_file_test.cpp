// SPDX-License-Identifier: GPL-3.0-or-later
// Output files: inputs and other outputs refused, devices and pipes written in place, symlinks
// followed, read-only files and missing folders refused, whole records when the disk refuses data.
#include <fcntl.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <algorithm>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "opencnc/core/output_file.hpp"

namespace fs = std::filesystem;
using opencnc::NamedPath;
using opencnc::OutputFile;

namespace {

class OutputFileTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = fs::temp_directory_path() / fmt_dir();
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  void TearDown() override {
    std::error_code ec;
    fs::permissions(dir_, fs::perms::owner_all, fs::perm_options::add, ec);
    fs::remove_all(dir_, ec);
  }
  static std::string fmt_dir() {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    return std::string("opencnc-output-") + info->name() + "-" + std::to_string(::getpid());
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  static std::string slurp(const std::string& p) {
    std::ifstream in(p);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void put(const std::string& p, const std::string& text) { std::ofstream(p) << text; }
  /// Names in the folder (a temporary file left behind shows here).
  std::vector<std::string> entries() const {
    std::vector<std::string> out;
    for (const auto& e : fs::directory_iterator(dir_)) out.push_back(e.path().filename().string());
    std::sort(out.begin(), out.end());
    return out;
  }
  static std::string write_all(const NamedPath& what, const std::vector<std::string>& records,
                               bool* ok = nullptr) {
    std::string error;
    auto f = OutputFile::open(what, &error);
    if (!f) return "open: " + error;
    for (const std::string& r : records) f->write(r);
    const bool committed = f->commit(&error);
    if (ok != nullptr) *ok = committed;
    return committed ? "" : error;
  }

  fs::path dir_;
};

TEST_F(OutputFileTest, NewFileIsCreatedWhole) {
  const std::string p = path("r.json");
  EXPECT_EQ(write_all({"--report", p}, {"{\n", "}\n"}), "");
  EXPECT_EQ(slurp(p), "{\n}\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"r.json"});  // no temporary left
}

TEST_F(OutputFileTest, ExistingFileIsReplacedAndKeepsItsMode) {
  const std::string p = path("r.json");
  put(p, "old contents that are longer than the new ones\n");
  ASSERT_EQ(::chmod(p.c_str(), 0600), 0);
  EXPECT_EQ(write_all({"--report", p}, {"new\n"}), "");
  EXPECT_EQ(slurp(p), "new\n");
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_EQ(st.st_mode & 07777, 0600u);
}

TEST_F(OutputFileTest, ReadOnlyFileIsRefusedBeforeAnythingIsWritten) {
  const std::string p = path("r.json");
  put(p, "keep me\n");
  ASSERT_EQ(::chmod(p.c_str(), 0444), 0);
  std::string error;
  EXPECT_EQ(OutputFile::open({"--report", p}, &error), nullptr);
  EXPECT_NE(error.find("--report " + p + ": is read-only (mode 0444)"), std::string::npos) << error;
  EXPECT_EQ(slurp(p), "keep me\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"r.json"});
}

TEST_F(OutputFileTest, MissingFolderAndFolderAreRefusedNamingThePathGiven) {
  std::string error;
  const std::string missing = path("no/such/t.csv");
  EXPECT_EQ(OutputFile::open({"--trace", missing}, &error), nullptr);
  EXPECT_EQ(error, "--trace " + missing + ": the folder " + path("no/such") + " does not exist");
  EXPECT_EQ(OutputFile::open({"-o", dir_.string()}, &error), nullptr);
  EXPECT_EQ(error, "-o " + dir_.string() + ": is a folder, not a file");
}

TEST_F(OutputFileTest, SymlinkIsWrittenThroughAndStaysALink) {
  fs::create_directories(dir_ / "elsewhere");
  const std::string target = path("elsewhere/real.csv"), link = path("link.csv");
  put(target, "old\n");
  fs::create_symlink("elsewhere/real.csv", link);
  EXPECT_EQ(write_all({"--trace", link}, {"a,b\n", "1,2\n"}), "");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(target), "a,b\n1,2\n");
  // The temporary file was made beside the target, so nothing is left in either folder.
  EXPECT_EQ(entries(), (std::vector<std::string>{"elsewhere", "link.csv"}));
  EXPECT_EQ(fs::directory_iterator(dir_ / "elsewhere")->path().filename(), "real.csv");
}

TEST_F(OutputFileTest, DanglingSymlinkCreatesItsTarget) {
  const std::string link = path("link.svg");
  fs::create_symlink("made.svg", link);
  EXPECT_EQ(write_all({"-o", link}, {"<svg/>\n"}), "");
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(slurp(path("made.svg")), "<svg/>\n");
}

TEST_F(OutputFileTest, CharacterDeviceIsWrittenInPlace) {
  EXPECT_EQ(write_all({"--report", "/dev/null"}, {"x\n"}), "");
  struct stat st {};
  ASSERT_EQ(::stat("/dev/null", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST_F(OutputFileTest, FullDeviceNamesTheReason) {
  bool ok = true;
  const std::string error = write_all({"--report", "/dev/full"}, {"{}\n"}, &ok);
  EXPECT_FALSE(ok);
  EXPECT_EQ(error, "--report /dev/full: No space left on device (ENOSPC)");
  struct stat st {};
  ASSERT_EQ(::stat("/dev/full", &st), 0);
  EXPECT_TRUE(S_ISCHR(st.st_mode));
}

TEST_F(OutputFileTest, FifoIsWrittenInPlace) {
  const std::string p = path("pipe");
  ASSERT_EQ(::mkfifo(p.c_str(), 0600), 0);
  std::string got;
  std::thread reader([&] { got = slurp(p); });
  EXPECT_EQ(write_all({"--trace", p}, {"row 1\n", "row 2\n"}), "");
  reader.join();
  EXPECT_EQ(got, "row 1\nrow 2\n");
  struct stat st {};
  ASSERT_EQ(::stat(p.c_str(), &st), 0);
  EXPECT_TRUE(S_ISFIFO(st.st_mode));
}

TEST_F(OutputFileTest, WhatStandardOutputIsIsWrittenInPlace) {
  // `--report /dev/stdout > out.txt`: out.txt is the shell's, written where stdout writes.
  const std::string out = path("out.txt");
  put(out, "");
  const int saved = ::dup(STDOUT_FILENO);
  const int fd = ::open(out.c_str(), O_WRONLY | O_APPEND);
  ASSERT_GE(fd, 0);
  ASSERT_EQ(::write(fd, "before\n", 7), 7);
  ::dup2(fd, STDOUT_FILENO);
  const std::string error = write_all({"--report", "/dev/stdout"}, {"report\n"});
  const std::string dash = write_all({"--report", "-"}, {"dash\n"});
  ::dup2(saved, STDOUT_FILENO);
  ::close(saved);
  ::close(fd);
  EXPECT_EQ(error, "");
  EXPECT_EQ(dash, "");
  EXPECT_EQ(slurp(out), "before\nreport\ndash\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"out.txt"});
}

// The disk refusing data is what RLIMIT_FSIZE makes a write do (EFBIG instead of ENOSPC; the
// same path through the code).
class FileSizeLimit {
 public:
  explicit FileSizeLimit(rlim_t bytes) {
    ::getrlimit(RLIMIT_FSIZE, &saved_);
    old_handler_ = std::signal(SIGXFSZ, SIG_IGN);
    rlimit l = saved_;
    l.rlim_cur = bytes;
    ::setrlimit(RLIMIT_FSIZE, &l);
  }
  ~FileSizeLimit() {
    ::setrlimit(RLIMIT_FSIZE, &saved_);
    std::signal(SIGXFSZ, old_handler_);
  }

 private:
  rlimit saved_{};
  void (*old_handler_)(int) = nullptr;
};

TEST_F(OutputFileTest, RefusedDataLeavesWholeRecordsAndSaysWhy) {
  const std::string p = path("t.csv");
  const std::string row = "0.0010,running,feed,0,12,34,100.000000\n";  // 39 bytes
  std::string error;
  bool ok = true;
  std::uint64_t records = 0;
  {
    FileSizeLimit limit(100000);
    auto f = OutputFile::open({"--trace", p}, &error);
    ASSERT_NE(f, nullptr) << error;
    for (int i = 0; i < 10000; ++i) f->write(row);
    EXPECT_TRUE(f->failed());
    ok = f->commit(&error);
    records = f->records();
  }
  EXPECT_FALSE(ok);
  EXPECT_EQ(error, "--trace " + p + ": File too large (EFBIG)");
  const std::string got = slurp(p);
  EXPECT_GT(got.size(), 0u);
  EXPECT_LE(got.size(), 100000u);
  EXPECT_EQ(got.size() % row.size(), 0u);
  EXPECT_EQ(records, got.size() / row.size());
  EXPECT_EQ(got.back(), '\n');
}

TEST_F(OutputFileTest, ARecordThatDoesNotFitLeavesTheOldFile) {
  const std::string p = path("r.json");
  put(p, "old report\n");
  std::string error;
  bool ok = true;
  {
    FileSizeLimit limit(1000);
    error = write_all({"--report", p}, {std::string(5000, 'x') + "\n"}, &ok);
  }
  EXPECT_FALSE(ok);
  EXPECT_EQ(error, "--report " + p + ": File too large (EFBIG)");
  EXPECT_EQ(slurp(p), "old report\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"r.json"});
}

TEST_F(OutputFileTest, UncommittedOutputLeavesTheOldFile) {
  const std::string p = path("r.json");
  put(p, "old\n");
  {
    std::string error;
    auto f = OutputFile::open({"--report", p}, &error);
    ASSERT_NE(f, nullptr) << error;
    f->write("new\n");
    EXPECT_EQ(entries().size(), 2u);  // the temporary file, until the end
  }
  EXPECT_EQ(slurp(p), "old\n");
  EXPECT_EQ(entries(), std::vector<std::string>{"r.json"});
}

TEST_F(OutputFileTest, TemporariesCanBeRemovedFromASignalHandler) {
  std::string error;
  auto f = OutputFile::open({"--trace", path("t.csv")}, &error);
  ASSERT_NE(f, nullptr) << error;
  EXPECT_EQ(entries().size(), 1u);
  opencnc::remove_output_temporaries();
  EXPECT_TRUE(entries().empty());
}

TEST_F(OutputFileTest, OutputThatNamesAnInputIsRefused) {
  const std::string program = path("part.ngc");
  put(program, "G0 X1\nM2\n");
  const std::vector<NamedPath> inputs = {{"the program", program}, {"the profile", ""}};
  std::vector<NamedPath> outputs = {{"--trace", ""}, {"--report", program}};
  EXPECT_EQ(opencnc::output_conflict(inputs, outputs),
            "--report " + program + " is the program (" + program +
                "): opencnc never writes over an input; choose another file");
  // Through a symlink, a hard link and another spelling of the path.
  fs::create_symlink("part.ngc", path("link.ngc"));
  fs::create_hard_link(program, path("hard.ngc"));
  for (const std::string& other : {path("link.ngc"), path("hard.ngc"), path("./sub/../part.ngc")}) {
    fs::create_directories(dir_ / "sub");
    outputs = {{"--trace", other}};
    EXPECT_NE(opencnc::output_conflict(inputs, outputs), "") << other;
  }
  outputs = {{"--trace", path("t.csv")}, {"--report", path("r.json")}};
  EXPECT_EQ(opencnc::output_conflict(inputs, outputs), "");
}

TEST_F(OutputFileTest, TwoOutputsOnOneFileAreRefusedButDevicesMayBeShared) {
  const std::vector<NamedPath> none;
  const std::string t = path("t.csv");
  std::vector<NamedPath> outputs = {{"--trace", t}, {"--report", path("./t.csv")}};
  EXPECT_EQ(opencnc::output_conflict(none, outputs), "--trace " + t + " and --report " + path("./t.csv") +
                                                         " are the same file: give each output its own file");
  put(t, "");
  EXPECT_NE(opencnc::output_conflict(none, outputs), "");
  outputs = {{"--trace", "/dev/null"}, {"--report", "/dev/null"}, {"--csv", "-"}, {"--svg", "-"}};
  EXPECT_EQ(opencnc::output_conflict(none, outputs), "");
}

}  // namespace
