// SPDX-License-Identifier: GPL-3.0-or-later
// The cut chart in a program: the library over the store, M194 and the material's settings as
// process codes, G41/G42 by the kerf, and the feed check at the line.
#include "opencnc/cutting/cut_chart.hpp"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <map>
#include <set>

#include <fmt/format.h>

#include "opencnc/canon/program.hpp"
#include "opencnc/controller/program_source.hpp"
#include "opencnc/core/atomic_file.hpp"
#include "opencnc/machine/cut_chart_codes.hpp"
#include "opencnc/machine/plasma.hpp"

namespace opencnc::cutting {

using store::Material;

CutChartLibrary::CutChartLibrary(std::shared_ptr<store::CutChartStore> store,
                                 const config::CutChartProfile& profile)
    : store_(std::move(store)), profile_(profile) {}

int CutChartLibrary::selected() {
  const int chosen = store_->selected().value_or(0);
  return chosen > 0 ? chosen : profile_.material;
}

std::shared_ptr<const std::vector<Material>> CutChartLibrary::chart(std::string* error) {
  std::lock_guard lock(mutex_);
  const std::uint64_t now = store_->changes();
  if (chart_ && now == seen_) return chart_;
  std::string why;
  auto read = store_->chart(&why);
  if (!read) {
    if (error != nullptr) *error = why;
    return nullptr;
  }
  chart_ = std::make_shared<const std::vector<Material>>(std::move(*read));
  seen_ = now;
  return chart_;
}

namespace {

// The program's material in force and the values a program may read (#<_cut_feed> for its F).
constexpr const char* kMaterialParam = "_cut_material";
constexpr const char* kKerfParam = "_cut_kerf";
constexpr const char* kFeedParam = "_cut_feed";
// A comment the pass turns into a diagnostic: "<mark>error@m194: message" — severity, the word
// whose column it points at, the words. The mark opens with a control character (RS) that no
// comment of a program carries, so a program's own "(cut chart: …)" is never taken for one.
// (A warning channel in the interpreter's ExecContext would be the cleaner way; see cutting.md.)
constexpr std::string_view kMark = "\x1e" "cut chart: ";

double to_program(double mm, const gcode::InterpState& st) noexcept {
  return st.modal.units == canon::Units::Inch ? mm / 25.4 : mm;
}

std::string listed(const std::vector<Material>& chart) {
  std::string s;
  for (const Material& m : chart) {
    if (s.size() > 60) return s + ", …";
    s += fmt::format("{}{}", s.empty() ? "" : ", ", m.number);
  }
  return s.empty() ? "none" : s;
}

class Chart {
 public:
  explicit Chart(std::shared_ptr<CutChartLibrary> library) : library_(std::move(library)) {}

  /// The material the program has selected, if any.
  static const gcode::NamedValue* in_force(gcode::ExecContext& ctx) {
    const auto it = ctx.state().globals.find(kMaterialParam);
    return it != ctx.state().globals.end() && it->second.set && it->second.value > 0 ? &it->second : nullptr;
  }

  /// Material `number` from now on: its settings to the torch stage, its values for the program.
  /// `selected`: the library's choice (at M190 or G41/G42), not the program's M194. An unknown
  /// material selects nothing: the pass reports it at this line (`token` finds its column).
  void select(gcode::ExecContext& ctx, int number, bool selected, const char* token) const {
    std::string error;
    const auto chart = library_->chart(&error);
    const Material* m = chart ? store::find(*chart, number) : nullptr;
    canon::Sink& out = ctx.output();
    const auto code = [&](int c, double p) {
      canon::ProcessCode pc;
      pc.code = c;
      pc.p = p;
      pc.q = selected ? 1 : 0;
      pc.group = c;  // each its own group: a resumed program gets every value in force again
      out.process_code(pc);
    };
    if (m == nullptr) {
      const std::string how = selected ? fmt::format("the material selected for this machine ({})", number)
                                       : fmt::format("M194: material {}", number);
      out.comment(fmt::format(
          "{}{}@{}: {}", kMark, "error", token,
          chart ? fmt::format("{} is not in the cut chart {} (its materials: {}; `opencnc "
                              "cutchart --db {} list`)",
                              how, library_->store()->path(), listed(*chart), library_->store()->path())
                : fmt::format("{}: the cut chart cannot be read: {}", how, error)));
      return;
    }
    code(machine::kMaterialCode, number);
    code(machine::kChartPierceHeightCode, m->pierce_height_mm);
    code(machine::kChartPierceDelayCode, m->pierce_delay_s);
    code(machine::kChartCutHeightCode, m->cut_height_mm);
    code(machine::kChartArcVoltageCode, m->arc_voltage_v);
    code(machine::kChartPuddleHeightCode, m->puddle_height_mm);
    code(machine::kChartPuddleDelayCode, m->puddle_delay_s);
    code(machine::kChartPreheatCode, m->preheat_s);
    gcode::InterpState& st = ctx.state();
    st.globals[kMaterialParam] = {static_cast<double>(number), true};
    st.globals[kKerfParam] = {to_program(m->kerf_width_mm, st), true};
    st.globals[kFeedParam] = {to_program(m->feed_mm_min, st), true};
  }

