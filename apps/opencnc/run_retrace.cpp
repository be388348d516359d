// SPDX-License-Identifier: GPL-3.0-or-later
// Retrace's part of `opencnc run`: the operator of a flame/plasma retrace scripted (--retrace), and
// the retraces in the report (docs/retrace.md).
#include <fmt/format.h>

#include <cmath>
#include <cstdio>

#include "opencnc/retrace/retrace.hpp"
#include "run_features_parts.hpp"

namespace opencnc::cli {

namespace {

/// One scripted retrace: at `at_s` seconds into the run, pause, jog to (x, y), start.
struct RetraceAt {
  double at_s = 0, x = 0, y = 0;
};

/// "12.5:100,40" → {12.5, 100, 40}; nullopt if it is not that (finite numbers, time ≥ 0).
std::optional<RetraceAt> parse_retrace(const std::string& text) {
  RetraceAt r;
  char tail = 0;
  if (std::sscanf(text.c_str(), "%lf:%lf,%lf%c", &r.at_s, &r.x, &r.y, &tail) != 3 || !std::isfinite(r.at_s) ||
      !std::isfinite(r.x) || !std::isfinite(r.y) || r.at_s < 0)
    return std::nullopt;
  return r;
}

/// The operator of `--retrace`: at each time, pause the cut (the retrace feature: hold, torch
/// out), jog X then Y to B, and start (to the nearest point C, re-light, cut on).
class RetraceScript {
 public:
  RetraceScript(std::vector<RetraceAt> steps, std::shared_ptr<recovery::RetraceFeature> feature)
      : steps_(std::move(steps)), feature_(std::move(feature)) {}

  void tick(controller::Controller& c, const controller::ControllerStatus& st) {
    using controller::Request;
    if (t0_ < 0 && st.run_active && st.job == controller::JobKind::Program) t0_ = st.servo.time_s;
    if (stage_ != Stage::Waiting && asked_ != 0 && !c.outcome(asked_)) return;  // not answered yet
    if (stage_ != Stage::Waiting && asked_ != 0) {
      const controller::Outcome o = *c.outcome(asked_);
      asked_ = 0;
      if (!o.accepted) {
        fmt::print(stderr, "error: retrace at {:g} s: {}\n", steps_[next_].at_s, o.message);
        stage_ = Stage::Waiting;
        ++next_;
        return;
      }
    }
    const bool idle = st.servo.state == control::State::Idle && !st.run_active;
    switch (stage_) {
      case Stage::Waiting:
        if (next_ >= steps_.size() || t0_ < 0 || st.servo.time_s - t0_ < steps_[next_].at_s) return;
        if (!st.run_active || st.job != controller::JobKind::Program) return;  // between jobs: at the next
        asked_ = c.submit(Request::feature("retrace", "pause"));
        stage_ = Stage::Pausing;
        return;
      case Stage::Pausing:
        if (feature_->phase() != recovery::RetracePhase::Paused || st.servo.mode != control::Mode::Manual ||
            !idle)
          return;
        asked_ = c.submit(Request::jog_by(Axis::X, steps_[next_].x - st.servo.commanded[0], kJogSpeed));
        stage_ = Stage::JogX;
        return;
      case Stage::JogX:
        if (!idle) return;
        asked_ = c.submit(Request::jog_by(Axis::Y, steps_[next_].y - st.servo.commanded[1], kJogSpeed));
        stage_ = Stage::JogY;
        return;
      case Stage::JogY:
        if (!idle) return;
        asked_ = c.submit(Request::feature("retrace", "start"));
        stage_ = Stage::Starting;
        return;
      case Stage::Starting:
        times_.push_back(steps_[next_].at_s);
        stage_ = Stage::Waiting;
        ++next_;
        return;
    }
  }
  /// The program's job ended: the session goes on while a retrace is under way.
  bool goes_on(const controller::ControllerEvent& e) const {
    return e.end == controller::JobEnd::Aborted && stage_ != Stage::Waiting;
  }
  /// The times of the retraces that started, in order.
  const std::vector<double>& times() const { return times_; }

