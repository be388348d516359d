// SPDX-License-Identifier: GPL-3.0-or-later
// The tool store's costs on a full magazine (40 tools, 2 edges each): one audited change (one
// fsync'ed WAL commit), a backup, the check against the backup, the 840D export and import.
// The store lives in the folder of $TMPDIR (default /tmp): the figures are that disk's.
#include <benchmark/benchmark.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "opencnc/store/tool_store.hpp"
#include "opencnc/tools/tool_check.hpp"
#include "opencnc/tools/tool_text.hpp"

namespace {

using opencnc::tools::Param;

opencnc::tools::ToolSet magazine() {
  opencnc::tools::ToolSet s;
  for (int t = 1; t <= 40; ++t) {
    s.tool_or_add(t).pocket = t;
    for (int d = 1; d <= 2; ++d) {
      auto& e = s.edge_or_add(t, d);
      e.set(Param::Type, 120);
      e.set(Param::Length1, 100 + t + 0.125 * d);
      e.set(Param::Radius, 2 + 0.5 * t);
      e.set(Param::WearLength1, -0.01 * d);
    }
  }
  return s;
}

struct Fixture {
  std::string path;
  std::shared_ptr<opencnc::store::ToolStore> store;
  Fixture() {
    path = (std::filesystem::temp_directory_path() / ("opencnc-bench-" + std::to_string(::getpid()) + ".db"))
               .string();
    std::filesystem::remove(path);
    std::string error;
    store = opencnc::store::ToolStore::open(path, &error);
    store->write(magazine(), "bench", "seed", &error);
    store->backup("bench", "backup", &error);
  }
  ~Fixture() {
    store.reset();
    for (const char* x : {"", "-wal", "-shm"}) std::filesystem::remove(path + x);
  }
};

void BM_SetOneValue(benchmark::State& state) {
  Fixture f;
  std::string error;
  int n = 0;
  for (auto _ : state) f.store->set(7, 1, Param::WearLength1, -0.001 * (++n % 50), "bench", &error);
}
BENCHMARK(BM_SetOneValue)->Unit(benchmark::kMillisecond);

void BM_Backup(benchmark::State& state) {
  Fixture f;
  std::string error;
  for (auto _ : state) f.store->backup("bench", "backup", &error);
}
BENCHMARK(BM_Backup)->Unit(benchmark::kMillisecond);

void BM_CheckAgainstBackup(benchmark::State& state) {
  Fixture f;
  const auto id = f.store->current_backup()->id;
  for (auto _ : state) {
    const auto b = f.store->backup_set(id);
    const auto l = f.store->live();
    benchmark::DoNotOptimize(opencnc::tools::check(*b, *l, {}));
  }
}
BENCHMARK(BM_CheckAgainstBackup)->Unit(benchmark::kMicrosecond);

void BM_Export840dAndReadBack(benchmark::State& state) {
  const auto s = magazine();
  for (auto _ : state) {
    const std::string text = opencnc::tools::format_840d(s, {1, "2026-11-26T03:10:56Z"});
    opencnc::Diagnostics d;
    benchmark::DoNotOptimize(opencnc::tools::parse_840d(text, "b.spf", d));
  }
}
BENCHMARK(BM_Export840dAndReadBack)->Unit(benchmark::kMicrosecond);

}  // namespace
