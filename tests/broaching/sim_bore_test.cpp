// SPDX-License-Identifier: GPL-3.0-or-later
// The simulated broach's workpiece beside the journal: round trip, and a torn or corrupt file refused.
#include <gtest/gtest.h>

#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

#include "opencnc/broaching/sim_bore.hpp"

namespace opencnc::recovery {
namespace {

SimBore sample() {
  SimBore b;
  b.program_hash = 0x0123456789abcdefull;
  b.signal_time_s = 3.2;
  for (int i = 0; i < 256 * 72; ++i) b.cells.push_back(static_cast<float>(i % 7) * 0.05f);
  return b;
}

TEST(SimBore, RoundTripsThroughItsFolder) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-sim-bore-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::string error;
  EXPECT_FALSE(load_sim_bore(dir.string(), &error).has_value());  // none yet: not an error
  EXPECT_EQ(error, "");
  ASSERT_TRUE(save_sim_bore(dir.string(), sample(), &error)) << error;
  const auto back = load_sim_bore(dir.string(), &error);
  ASSERT_TRUE(back.has_value()) << error;
  EXPECT_EQ(back->program_hash, sample().program_hash);
  EXPECT_EQ(back->signal_time_s, 3.2);
  EXPECT_EQ(back->cells, sample().cells);
  std::filesystem::remove_all(dir);
}

TEST(SimBore, ATornOrCorruptFileIsRefused) {
  const std::string bytes = encode_sim_bore(sample());
  std::string error;
  ASSERT_TRUE(decode_sim_bore(bytes, &error).has_value()) << error;
  for (std::size_t at : {std::size_t{2}, std::size_t{9}, bytes.size() / 2, bytes.size() - 1}) {
    std::string bad = bytes;
    bad[at] = static_cast<char>(bad[at] ^ 0x10);
    EXPECT_FALSE(decode_sim_bore(bad, &error).has_value()) << at;
    EXPECT_FALSE(error.empty());
  }
  EXPECT_FALSE(decode_sim_bore(std::string_view(bytes).substr(0, bytes.size() - 100), &error).has_value());
  EXPECT_NE(error.find("checksum"), std::string::npos) << error;
  EXPECT_FALSE(decode_sim_bore("", &error).has_value());
}

// The second hostile probe (issue 29): a symlink to /dev/zero in the journal's folder was read until
// memory ran out; a FIFO would block. Refused before a byte is read.
TEST(SimBore, ADeviceOrAFifoInItsPlaceIsRefusedAtOnce) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("opencnc-sim-bore-dev-" + std::to_string(::getpid()));
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
  std::filesystem::create_symlink("/dev/zero", dir / "sim-bore.bin");
  std::string error;
  EXPECT_FALSE(load_sim_bore(dir.string(), &error).has_value());
  EXPECT_EQ(error, "it is a device, not a file");
  std::filesystem::remove(dir / "sim-bore.bin");
  ASSERT_EQ(::mkfifo((dir / "sim-bore.bin").c_str(), 0600), 0);
  EXPECT_FALSE(load_sim_bore(dir.string(), &error).has_value());
  EXPECT_EQ(error, "it is a FIFO, not a file");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace opencnc::recovery
