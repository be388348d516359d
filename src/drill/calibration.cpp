// SPDX-License-Identifier: GPL-3.0-or-later
// Calibration runs on the simulated machine: homing repeatability, the ISO 230-2 style positioning
// test, and the compensation table a measurement gives.
#include "opencnc/drill/calibration.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numeric>
#include <stdexcept>

#include "opencnc/controller/gcode_source.hpp"
#include "opencnc/controller/servo_setup.hpp"
#include "opencnc/controller/sim_rig.hpp"
#include "opencnc/drill/setup.hpp"
#include "opencnc/machine/sim_switch.hpp"

namespace opencnc::drill {

namespace {

/// A uniform number in [0, 1) from the seeded generator (the same on every platform).
double unit(machine::SplitMix64& rng) {
  return 0.5 * (rng.symmetric() + 1.0);
}

double spread(const std::vector<double>& v) {
  if (v.empty()) return 0;
  const auto [lo, hi] = std::minmax_element(v.begin(), v.end());
  return *hi - *lo;
}

/// Hands every servo period's sample (homing included) to a function.
class TraceForward final : public controller::ControllerObserver {
 public:
  explicit TraceForward(std::function<void(const control::TraceSample&)> f) : f_(std::move(f)) {}
  void on_trace(const control::TraceSample& s, const controller::TraceContext&) override { f_(s); }

