// SPDX-License-Identifier: GPL-3.0-or-later
// libFuzzer target: arbitrary bytes as a G-code program (or MDI lines) through the lexer,
// parser and interpreter, printing rs274 text, with limits low enough that nothing hangs.
// Run: build-fuzz/fuzz/gcode/fuzz_gcode fuzz/gcode/corpus -max_total_time=60
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <string_view>

#include "opencnc/canon/rs274_printer.hpp"
#include "opencnc/gcode/interpreter.hpp"
#include "opencnc/gcode/standard_extensions.hpp"

using namespace opencnc;

namespace {

std::shared_ptr<const tools::ToolTable> fuzz_tools() {
  Diagnostics diags;
  static const auto table = std::make_shared<const tools::ToolTable>(
      tools::ToolTable::parse("T1 P1 Z0.5 D0.25\nT2 P2 X0.1 Z1 D0.5 I10 J80 Q2\nT7 P5 Z-0.25\n", "fuzz.tbl", diags));
  return table;
}

gcode::Options fuzz_options(std::uint8_t flags) {
  gcode::Options o;
  static const auto extensions = gcode::standard_extensions(gcode::Dialect::LinuxCnc);
  o.extensions = extensions;   // the modules built on the core are fuzzed with it
  o.tool_table = fuzz_tools();
  o.extensions = gcode::standard_extensions(gcode::Dialect::LinuxCnc);
  o.mode = (flags & 1) ? gcode::Mode::Execute : gcode::Mode::Scan;
  o.block_delete = (flags & 2) != 0;
  o.initial_units = (flags & 4) ? canon::Units::Inch : canon::Units::Mm;
  if (flags & 8) o.axes = AxisMask::from_letters("XYZUVW");
  if (flags & 16) std::swap(o.axis_map[0], o.axis_map[2]);
  o.quiet_until_segment = (flags & 32) ? 3 : 0;
  // M99 in the main program repeats it only in scan mode here: in execute mode a repeating
  // program runs until its caller stops it, which this harness does not.
  if ((flags & 64) && o.mode == gcode::Mode::Scan) o.main_m99 = gcode::MainM99::Repeat;
  if (flags & 128) {
    o.dialect = gcode::Dialect::Fanuc;
    o.machine = (flags & 8) ? gcode::MachineKind::Lathe : gcode::MachineKind::Mill;
  }
  o.extensions = gcode::standard_extensions(o.dialect);
  // No subprogram files: the fuzzer must not read the disk. Small limits: no input may run
  // for long or grow memory without bound.
  o.subroutine_path.clear();
  o.limits.max_blocks = 20000;
  o.limits.max_loop_iterations = 5000;
  o.limits.max_repeat_count = 5000;
  o.limits.max_segments = 20000;
  o.limits.max_skipped_lines = 20000;
  o.limits.max_main_repeats = 20;
  return o;
}

// Runs to the end, answering sync points with plausible values.
void run(gcode::Interpreter& interp, canon::Sink& sink) {
  for (int guard = 0; guard < 100000; ++guard) {
    const gcode::RunStatus s = interp.run(sink);
    if (s != gcode::RunStatus::NeedSync) return;
    gcode::SyncValues v;
    v.kind = interp.pending_sync();
    v.input_value = 1;
    v.probe_tripped = true;
    interp.sync(v);
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  static std::FILE* null = std::fopen("/dev/null", "w");
  const std::uint8_t flags = data[0];
  const std::string_view text(reinterpret_cast<const char*>(data + 1), size - 1);
  gcode::Interpreter interp(fuzz_options(flags));
  {
    canon::Rs274Printer printer(null, null);
    if (flags & 64) {
      // Every line as MDI.
      std::size_t pos = 0;
      while (pos < text.size()) {
        std::size_t nl = text.find('\n', pos);
        if (nl == std::string_view::npos) nl = text.size();
        interp.execute_mdi(text.substr(pos, nl - pos), printer);
        while (interp.pending_sync() != gcode::SyncKind::None) interp.sync({});
        pos = nl + 1;
      }
    } else {
      interp.open_text("fuzz.ngc", std::string(text));
      run(interp, printer);
    }
  }
  // The state must stay a consistent value.
  const gcode::InterpState st = interp.state();
  if (st.digest() != gcode::InterpState(st).digest()) __builtin_trap();
  return 0;
}
