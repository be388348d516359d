// SPDX-License-Identifier: GPL-3.0-or-later
// Readers of the profile's sections, each filling its part of a MachineProfile.
#pragma once

#include <filesystem>
#include <optional>
#include <span>
#include <string_view>
#include <utility>

#include "opencnc/config/machine_profile.hpp"
#include "opencnc/config/profile_loader.hpp"
#include "toml_reader.hpp"

namespace opencnc::config::detail {

/// [sim]: sub-step and seed. Needs servo_period_s.
void read_sim(Section& top, MachineProfile& profile);
/// [axis.<letter>] with homing, switches and sim. Needs servo_period_s and sim_substeps.
void read_axes(Section& top, MachineProfile& profile);
void read_spindle(Section& top, MachineProfile& profile);
void read_power(Section& top, MachineProfile& profile);
/// [probe]. Needs the axes.
void read_probe(Section& top, MachineProfile& profile);
/// [probe.reference_sphere] (read_probe calls it). Needs the axes.
void read_reference_sphere(Section& probe, MachineProfile& profile);
/// [[sim.electrode]]: the tools' true electrodes in the simulation (read_sim calls it).
void read_sim_electrodes(Section& sim, MachineProfile& profile);
void read_tool_changer(Section& top, MachineProfile& profile);
/// [tool_change]: the tool-change position. Needs the axes (their letters and soft limits).
void read_tool_change(Section& top, MachineProfile& profile);
void read_io(Section& top, MachineProfile& profile);
/// [process] with [process.cutting] and [process.broaching]. Needs [io], the axes and [coupling].
void read_process(Section& top, MachineProfile& profile);
void read_interpreter(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir);
void read_planner(Section& top, MachineProfile& profile);
/// [tool_guard]. Needs [interpreter] (a tool store and a tool table file exclude each other).
void read_tool_guard(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir);
/// [axis.<letter>.compensation] of every axis read. Needs the axes; comp files are found from
/// `base_dir`, or taken from `files` when their path is there.
void read_compensation(Section& top, MachineProfile& profile, const std::filesystem::path& base_dir,
                       std::span<const FileText> files);
/// [interlocks] (named inputs and outputs, rules) and [handwheel]. Needs the axes and [io].
void read_interlocks(Section& top, MachineProfile& profile);
void read_handwheel(Section& top, MachineProfile& profile);
/// [alarms.<name>]: process-input alarms. Needs [io].
void read_alarms(Section& top, MachineProfile& profile);
/// [kinematics]: the structure and the two rotary axes. Needs the axes.
void read_kinematics(Section& top, MachineProfile& profile);
/// [coupling] and its tables. Needs the axes.
void read_coupling(Section& top, MachineProfile& profile);
/// [process.broaching] and its sim, from read_process. Needs the axes, [io] and [coupling].
void read_broaching(Section& process, MachineProfile& profile);
/// [process.plasma] with .thc, .holes and .sim, from read_process. Needs the axes and [io].
void read_plasma(Section& process, MachineProfile& profile);
/// [process.oxyfuel] with .thc and .sim, from read_process (into MachineProfile::plasma, the
/// torch stage's settings with process = OxyFuel). Needs the axes and [io].
void read_oxyfuel(Section& process, MachineProfile& profile);
/// A torch's channel `key` of `count` (an [io] count of `what`: "analog input", "digital input",
/// "digital output"), else an error at the key.
std::int32_t torch_channel(Section& s, std::string_view key, int count, std::string_view what, int max);
/// `value` (read from `key`) within the torch axis' limit `of`, else an error at the key.
void torch_within(Section& s, std::string_view key, double value, double limit, std::string_view of);
/// A torch's probe speed and travel, its height moves' speed and acceleration, within Z's limits.
void read_torch_motion(Section& s, machine::PlasmaConfig& c, const AxisProfile* z);
/// A torch's cut height (read after its pierce height), never above the pierce height.
void read_cut_height(Section& s, machine::PlasmaConfig& c);
/// The height control's keys both torches have (.thc: enabled, delay, speed share, time constant,
/// filter, speed, acceleration and reach of the correction, anti-dive), within Z's limits.
void read_thc_common(Section& m, machine::PlasmaConfig& c, const AxisProfile* z);
/// A simulated torch's plate (.sim: seed, plate Z, warp and its wavelength, the plate's extent).
void read_sim_plate(Section& m, machine::SimPlasmaConfig& c);
/// [edm], its conditions and [edm.sim]. Needs the axes and [process].
void read_edm(Section& top, MachineProfile& profile);

/// Reports axis limits outside what any machine has (config.implausible), at the key.
void check_plausible(Section& s, const AxisProfile& a);

/// `node` as an array of exactly two numbers (integers or floats, inf allowed), else nullopt.
std::optional<std::pair<double, double>> number_pair(const toml::node& node);
/// `key` as [x, y, z] (three finite numbers, in `unit`) into `out`; reports (missing, or not
/// three numbers) and returns false otherwise, leaving `out` as it was.
bool read_triple(Section& s, std::string_view key, Vec3& out, std::string_view unit = "mm");
/// `key` as a switch window [from, to] (±inf allowed, from ≤ to); nullopt if absent or bad.
std::optional<machine::SwitchWindow> read_window(Section& section, std::string_view key);
/// The axis a one-letter key names (either case), if it is one.
std::optional<Axis> axis_from_letter(std::string_view letter) noexcept;

}  // namespace opencnc::config::detail