 private:
  enum class Stage : std::uint8_t { Waiting, Pausing, JogX, JogY, Starting };
  static constexpr double kJogSpeed = 50;  ///< mm/s: a hand on the jog buttons
  std::vector<RetraceAt> steps_;
  std::shared_ptr<recovery::RetraceFeature> feature_;
  std::size_t next_ = 0;
  Stage stage_ = Stage::Waiting;
  std::uint64_t asked_ = 0;
  double t0_ = -1;
  std::vector<double> times_;
};

nlohmann::json retraces_json(const std::vector<recovery::RetraceRecord>& records,
                             const std::vector<double>& times) {
  nlohmann::json list = nlohmann::json::array();
  for (std::size_t i = 0; i < records.size(); ++i) {
    const recovery::RetraceRecord& r = records[i];
    nlohmann::json j;
    j["at_s"] = i < times.size() ? nlohmann::json(times[i]) : nlohmann::json(nullptr);
    j["a"] = r.a_known ? nlohmann::json({r.a[0], r.a[1], r.a[2]}) : nlohmann::json(nullptr);
    j["b"] = {r.b[0], r.b[1], r.b[2]};
    j["c"] = {r.c[0], r.c[1], r.c[2]};
    j["segment"] = r.segment;
    j["line"] = r.line;
    j["distance_mm"] = r.distance_mm;
    j["candidates"] = r.candidates;
    list.push_back(j);
  }
  return list;
}

class RetraceRun final : public RunFeature {
 public:
  void add_options(CLI::App& run) override {
    run.add_option(
           "--retrace", steps_text_,
           "Script the operator of a flame/plasma retrace: at AT_SECONDS into the run hold the cut (torch "
           "out), jog to X,Y and start from the nearest point of the path (repeatable; the report lists "
           "them as `retraces`)")
        ->expected(1)
        ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll)
        ->excludes("--electrode-change")
        ->excludes("--hold-retrace-back")
        ->check(CLI::Validator(
            [](const std::string& s) {
              return parse_retrace(s)
                         ? std::string()
                         : "expected AT_SECONDS:X,Y (seconds into the run, mm), e.g. 12.5:100,40";
            },
            "AT_SECONDS:X,Y"));
  }
  bool check(const config::MachineProfile*, SessionOptions&) override {
    for (const std::string& text : steps_text_)
      steps_.push_back(*parse_retrace(text));  // checked by the option
    return true;
  }
  bool set_up(controller::MachineSetup& machine) override {
    // The retraces in the report are also those another feature's operator made (opencnc run
    // --hold-retrace-back, after an arc loss).
    feature_ = std::dynamic_pointer_cast<recovery::RetraceFeature>(machine.feature("retrace"));
    if (steps_.empty()) return true;
    if (!feature_) {
      fmt::print(stderr, "error: --retrace: the machine has no torch to retrace with ([process.cutting])\n");
      return false;
    }
    script_.emplace(steps_, feature_);
    return true;
  }
  void tick(controller::Controller& c, const controller::ControllerStatus& st,
            machine::SimMachine*) override {
    if (script_) script_->tick(c, st);
  }
  bool goes_on(const controller::ControllerEvent& e) const override { return script_ && script_->goes_on(e); }
  bool report(nlohmann::json& j) override {
    if (!feature_) return true;
    const std::vector<recovery::RetraceRecord> records = feature_->records();
    if (records.empty() && !script_) return true;
    for (const recovery::RetraceRecord& x : records) {
      fmt::print("retrace             B ({:.3f}, {:.3f}) -> C ({:.4f}, {:.4f}) {:.3f} mm, segment {}, {}\n",
                 x.b[0], x.b[1], x.c[0], x.c[1], x.distance_mm, x.segment, x.line);
    }
    j["retraces"] = retraces_json(records, script_ ? script_->times() : std::vector<double>{});
    return true;
  }

 private:
  std::vector<std::string> steps_text_;
  std::vector<RetraceAt> steps_;
  std::shared_ptr<recovery::RetraceFeature> feature_;
  std::optional<RetraceScript> script_;
};

}  // namespace

std::unique_ptr<RunFeature> retrace_run() {
  return std::make_unique<RetraceRun>();
}

}  // namespace opencnc::cli
