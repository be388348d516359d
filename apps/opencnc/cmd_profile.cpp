// SPDX-License-Identifier: GPL-3.0-or-later
// `opencnc profile`: check a machine profile, summarise it, and move one simulated axis.
#include <fmt/format.h>
#include <CLI/CLI.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>
#include <vector>

#include "cli_files.hpp"
#include "commands.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "opencnc/machine/sim_machine.hpp"

namespace opencnc::cli {

namespace {

struct ProfileOptions {
  std::string file;
  std::vector<std::string> sets;
  std::string move;  // "x=100"
  std::string csv;
};

void print_summary(const config::MachineProfile& p) {
  fmt::print("{}: {} axes, servo period {} s, sim {} sub-steps\n", p.name, p.axes.size(), p.servo_period_s,
             p.sim_substeps);
  for (const config::AxisProfile& a : p.axes) {
    const std::string limits =
        a.wrapped ? std::string("turns without end") : fmt::format("limits [{}, {}]", a.min_limit, a.max_limit);
    fmt::print("  {} joint {}: {} {}, v {} a {} j {}, {}, {} counts/unit\n", letter(a.axis), a.joint,
               a.rotary ? "rotary" : "linear",
               a.drive == machine::JointDrive::Servo ? "servo" : (a.manual() ? "manual" : "stepper"),
               a.max_velocity, a.max_acceleration, a.max_jerk, limits, a.counts_per_unit);
  }
  if (p.spindle.present) fmt::print("  spindle: {}–{} rpm\n", p.spindle.min_rpm, p.spindle.max_rpm);
}

/// Position and velocity of a rest-to-rest move of `distance` at the axis' velocity and
/// acceleration limits (trapezoid, or triangle when too short to cruise).
struct Trapezoid {
  double distance, v, a, t_ramp, t_cruise;
  Trapezoid(double d, double vmax, double amax) : distance(std::abs(d)), a(amax) {
    t_ramp = std::min(vmax / amax, std::sqrt(distance / amax));
    v = amax * t_ramp;
    t_cruise = (distance - amax * t_ramp * t_ramp) / v;
  }
  double duration() const { return 2 * t_ramp + t_cruise; }
  std::pair<double, double> at(double t) const {
    if (t <= 0) return {0, 0};
    if (t < t_ramp) return {0.5 * a * t * t, a * t};
    if (t < t_ramp + t_cruise) return {0.5 * a * t_ramp * t_ramp + v * (t - t_ramp), v};
    const double r = std::max(0.0, duration() - t);
    return {distance - 0.5 * a * r * r, a * r};
  }
};

int run_move(const config::MachineProfile& p, const ProfileOptions& o) {
  const auto eq = o.move.find('=');
  const auto axis = eq == 1 ? std::optional(AxisMask::from_letters(o.move.substr(0, 1))) : std::nullopt;
  const config::AxisProfile* a = nullptr;
  for (const config::AxisProfile& cand : p.axes) {
    if (axis && axis->has(cand.axis)) a = &cand;
  }
  double distance = 0;
  if (a == nullptr || std::sscanf(o.move.c_str() + eq + 1, "%lf", &distance) != 1 || distance == 0) {
    fmt::print(stderr, "error: --move wants AXIS=DISTANCE with an axis of the profile, e.g. x=100\n");
    return kExitUsage;
  }
  machine::SimMachine m(config::sim_machine_config(p));
  machine::MachineInputs in;
  m.read(in);
  machine::MachineOutputs out;
  out.estop_release = true;
  for (const config::AxisProfile& each : p.axes) {
    out.joints[static_cast<std::size_t>(each.joint)] = {
        in.joints[static_cast<std::size_t>(each.joint)].position, 0, 0, true};
  }
  const auto j = static_cast<std::size_t>(a->joint);
  const double start = in.joints[j].position, sign = distance < 0 ? -1 : 1;
  const Trapezoid move(distance, a->max_velocity, a->max_acceleration);
  std::vector<NamedPath> inputs = {{"the profile", o.file}};
  if (!p.interpreter.tool_table.empty()) inputs.push_back({"the tool table", p.interpreter.tool_table});
  const NamedPath outputs[] = {{"--csv", o.csv}};
  const auto files = open_outputs(inputs, outputs);
  if (files.empty()) return kExitUsage;
  OutputFile* const csv = files[0].get();
  if (csv != nullptr) csv->write("t_s,command,feedback,table,following_error,effort\n");
  double worst = 0, worst_t = 0;
  const int periods = static_cast<int>(std::ceil((move.duration() + 0.2) / p.servo_period_s));
  for (int k = 0; k < periods; ++k) {
    const double t = k * p.servo_period_s;
    const auto [s, v] = move.at(t);
    out.joints[j].position = start + sign * s;
    out.joints[j].velocity_ff = sign * v;
    m.read(in);
    const double error = out.joints[j].position - in.joints[j].position;
    if (std::abs(error) > worst) worst = std::abs(error), worst_t = t;
    if (csv != nullptr) {
      csv->write(fmt::format("{:.4f},{:.6f},{:.6f},{:.6f},{:.6f},{:.3f}\n", t, out.joints[j].position,
                             in.joints[j].position, m.joint(a->joint).table_position(), error,
                             in.joints[j].effort));
    }
    m.write(out);
  }
  m.read(in);
  if (csv != nullptr && !commit(*csv)) return kExitUsage;
  fmt::print("{} {:+} in {:.3f} s: max following error {:.4f} at t = {:.3f} s; final error {:.4f}\n",
             letter(a->axis), distance, move.duration(), worst, worst_t,
             out.joints[j].position - in.joints[j].position);
  return kExitOk;
}

int run_profile(const ProfileOptions& o) {
  const config::ProfileLoad load = config::load_profile(o.file, o.sets);
  for (const Diagnostic& d : load.diagnostics.items()) fmt::print(stderr, "{}\n", d.format());
  if (!load.ok()) {
    const bool unreadable =
        !load.diagnostics.items().empty() && load.diagnostics.items()[0].code == "config.file";
    return unreadable ? kExitUsage : kExitProgram;
  }
  print_summary(*load.profile);
  return o.move.empty() ? kExitOk : run_move(*load.profile, o);
}

}  // namespace

void add_profile_command(CLI::App& app, Registry& registry) {
  auto opts = std::make_shared<ProfileOptions>();
  CLI::App* cmd =
      app.add_subcommand("profile", "Check a machine profile (TOML) and try its simulated machine");
  cmd->add_option("file", opts->file, "Machine profile, e.g. configs/mill-3axis.toml")->required();
  cmd->add_option("--set", opts->sets, "Override a key: --set axis.x.max_velocity=200 (repeatable)")
      ->expected(1)
      ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  CLI::Option* move =
      cmd->add_option("--move", opts->move, "Move one simulated axis from its start, e.g. --move x=100");
  cmd->add_option("--csv", opts->csv,
                  "With --move: write t, command, feedback, table, error, effort per period")
      ->needs(move);
  cmd->callback([opts, &registry] { registry.set_result(run_profile(*opts)); });
}

}  // namespace opencnc::cli