  /// The program's material, else the library's selection (selected now); nothing without either.
  std::optional<Material> ensure(gcode::ExecContext& ctx, const char* token) const {
    if (in_force(ctx) == nullptr) {
      const int selected = library_->selected();
      if (selected <= 0) return std::nullopt;
      select(ctx, selected, true, token);
    }
    const auto chart = library_->chart();
    const Material* m = chart ? store::find(*chart, static_cast<int>(in_force(ctx)->value)) : nullptr;
    return m != nullptr ? std::optional<Material>(*m) : std::nullopt;
  }

  CutChartLibrary& library() const noexcept { return *library_; }

 private:
  std::shared_ptr<CutChartLibrary> library_;
};

// M194 P<n>.
class MaterialCode final : public gcode::CodeHandler {
 public:
  explicit MaterialCode(std::shared_ptr<const Chart> chart) : chart_(std::move(chart)) {}
  void execute(gcode::ExecContext& ctx, const gcode::Block& b, int) override {
    const double p = b.p_or(0);
    if (!b.has('p') || !std::isfinite(p) || p != std::floor(p) || p < 1 || p > 99999) {
      ctx.output().comment(fmt::format(
          "{}error@m194: M194 needs the number of a cut chart material as P (a whole number from 1 to 99999)",
          kMark));
      return;
    }
    chart_->select(ctx, static_cast<int>(p), false, "m194");
  }

 private:
  std::shared_ptr<const Chart> chart_;
};

// M190 (and anything else run with the material in force): the library's material when the
// program has none, then the code as before.
class WithMaterial final : public gcode::CodeHandler {
 public:
  WithMaterial(std::shared_ptr<const Chart> chart, std::shared_ptr<gcode::CodeHandler> inner)
      : chart_(std::move(chart)), inner_(std::move(inner)) {}
  std::optional<Rejection> check(const gcode::Block& b, int code,
                                 const gcode::InterpState& st) const override {
    return inner_->check(b, code, st);
  }
  Traits traits(int code) const override { return inner_->traits(code); }
  void execute(gcode::ExecContext& ctx, const gcode::Block& b, int code) override {
    chart_->ensure(ctx, "m190");
    inner_->execute(ctx, b, code);
  }

 private:
  std::shared_ptr<const Chart> chart_;
  std::shared_ptr<gcode::CodeHandler> inner_;
};

// G41/G42 with a material in force: G41.1/G42.1 with the kerf as the diameter. G41.1/G42.1: a
// warning when the program's diameter is not the kerf.
class KerfComp final : public gcode::CodeHandler {
 public:
  KerfComp(std::shared_ptr<const Chart> chart, std::shared_ptr<gcode::CodeHandler> tool,
           std::shared_ptr<gcode::CodeHandler> dynamic)
      : chart_(std::move(chart)), tool_(std::move(tool)), dynamic_(std::move(dynamic)) {}
  std::optional<Rejection> check(const gcode::Block& b, int code,
                                 const gcode::InterpState& st) const override {
    return inner(code)->check(b, code, st);
  }
  Traits traits(int code) const override { return inner(code)->traits(code); }
  void execute(gcode::ExecContext& ctx, const gcode::Block& b, int code) override {
    const std::optional<Material> m = chart_->ensure(ctx, code / 10 == 41 ? "g41" : "g42");
    if (!m) return inner(code)->execute(ctx, b, code);
    const double kerf = to_program(m->kerf_width_mm, ctx.state());
    if (code % 10 == 1) {
      const double tol = to_program(chart_->library().profile().kerf_tolerance_mm, ctx.state());
      if (b.has('d') && std::fabs(b.get('d') - kerf) > tol + 1e-9)
        ctx.output().comment(fmt::format(
            "{}warning@d: G{}.1 D{} is not the kerf of cut chart material {} ({}): {} (more than {} apart)",
            kMark, code / 10, b.get('d'), m->number, m->name, kerf, tol));
      return dynamic_->execute(ctx, b, code);
    }
    gcode::Block k = b;  // G41 → G41.1 D<kerf>
    k.words |= 1u << ('d' - 'a');
    k.value[static_cast<std::size_t>('d' - 'a')] = kerf;
    k.words &= ~(1u << ('l' - 'a'));
    dynamic_->execute(ctx, k, code + 1);
  }

