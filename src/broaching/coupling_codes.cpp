// SPDX-License-Identifier: GPL-3.0-or-later
// The broaching codes M171-M175: their words checked, one canonical set_axis_coupling call each.
#include "opencnc/broaching/coupling_codes.hpp"

#include <cmath>

#include <fmt/format.h>

#include "opencnc/gcode/standard_extensions.hpp"

namespace opencnc::gcode {

namespace {

/// Most tables a profile defines (motion::kMaxCouplingTables; the interpreter does not link motion).
constexpr int kMaxTables = 8;

constexpr int kConstant = 171, kLinear = 172, kPitchTable = 173, kCam = 174, kOff = 175;

class CouplingCodes final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    if (auto r = problem(b, code, ctx.state())) ctx.error(r->code, r->message);
    ctx.output().set_axis_coupling(coupling(b, code));
  }

 private:
  // The engine asks CodeHandler::check of G codes only; user M codes are checked as they execute.
  static std::optional<Rejection> problem(const Block& b, int code, const InterpState& state) {
    if (state.modal.cutter_comp != CutterComp::Off)
      return Rejection{
          ErrorCode::CouplingCutterComp,
          fmt::format("M{} cannot change the axis coupling while cutter compensation is on: G40 first",
                      code)};
    switch (code) {
      case kConstant:
      case kLinear:
        // A pitch below the least increment (0.0001 mm) would turn the slave without end.
        if (!b.has('p') || std::fabs(b.get('p')) < 1e-4 || !std::isfinite(b.get('p')))
          return Rejection{
              ErrorCode::CouplingWord,
              fmt::format(
                  "M{} needs the pitch per revolution as P, at least 0.0001 mm (negative: a left-hand helix)",
                  code)};
        if (code == kLinear && !b.has('q'))
          return Rejection{
              ErrorCode::CouplingWord,
              "M172 needs Q, the change of pitch per unit of master travel (Q0: constant pitch)"};
        break;
      case kPitchTable:
      case kCam: {
        const double p = b.p_or(0);
        if (!b.has('p') || p != std::floor(p) || p < 1 || p > kMaxTables)
          return Rejection{ErrorCode::CouplingWord,
                           fmt::format("M{} needs the number of a {} table of the machine as P, 1 to {}",
                                       code, code == kCam ? "cam" : "pitch", kMaxTables)};
        break;
      }
      default:
        break;
    }
    return std::nullopt;
  }

  static canon::AxisCoupling coupling(const Block& b, int code) {
    canon::AxisCoupling c;
    switch (code) {
      case kConstant:
        c.law = 1;
        c.pitch = b.get('p');
        break;
      case kLinear:
        c.law = 2;
        c.pitch = b.get('p');
        c.rate = b.get('q');
        break;
      case kPitchTable:
      case kCam:
        c.law = code == kCam ? 4 : 3;
        c.table = static_cast<int>(b.get('p'));
        break;
      default:
        c.law = 0;
        break;
    }
    return c;
  }
};

}  // namespace

void add_coupling_codes(Extensions& ext) {
  auto codes = std::make_shared<CouplingCodes>();
  for (int code : {kConstant, kLinear, kPitchTable, kCam, kOff})
    ext.m[static_cast<std::size_t>(code)] = codes;
}

std::shared_ptr<const Extensions> coupling_extensions(Dialect dialect) {
  auto base = standard_extensions(dialect);
  auto ext = std::make_shared<Extensions>(*base);
  add_coupling_codes(*ext);
  return ext;
}

}  // namespace opencnc::gcode
