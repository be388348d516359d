// SPDX-License-Identifier: GPL-3.0-or-later
// The drill's hand-fed axes on a machine: their pass and their words, added to the hub.
#include "opencnc/drill/setup.hpp"

#include <fmt/format.h>

#include "opencnc/drill/hand_axis.hpp"

namespace opencnc::drill {

namespace {

char axis_letter(int axis) {
  return axis >= 0 && axis < kAxisCount ? kAxisLetters[static_cast<std::size_t>(axis)] : '?';
}

/// The hand-axis pass over every program's moves.
class HandAxisPart final : public controller::SourcePart {
 public:
  explicit HandAxisPart(const drill::HandAxes& hand) : hand_(hand) {}
  std::unique_ptr<controller::MovePass> pass() const override {
    return std::make_unique<drill::HandAxisFilter>(hand_);
  }

 private:
  drill::HandAxes hand_;
};

/// What the run waits for at a hand-fed axis, and the axis that left its place, in words.
class Texts final : public controller::EventTexts {
 public:
  std::optional<controller::EventNote> event_note(const control::ServoEvent& e, const config::MachineProfile&,
                                                  const control::ServoConfig&) const override {
    if (e.kind != control::EventKind::HandAxisMoved) return std::nullopt;
    return controller::EventNote{
        Severity::Warning, "control.hand-axis",
        fmt::format("{} left the position the program needs ({:.4f} mm) while the table moved: feed hold",
                    axis_letter(e.axis), e.value)};
  }
  std::optional<std::string> wait_text(const control::ServoStatus& s) const override {
    if (s.wait != control::Wait::HandAxis) return std::nullopt;
    const control::HandWait& h = s.hand_wait;
    return fmt::format("the operator to bring the hand-fed {} {} {:.3f} mm", axis_letter(h.axis),
                       h.retract ? "up to" : "down to", h.target);
  }
};

}  // namespace

bool setup(const config::MachineProfile& profile, controller::MachineSetup& host) {
  const drill::HandAxes hand = drill::hand_axes(profile);
  if (!hand.any()) return true;
  host.add_source_part(std::make_shared<HandAxisPart>(hand));
  host.add_texts(std::make_shared<Texts>());
  return true;
}

}  // namespace opencnc::drill