 private:
  gcode::CodeHandler* inner(int code) const { return code % 10 == 1 ? dynamic_.get() : tool_.get(); }
  std::shared_ptr<const Chart> chart_;
  std::shared_ptr<gcode::CodeHandler> tool_, dynamic_;
};

// --- the feed check --------------------------------------------------------------------------

// The column where `word` (lower case: "f", "d", "m194") starts on `line` of `path`, outside
// comments (the line's first character when it is not there), each file read once (core::read_file's
// bounds: a file it refuses gives column 0).
class Columns {
 public:
  std::uint32_t column(const std::string& path, std::uint32_t line, std::string_view word) {
    auto it = files_.find(path);
    if (it == files_.end()) it = files_.emplace(path, read(path)).first;
    const std::vector<std::string>& lines = it->second;
    if (line == 0 || line > lines.size()) return 0;
    const std::string& text = lines[line - 1];
    int depth = 0;
    for (std::size_t i = 0; i < text.size(); ++i) {
      const char c = text[i];
      if (c == '(') ++depth;
      if (c == ')' && depth > 0) --depth;
      if (depth == 0 && c == ';') break;
      if (depth != 0 || text.size() - i < word.size()) continue;
      bool same = true;
      for (std::size_t k = 0; k < word.size() && same; ++k)
        same = std::tolower(static_cast<unsigned char>(text[i + k])) == word[k];
      if (same) return static_cast<std::uint32_t>(i + 1);
    }
    const std::size_t first = text.find_first_not_of(" \t");
    return first == std::string::npos ? 1 : static_cast<std::uint32_t>(first + 1);
  }

 private:
  static std::vector<std::string> read(const std::string& path) {
    std::vector<std::string> lines;
    std::string text;
    if (!read_file(path, text, nullptr)) return lines;
    for (std::size_t pos = 0; pos <= text.size();) {
      const std::size_t eol = std::min(text.find('\n', pos), text.size());
      lines.emplace_back(text.substr(pos, eol - pos));
      pos = eol + 1;
    }
    return lines;
  }
  std::map<std::string, std::vector<std::string>, std::less<>> files_;
};

class ChartCheck final : public controller::MovePass {
 public:
  explicit ChartCheck(std::shared_ptr<CutChartLibrary> library) : library_(std::move(library)) {}

  void process(canon::Program& p) override {
    for (; next_move_ < p.size(); ++next_move_) {
      for (; next_action_ < p.action_count() && p.action(next_action_).before_move <= next_move_;
           ++next_action_)
        take(p, p.action(next_action_));
      check(p, next_move_);
    }
    for (; next_action_ < p.action_count(); ++next_action_) take(p, p.action(next_action_));
  }
  void restart() override { next_move_ = next_action_ = 0; }
  const Diagnostics& failures() const override { return diags_; }

 private:
  void report(const canon::Program& p, std::uint32_t context, std::uint32_t line, Severity severity,
              std::string_view word, const std::string& message, const char* code) {
    const controller::SourceLocation at = controller::locate(p.sources(), context, line);
    std::string where;
    for (const std::string& c : at.calls) where += fmt::format(" (in {})", c);
    diags_.add({severity, at.file, at.line, columns_.column(at.file, at.line, word), message + where, code});
  }

  void take(const canon::Program& p, const canon::Action& a) {
    if (a.kind == canon::ActionKind::Comment) {
      const std::string& text = p.text(a.text);
      if (text.compare(0, kMark.size(), kMark) != 0) return;
      const std::size_t at = text.find('@'), colon = text.find(": ", kMark.size());
      if (at == std::string::npos || colon == std::string::npos || at > colon) return;
      const bool error = text.compare(kMark.size(), at - kMark.size(), "error") == 0;
      const std::string word = text.substr(at + 1, colon - at - 1);
      report(p, a.context, a.line, error ? Severity::Error : Severity::Warning, word, text.substr(colon + 2),
             error ? "cutchart.material" : "cutchart.kerf");
      return;
    }
    if (a.kind != canon::ActionKind::ProcessCode) return;
    if (a.index == machine::kMaterialCode) {  // looked up once: the check runs for every move
      material_ = static_cast<int>(a.value);
      const auto chart = library_->chart();
      const Material* m = chart ? store::find(*chart, material_) : nullptr;
      feed_ = m != nullptr ? m->feed_mm_min : 0.0;
    }
    if (a.index == machine::kTorchOnCode) torch_ = true;
    if (a.index == machine::kTorchOffCode) torch_ = false;
    if (a.index == machine::kThcHoldCode) held_ = true;
    if (a.index == machine::kThcReleaseCode) held_ = false;
  }

