// SPDX-License-Identifier: GPL-3.0-or-later
// Retrace on a machine: the feature and its state, added to the hub.
#include "opencnc/retrace/setup.hpp"

#include <nlohmann/json.hpp>

#include "opencnc/retrace/retrace.hpp"

namespace opencnc::retrace {

namespace {

nlohmann::json point(const Vec3& v) {
  return nlohmann::json::array({v[0], v[1], v[2]});
}

/// The retrace's state for a front end (docs/api.md, "features"): its phase, how many retraces
/// and the last one (A where it paused, B where it was brought, C the nearest point of the path).
class State final : public controller::FeatureState {
 public:
  explicit State(std::shared_ptr<recovery::RetraceFeature> feature) : feature_(std::move(feature)) {}
  std::string state_key() const override { return "retrace"; }
  std::string state_json(const controller::ControllerStatus&) override {
    using nlohmann::json;
    json last = nullptr;
    const std::vector<recovery::RetraceRecord> records = feature_->records();
    if (!records.empty()) {
      const recovery::RetraceRecord& r = records.back();
      last = {{"a", r.a_known ? point(r.a) : json(nullptr)},
              {"b", point(r.b)},
              {"c", point(r.c)},
              {"line", r.line},
              {"segment", r.segment},
              {"distance_mm", r.distance_mm},
              {"candidates", r.candidates}};
    }
    return json{
        {"phase", recovery::to_string(feature_->phase())}, {"retraces", records.size()}, {"last", last}}
        .dump();
  }

 private:
  std::shared_ptr<recovery::RetraceFeature> feature_;
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  if (!profile.cutting.present) return true;
  auto feature = std::make_shared<recovery::RetraceFeature>(host.make_source(), profile);
  host.add_feature(feature, controller::ObserverOptions{profile.servo_period_s, false});
  host.add_state(std::make_shared<State>(feature));
  return true;
}

}  // namespace opencnc::retrace
