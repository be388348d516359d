// SPDX-License-Identifier: GPL-3.0-or-later
// The process log's part of `opencnc run`: --process-log FILE.csv|FILE.sqlite, the process data of
// the run at the profile's rate (docs/broaching.md).
#include <fmt/format.h>

#include "opencnc/process/process_log.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

class ProcessLogRun final : public RunFeature {
 public:
  void add_options(CLI::App& run) override {
    run.add_option(
        "--process-log", path_,
        "Write the process data (load, positions, feed, helix error) at the profile's rate "
        "([process.broaching] log_rate_hz, else 100 Hz) to FILE.csv or FILE.sqlite (docs/broaching.md)");
  }
  bool check_options() override {
    if (path_.empty()) return true;
    format_ = process::log_format(path_);
    if (!format_) {
      fmt::print(stderr, "error: --process-log {}: the name must end in .csv, .sqlite, .sqlite3 or .db\n",
                 path_);
      return false;
    }
    return true;
  }
  std::vector<NamedPath> outputs() const override { return {{"--process-log", path_}}; }
  void take_outputs(const std::vector<OutputFile*>& files) override {
    file_ = files.empty() ? nullptr : files[0];
  }
  bool check(const config::MachineProfile*, SessionOptions& session) override {
    program_ = session.file;
    return true;
  }
  void opened(const config::MachineProfile& machine, SessionObservers& out) override {
    if (file_ == nullptr) return;
    process::ProcessLogSetup setup{machine.axis_mask(),
                                   machine.broaching.present ? machine.broaching.log_rate_hz : 100.0,
                                   machine.servo_period_s,
                                   machine.coupling.present ? machine.coupling.radius_mm : 0.0,
                                   program_,
                                   machine.name};
    log_ = std::make_shared<process::ProcessLog>(setup, *format_, *file_);
    out.emplace_back(log_, controller::ObserverOptions{0, true});
  }
  bool report(nlohmann::json&) override {
    if (!log_) return true;
    std::string error;
    if (log_->finish(&error) && file_->commit(&error)) return true;
    fmt::print(stderr, "error: --process-log {}: {}\n", path_, error);
    return false;
  }

 private:
  std::string path_, program_;
  std::optional<process::LogFormat> format_;
  OutputFile* file_ = nullptr;
  std::shared_ptr<process::ProcessLog> log_;
};

}  // namespace

std::unique_ptr<RunFeature> process_log_run() {
  return std::make_unique<ProcessLogRun>();
}

}  // namespace opencnc::cli