  void check(const canon::Program& p, std::size_t id) {
    const canon::Move& mv = p.move(static_cast<canon::SegmentId>(id));
    if (!torch_ || held_ || material_ <= 0 || feed_ <= 0) return;
    if (mv.kind != canon::MoveKind::Feed && mv.kind != canon::MoveKind::Arc) return;
    const double f = p.feed(static_cast<canon::SegmentId>(id));
    const double tol = library_->profile().feed_tolerance;
    if (std::fabs(f - feed_) <= tol * feed_ + 1e-9) return;
    if (!warned_.insert({mv.context, mv.line}).second) return;
    report(p, mv.context, mv.line, Severity::Warning, "f",
           fmt::format("the feed {} mm/min is {} than cut chart material {}'s {} mm/min by more than {} %", f,
                       f < feed_ ? "slower" : "faster", material_, feed_, tol * 100),
           "cutchart.feed");
  }

  std::shared_ptr<CutChartLibrary> library_;
  std::size_t next_move_ = 0, next_action_ = 0;
  int material_ = 0;
  double feed_ = 0;  ///< the material's, mm/min (0: not in the chart)
  bool torch_ = false, held_ = false;
  std::set<std::pair<std::uint32_t, std::uint32_t>> warned_;
  Columns columns_;
  Diagnostics diags_;
};

class Part final : public controller::SourcePart {
 public:
  explicit Part(std::shared_ptr<CutChartLibrary> library) : library_(std::move(library)) {}
  std::shared_ptr<const gcode::Extensions> modules(
      gcode::Dialect, std::shared_ptr<const gcode::Extensions> base) const override {
    auto ext = std::make_shared<gcode::Extensions>(*base);
    add_cut_chart_codes(*ext, library_);
    return ext;
  }
  std::unique_ptr<controller::MovePass> pass() const override { return chart_check_pass(library_); }

 private:
  std::shared_ptr<CutChartLibrary> library_;
};

}  // namespace

void add_cut_chart_codes(gcode::Extensions& ext, std::shared_ptr<CutChartLibrary> library) {
  auto chart = std::make_shared<const Chart>(std::move(library));
  ext.m[machine::kMaterialCode] = std::make_shared<MaterialCode>(chart);
  if (auto on = ext.m[machine::kTorchOnCode])
    ext.m[machine::kTorchOnCode] = std::make_shared<WithMaterial>(chart, on);
  for (int code : {410, 420}) {
    auto tool = ext.g[static_cast<std::size_t>(code)];
    auto dynamic = ext.g[static_cast<std::size_t>(code + 1)];
    if (!tool || !dynamic) continue;
    auto k = std::make_shared<KerfComp>(chart, tool, dynamic);
    ext.g[static_cast<std::size_t>(code)] = k;
    ext.g[static_cast<std::size_t>(code + 1)] = k;
  }
}

std::unique_ptr<controller::MovePass> chart_check_pass(std::shared_ptr<CutChartLibrary> library) {
  return std::make_unique<ChartCheck>(std::move(library));
}

std::shared_ptr<const controller::SourcePart> cut_chart_part(std::shared_ptr<CutChartLibrary> library) {
  return std::make_shared<Part>(std::move(library));
}

bool setup_cut_chart(const config::MachineProfile& profile, controller::MachineSetup& host) {
  const std::optional<config::CutChartProfile> c = config::cut_chart_profile(profile, host.diagnostics());
  if (!c) return !host.diagnostics().has_errors();
  std::string error;
  auto store = store::CutChartStore::open(c->store, &error, false);
  if (!store) {
    host.diagnostics().error(
        profile.source, 0, 0,
        fmt::format("cut_chart.store: {} (create it with `opencnc cutchart --db {} import "
                    "CHART.csv`)",
                    error, c->store),
        "cutchart.store");
    return false;
  }
  host.add_source_part(cut_chart_part(std::make_shared<CutChartLibrary>(std::move(store), *c)));
  return true;
}

}  // namespace opencnc::cutting
