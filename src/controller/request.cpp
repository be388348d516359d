// SPDX-License-Identifier: GPL-3.0-or-later
// Requests: their names, and the servo commands they stand for.
#include "opencnc/controller/request.hpp"

#include <type_traits>

namespace opencnc::controller {

namespace {

template <class... Fs>
struct Overload : Fs... {
  using Fs::operator()...;
};
template <class... Fs>
Overload(Fs...) -> Overload<Fs...>;

const char* override_name(OverrideKind k) {
  switch (k) {
    case OverrideKind::Feed:
      return "feed-override";
    case OverrideKind::Rapid:
      return "rapid-override";
    case OverrideKind::Spindle:
      return "spindle-override";
  }
  return "override";
}

const char* switch_name(SwitchKind k) {
  switch (k) {
    case SwitchKind::SingleBlock:
      return "single-block";
    case SwitchKind::OptionalStop:
      return "optional-stop";
    case SwitchKind::BlockDelete:
      return "block-delete";
  }
  return "switch";
}

control::Command command(control::CommandKind k) {
  control::Command c;
  c.kind = k;
  return c;
}

std::int8_t axis_index(std::optional<Axis> a) {
  return a ? static_cast<std::int8_t>(index(*a)) : std::int8_t{-1};
}

}  // namespace

std::string Request::name() const {
  return std::visit(Overload{
                        [](const requests::Servo& r) -> std::string { return to_string(r.kind); },
                        [](const requests::SetMode&) -> std::string { return "set-mode"; },
                        [](const requests::Jog&) -> std::string { return "jog"; },
                        [](const requests::JogBy&) -> std::string { return "jog-by"; },
                        [](const requests::JogStop&) -> std::string { return "jog-stop"; },
                        [](const requests::Home&) -> std::string { return "home"; },
                        [](const requests::SetOverride& r) -> std::string { return override_name(r.which); },
                        [](const requests::SetSwitch& r) -> std::string { return switch_name(r.which); },
                        [](const requests::SpindleOn&) -> std::string { return "spindle-on"; },
                        [](const requests::SetCoolant&) -> std::string { return "coolant"; },
                        [](const requests::OpenFile&) -> std::string { return "open"; },
                        [](const requests::OpenCanon&) -> std::string { return "open"; },
                        [](const requests::Mdi&) -> std::string { return "mdi"; },
                        [](const requests::RunAuxiliary&) -> std::string { return "run-auxiliary"; },
                        [](const requests::Feature& r) -> std::string { return r.feature + "." + r.action; },
                        [](const requests::SetHandwheel&) -> std::string { return "handwheel"; },
                        [](const requests::ResumeProgram&) -> std::string { return "resume-program"; },
                        [](const requests::EditProfile&) -> std::string { return "edit-profile"; },
                        [](const requests::SeekLimit&) -> std::string { return "seek-limit"; },
                    },
                    body);
}

std::optional<control::Command> to_command(const Request& r) {
  return std::visit(
      Overload{
          [](const requests::Servo& s) -> std::optional<control::Command> { return command(s.kind); },
          [](const requests::SetMode& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::SetMode);
            c.mode = s.mode;
            return c;
          },
          [](const requests::Jog& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::JogContinuous);
            c.axis = axis_index(s.axis);
            c.value = s.velocity;
            return c;
          },
          [](const requests::JogBy& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::JogIncrement);
            c.axis = axis_index(s.axis);
            c.value = s.distance;
            c.value2 = s.speed;
            return c;
          },
          [](const requests::JogStop& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::JogStop);
            c.axis = axis_index(s.axis);
            return c;
          },
          [](const requests::Home& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::Home);
            c.axis = axis_index(s.axis);
            return c;
          },
          [](const requests::SeekLimit& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::SeekLimit);
            c.axis = axis_index(s.axis);
            c.value = s.direction;
            return c;
          },
          [](const requests::SetOverride& s) -> std::optional<control::Command> {
            control::Command c =
                command(s.which == OverrideKind::Feed    ? control::CommandKind::SetFeedOverride
                        : s.which == OverrideKind::Rapid ? control::CommandKind::SetRapidOverride
                                                         : control::CommandKind::SetSpindleOverride);
            c.value = s.value;
            return c;
          },
          [](const requests::SetSwitch& s) -> std::optional<control::Command> {
            if (s.which == SwitchKind::BlockDelete) return std::nullopt;  // the controller's
            control::Command c =
                command(s.which == SwitchKind::SingleBlock ? control::CommandKind::SetSingleBlock
                                                           : control::CommandKind::SetOptionalStop);
            c.flag = s.on;
            return c;
          },
          [](const requests::SpindleOn& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::SpindleOn);
            c.value = s.rpm;
            c.flag = s.clockwise;
            return c;
          },
          [](const requests::SetCoolant& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::Coolant);
            c.coolant = s.which;
            c.flag = s.on;
            return c;
          },
          [](const requests::SetHandwheel& s) -> std::optional<control::Command> {
            control::Command c = command(control::CommandKind::SetHandwheel);
            c.axis = axis_index(s.axis);
            c.value = s.step;
            return c;
          },
          [](const auto&) -> std::optional<control::Command> { return std::nullopt; },
      },
      r.body);
}

bool takes_urgent_lane(const Request& r) {
  if (const auto* s = std::get_if<requests::Servo>(&r.body)) {
    switch (s->kind) {
      case control::CommandKind::EStop:
      case control::CommandKind::MachineOff:
      case control::CommandKind::Abort:
      case control::CommandKind::FeedHold:
      case control::CommandKind::SpindleOff:
        return true;
      default:
        return false;
    }
  }
  if (const auto* c = std::get_if<requests::SetCoolant>(&r.body)) return !c->on;
  return std::holds_alternative<requests::JogStop>(r.body) ||
         std::holds_alternative<requests::SetOverride>(r.body);
}

bool is_halt(const Request& r) {
  const auto* s = std::get_if<requests::Servo>(&r.body);
  return s != nullptr &&
         (s->kind == control::CommandKind::EStop || s->kind == control::CommandKind::MachineOff ||
          s->kind == control::CommandKind::Abort);
}

bool is_stop(const Request& r) {
  const auto* s = std::get_if<requests::Servo>(&r.body);
  return is_halt(r) || (s != nullptr && s->kind == control::CommandKind::FeedHold);
}

}  // namespace opencnc::controller