 private:
  std::function<void(const control::TraceSample&)> f_;
};

/// Runs `rig` until `done` holds; throws with the machine's fault when it faults or when
/// `max_ticks` pass.
template <typename F>
void run_until(controller::SimRig& rig, F done, std::uint64_t max_ticks, const char* what) {
  for (std::uint64_t i = 0; i < max_ticks; ++i) {
    rig.step();
    const controller::ControllerStatus s = rig.status();
    if (s.servo.state == control::State::Faulted || s.servo.state == control::State::EStopped)
      throw std::runtime_error(fmt::format("{}: the machine stopped: {}", what, s.fault_text));
    if (done(s)) return;
  }
  throw std::runtime_error(fmt::format("{}: did not finish in {} s of machine time", what,
                                       static_cast<double>(max_ticks) * rig.servo().config().period_s));
}

void must(controller::SimRig& rig, controller::Request r, const char* what) {
  const controller::Outcome o = rig.request(std::move(r), 100000);
  if (o.accepted) return;
  std::string why = o.message;
  for (const Diagnostic& d : o.diagnostics.items()) why += "; " + d.format();
  throw std::runtime_error(fmt::format("{}: {}", what, why));
}

void home(controller::SimRig& rig) {
  must(rig, controller::Request::simple(control::CommandKind::MachineOn), "machine on");
  if (!rig.controller().servo_config().homing_required) return;
  must(rig, controller::Request::set_mode(control::Mode::Manual), "manual mode");
  must(rig, controller::Request::home(), "home");
  run_until(
      rig,
      [](const controller::ControllerStatus& s) {
        return s.servo.state == control::State::Idle && s.servo.all_homed;
      },
      2'000'000, "homing");
}

/// ISO 230-2 figures of one axis from its deviations (targets × approaches, each direction).
void evaluate(const std::vector<std::vector<double>>& up, const std::vector<std::vector<double>>& down,
              AxisPositioning& a) {
  const auto mean = [](const std::vector<double>& v) {
    return std::accumulate(v.begin(), v.end(), 0.0) / static_cast<double>(v.size());
  };
  const auto sd = [&](const std::vector<double>& v) {
    if (v.size() < 2) return 0.0;
    const double m = mean(v);
    double q = 0;
    for (double x : v) q += (x - m) * (x - m);
    return std::sqrt(q / static_cast<double>(v.size() - 1));
  };
  double hi = -1e300, lo = 1e300;
  for (std::size_t i = 0; i < up.size(); ++i) {
    const double mu = mean(up[i]), md = mean(down[i]), su = sd(up[i]), sdn = sd(down[i]);
    a.mean_up.push_back(mu);
    a.mean_down.push_back(md);
    a.sd_up.push_back(su);
    a.sd_down.push_back(sdn);
    const double b = mu - md;
    a.reversal = std::max(a.reversal, std::abs(b));
    a.repeatability = std::max({a.repeatability, 2 * su + 2 * sdn + std::abs(b), 4 * su, 4 * sdn});
    hi = std::max({hi, mu + 2 * su, md + 2 * sdn});
    lo = std::min({lo, mu - 2 * su, md - 2 * sdn});
  }
  a.accuracy = up.empty() ? 0.0 : hi - lo;
}

/// The linear cycles of one axis: up through the targets, back down, `approaches` times.
AxisPositioning measure_axis(controller::SimRig& rig, const config::AxisProfile& ax,
                             const PositioningOptions& o) {
  AxisPositioning a;
  const double home = ax.homing.position;
  const auto k0 = static_cast<long>(std::ceil((ax.min_limit + o.overrun - home) / o.interval - 1e-9));
  const auto k1 = static_cast<long>(std::floor((ax.max_limit - o.overrun - home) / o.interval + 1e-9));
  for (long k = k0; k <= k1; ++k) a.targets.push_back(home + static_cast<double>(k) * o.interval);
  if (a.targets.empty())
    throw std::runtime_error(fmt::format("axis {}: no target fits its travel", letter(ax.axis)));
  const auto period = rig.servo().config().period_s;
  const auto dwell = static_cast<std::uint64_t>(std::llround(o.dwell_s / period));
  const machine::SimJoint& joint = rig.machine().joint(ax.joint);
  const auto move = [&](double x) {
    must(rig, controller::Request::mdi(fmt::format("G90 G1 {}{:.6f} F{}", letter(ax.axis), x, o.feed)),
         "positioning move");
    run_until(
        rig,
        [](const controller::ControllerStatus& s) {
          return !s.run_active && s.servo.state == control::State::Idle;
        },
        10'000'000, "positioning move");
    rig.run(dwell);
  };
  const auto read = [&] { return std::round(joint.table_position() / o.resolution) * o.resolution; };
  const double first = a.targets.front(), last = a.targets.back();
  move(first - o.overrun);
  move(first);
  const double zero = read();  // the scale is zeroed at the first target, approached upward
  const auto deviation = [&](double target) { return (read() - zero) - (target - first); };
  std::vector<std::vector<double>> up(a.targets.size()), down(a.targets.size());
  for (int c = 0; c < o.approaches; ++c) {
    move(first - o.overrun);
    for (std::size_t i = 0; i < a.targets.size(); ++i) {
      move(a.targets[i]);
      up[i].push_back(deviation(a.targets[i]));
    }
    move(last + o.overrun);
    for (std::size_t i = a.targets.size(); i-- > 0;) {
      move(a.targets[i]);
      down[i].push_back(deviation(a.targets[i]));
    }
  }
  move(home);
  evaluate(up, down, a);
  return a;
}

}  // namespace

HomingSpread homing_spread(const config::MachineProfile& profile, const HomingSpreadOptions& o) {
  HomingSpread r;
  for (const config::AxisProfile& a : profile.axes) {
    if (a.homing.method == config::HomingMethod::DecelMidpoint) r.axes.set(a.axis);
  }
  machine::SplitMix64 rng(o.seed);
  r.temperature_min_c = profile.sim_temperature_c + 0.5 * o.temperature_swing_c;
  r.temperature_max_c = profile.sim_temperature_c - 0.5 * o.temperature_swing_c;
  for (int run = 0; run < o.runs; ++run) {
    config::MachineProfile p = profile;
    p.sim_seed = o.seed * 7919 + static_cast<std::uint64_t>(run);
    for (config::AxisProfile& a : p.axes) {
      if (a.homing.method != config::HomingMethod::Immediate && !a.manual())
        a.sim.start_position = a.min_limit + (a.max_limit - a.min_limit) * unit(rng);
    }
    p.sim_temperature_c = profile.sim_temperature_c + o.temperature_swing_c * (unit(rng) - 0.5);
    r.temperature_min_c = std::min(r.temperature_min_c, p.sim_temperature_c);
    r.temperature_max_c = std::max(r.temperature_max_c, p.sim_temperature_c);
    controller::SimRig rig(p);
    if (run == 0 && o.trace) {
      rig.controller().attach(std::make_shared<TraceForward>(o.trace), controller::ObserverOptions{0, true});
      rig.step();  // attached from here on
    }
    home(rig);
    const control::ServoStatus s = rig.status().servo;
    for (const config::AxisProfile& a : p.axes) {
      if (!r.axes.has(a.axis)) continue;
      const control::HomingStatus& h = s.homing[static_cast<std::size_t>(a.joint)];
      r.midpoint[static_cast<std::size_t>(index(a.axis))].push_back(0.5 * (h.rising_edge + h.falling_edge));
      r.rising[static_cast<std::size_t>(index(a.axis))].push_back(h.rising_edge);
    }
    ++r.runs;
  }
  for (int i = 0; i < kAxisCount; ++i) {
    const auto ui = static_cast<std::size_t>(i);
    r.midpoint_spread[ui] = spread(r.midpoint[ui]);
    r.single_edge_spread[ui] = spread(r.rising[ui]);
  }
  return r;
}

Positioning measure_positioning(const config::MachineProfile& profile, const PositioningOptions& o) {
  config::MachineProfile p = profile;
  p.sim_seed = o.seed;
  Diagnostics diags;
  std::unique_ptr<controller::MachineSetup> machine = controller::MachineSetup::create(p, {}, diags);
  if (!machine) throw std::runtime_error("the profile's tool table cannot be read");
  drill::setup(p, *machine);  // the machine's hand-fed axes wait for the operator, as in a run
  controller::SimRig rig(p, *machine);
  home(rig);
  must(rig, controller::Request::set_mode(control::Mode::Mdi), "MDI mode");
  Positioning r;
  for (const config::AxisProfile& ax : p.axes) {
    if (!o.axes.has(ax.axis)) continue;
    if (ax.manual())
      throw std::runtime_error(fmt::format("axis {} is moved by hand: nothing to position", letter(ax.axis)));
    r.axes.set(ax.axis);
    r.axis[static_cast<std::size_t>(index(ax.axis))] = measure_axis(rig, ax, o);
  }
  return r;
}

config::MachineProfile without_compensation(const config::MachineProfile& profile) {
  config::MachineProfile p = profile;
  for (config::AxisProfile& a : p.axes) a.compensation = config::CompensationProfile{};
  return p;
}

config::CompensationProfile compensation_from(const AxisPositioning& m, const config::AxisProfile& axis) {
  config::CompensationProfile c;
  c.present = true;
  c.positions = m.targets;
  c.forward = m.mean_up;
  c.reverse = m.mean_down;
  c.backlash = 0;  // the reversal is in the tables
  const bool had = axis.compensation.present;
  c.takeup_velocity = had ? axis.compensation.takeup_velocity : 0.1 * axis.max_velocity;
  c.takeup_acceleration = had ? axis.compensation.takeup_acceleration : 0.1 * axis.max_acceleration;
  return c;
}

}  // namespace opencnc::drill
