// SPDX-License-Identifier: GPL-3.0-or-later
// M190–M193: one canonical process_code call each (the tick's torch stage applies it at an exact
// stop of no time).
#include "opencnc/cutting/torch_codes.hpp"

#include "opencnc/gcode/standard_extensions.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::gcode {

namespace {

class TorchCodes final : public CodeHandler {
 public:
  void execute(ExecContext& ctx, const Block& b, int code) override {
    canon::ProcessCode c;
    c.code = code;
    c.p = b.p_or(0);
    const bool torch = code == machine::kTorchOnCode || code == machine::kTorchOffCode;
    c.group = torch ? machine::kTorchOnCode : machine::kThcHoldCode;
    ctx.output().process_code(c);
  }
};

}  // namespace

void add_torch_codes(Extensions& ext) {
  auto codes = std::make_shared<TorchCodes>();
  for (int code :
       {machine::kTorchOnCode, machine::kTorchOffCode, machine::kThcHoldCode, machine::kThcReleaseCode})
    ext.m[static_cast<std::size_t>(code)] = codes;
}

std::shared_ptr<const Extensions> torch_extensions(Dialect dialect, std::shared_ptr<const Extensions> base) {
  auto ext = std::make_shared<Extensions>(base ? *base : *standard_extensions(dialect));
  add_torch_codes(*ext);
  return ext;
}

}  // namespace opencnc::gcode
