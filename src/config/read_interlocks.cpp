// SPDX-License-Identifier: GPL-3.0-or-later
// Reading `[interlocks]` — named digital inputs and outputs and the rules that compile into
// machine::InterlockRules — and `[handwheel]`. The rule language is in docs/machine.md.
#include <fmt/format.h>

#include <cctype>
#include <optional>
#include <string>
#include <vector>

#include "sections.hpp"

namespace opencnc::config::detail {

namespace {

using machine::InterlockAction;
using machine::RuleToken;
using machine::SignalKind;
using machine::TokenOp;

/// A word of a rule and where it starts in the rule's text (0-based).
struct Word {
  std::string text;
  std::size_t at = 0;
};

/// Words are runs of letters, digits and '_'; '(' and ')' are words of their own. Returns the
/// offset of a character that is none of these and no blank, or npos.
std::size_t split(std::string_view rule, std::vector<Word>& out) {
  std::size_t i = 0;
  while (i < rule.size()) {
    const unsigned char ch = static_cast<unsigned char>(rule[i]);
    if (ch == ' ' || ch == '\t') {
      ++i;
    } else if (ch == '(' || ch == ')') {
      out.push_back({std::string(1, static_cast<char>(ch)), i++});
    } else if (std::isalnum(ch) || ch == '_') {
      const std::size_t start = i;
      while (i < rule.size() && (std::isalnum(static_cast<unsigned char>(rule[i])) || rule[i] == '_')) ++i;
      std::string w(rule.substr(start, i - start));
      for (char& c : w) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
      out.push_back({std::move(w), start});
    } else {
      return i;
    }
  }
  return std::string_view::npos;
}

/// Compiles one rule; reports the first problem at the offset of the word at fault.
class RuleCompiler {
 public:
  RuleCompiler(const MachineProfile& p, std::string_view text) : p_(p), text_(text) {}

  /// The rule, or nullopt with `error` and `error_at` (offset in the text) set.
  std::optional<machine::InterlockRule> compile() {
    const std::size_t bad = split(text_, words_);
    if (bad != std::string_view::npos) {
      fail(bad, fmt::format("'{}' cannot appear in a rule", text_[bad]));
      return std::nullopt;
    }
    machine::InterlockRule r;
    if (!action(r)) return std::nullopt;
    if (pos_ >= words_.size() || (words_[pos_].text != "when" && words_[pos_].text != "unless")) {
      fail_here("expected 'when' or 'unless' after the action");
      return std::nullopt;
    }
    const bool unless = words_[pos_++].text == "unless";
    if (!expression()) return std::nullopt;
    if (pos_ < words_.size()) {
      fail_here(fmt::format("unexpected '{}'", words_[pos_].text));
      return std::nullopt;
    }
    if (unless && !emit({TokenOp::Not})) return std::nullopt;
    r.token_count = static_cast<std::uint8_t>(tokens_.size());
    for (std::size_t i = 0; i < tokens_.size(); ++i) r.tokens[i] = tokens_[i];
    return r;
  }
  const std::string& error() const { return error_; }
  std::size_t error_at() const { return error_at_; }

 private:
  /// Records the first problem; always false.
  bool fail(std::size_t at, std::string message) {
    if (error_.empty()) {
      error_ = std::move(message);
      error_at_ = at;
    }
    return false;
  }
  bool fail_here(std::string message) {
    return fail(pos_ < words_.size() ? words_[pos_].at : text_.size(), std::move(message));
  }
  bool accept(std::string_view w) {
    if (pos_ < words_.size() && words_[pos_].text == w) {
      ++pos_;
      return true;
    }
    return false;
  }
  bool emit(RuleToken t) {
    if (tokens_.size() == static_cast<std::size_t>(machine::kMaxRuleTokens)) {
      return fail(
          0, fmt::format("a rule's condition has at most {} signals and operators", machine::kMaxRuleTokens));
    }
    tokens_.push_back(t);
    return true;
  }

  bool action(machine::InterlockRule& r) {
    const std::size_t at = pos_ < words_.size() ? words_[pos_].at : 0;
    if (accept("stop")) {
      if (accept("spindle")) return set(r, InterlockAction::StopSpindle);
      if (accept("coolant")) return set(r, InterlockAction::StopCoolant);
      return fail_here("'stop' takes 'spindle' or 'coolant'");
    }
    if (accept("block")) {
      if (accept("spindle")) return set(r, InterlockAction::BlockSpindle);
      if (accept("motion")) return set(r, InterlockAction::BlockMotion);
      fail_here("'block' takes 'spindle' or 'motion'");
      return false;
    }
    if (accept("hold")) {
      if (accept("motion")) return set(r, InterlockAction::HoldMotion);
      fail_here("'hold' takes 'motion'");
      return false;
    }
    if (accept("estop")) return set(r, InterlockAction::EStop);
    if (accept("set")) {
      const std::size_t name_at = pos_ < words_.size() ? words_[pos_].at : text_.size();
      const std::string name = pos_ < words_.size() ? words_[pos_++].text : "";
      for (const NamedSignal& o : p_.interlocks.outputs) {
        if (o.name == name) {
          r.output = static_cast<std::uint8_t>(o.channel);
          return set(r, InterlockAction::SetOutput);
        }
      }
      fail(name_at, name.empty() ? std::string("'set' takes the name of an output of [interlocks.outputs]")
                                 : fmt::format("'{}' is not an output of [interlocks.outputs]", name));
      return false;
    }
    fail(at,
         "a rule starts with an action: stop spindle, stop coolant, block spindle, block motion, hold "
         "motion, estop or set OUTPUT");
    return false;
  }
  static bool set(machine::InterlockRule& r, InterlockAction a) {
    r.action = a;
    return true;
  }

  // expression := term ('or' term)* ; term := factor ('and' factor)* ; factor := 'not' factor |
  // '(' expression ')' | signal. Emitted in postfix order.
  bool expression() {
    if (!term()) return false;
    while (accept("or")) {
      if (!term() || !emit({TokenOp::Or})) return false;
    }
    return true;
  }
  bool term() {
    if (!factor()) return false;
    while (accept("and")) {
      if (!factor() || !emit({TokenOp::And})) return false;
    }
    return true;
  }
  bool factor() {
    if (++depth_ > 16) return (fail_here("the condition is nested too deeply"));
    bool ok;
    if (accept("not")) {
      ok = factor() && emit({TokenOp::Not});
    } else if (accept("(")) {
      ok = expression();
      if (ok && !accept(")")) ok = (fail_here("expected ')'"));
    } else {
      ok = signal();
    }
    --depth_;
    return ok;
  }
  bool signal() {
    if (pos_ >= words_.size()) return (fail_here("a condition needs a signal here"));
    const Word& w = words_[pos_];
    const std::optional<RuleToken> t = lookup(w.text);
    if (!t) return (fail(w.at, fmt::format("unknown signal '{}'", w.text)));
    ++pos_;
    return emit(*t);
  }

  std::optional<RuleToken> lookup(const std::string& w) const {
    static constexpr std::pair<std::string_view, SignalKind> kBuiltins[] = {
        {"estop", SignalKind::EStop},
        {"machine_on", SignalKind::MachineOn},
        {"spindle_on", SignalKind::SpindleOn},
        {"spindle_at_speed", SignalKind::SpindleAtSpeed},
        {"coolant_on", SignalKind::Coolant},
        {"table_still", SignalKind::TableStill},
        {"program_running", SignalKind::ProgramRunning},
    };
    for (const auto& [name, kind] : kBuiltins) {
      if (w == name) return RuleToken{TokenOp::Signal, kind, 0};
    }
    for (const NamedSignal& in : p_.interlocks.inputs) {
      if (w == in.name)
        return RuleToken{TokenOp::Signal, SignalKind::DigitalInput, static_cast<std::uint8_t>(in.channel)};
    }
    for (const NamedSignal& out : p_.interlocks.outputs) {
      if (w == out.name)
        return RuleToken{TokenOp::Signal, SignalKind::DigitalOutput, static_cast<std::uint8_t>(out.channel)};
    }
    static constexpr std::pair<std::string_view, SignalKind> kPerAxis[] = {
        {"_homed", SignalKind::AxisHomed},        {"_moving", SignalKind::AxisMoving},
        {"_limit_min", SignalKind::AxisLimitMin}, {"_limit_max", SignalKind::AxisLimitMax},
        {"_home", SignalKind::AxisHomeSwitch},
    };
    for (const AxisProfile& a : p_.axes) {
      const char axis = static_cast<char>(std::tolower(letter(a.axis)));
      for (const auto& [suffix, kind] : kPerAxis) {
        if (w.size() == suffix.size() + 1 && w[0] == axis && std::string_view(w).substr(1) == suffix)
          return RuleToken{TokenOp::Signal, kind, static_cast<std::uint8_t>(a.joint)};
      }
    }
    return std::nullopt;
  }

  const MachineProfile& p_;
  std::string_view text_;
  std::vector<Word> words_;
  std::size_t pos_ = 0;
  int depth_ = 0;
  std::vector<RuleToken> tokens_;
  std::string error_;
  std::size_t error_at_ = 0;
};

bool valid_name(const std::string& n) {
  if (n.empty() || !std::isalpha(static_cast<unsigned char>(n[0]))) return false;
  for (char c : n) {
    if (!(std::islower(static_cast<unsigned char>(c)) || std::isdigit(static_cast<unsigned char>(c)) ||
          c == '_'))
      return false;
  }
  return true;
}

/// `[interlocks.outputs]` or `[interlocks.inputs]`: name = channel, or (inputs) a table with
/// `channel` and `sim = { axis, window }` (a switch on that axis drives the simulated input).
void read_names(Section& s, std::string_view key, int channels, bool inputs, MachineProfile& p) {
  const toml::table* t = s.subtable(key);
  if (t == nullptr) return;
  Reporter& r = s.reporter();
  for (const auto& [name_key, node] : *t) {
    const std::string name(name_key.str());
    const std::string path = s.key_path(key) + "." + name;
    if (!valid_name(name)) {
      r.error(&name_key.source(),
              fmt::format("{}: a signal name is lower case letters, digits and '_', starting with a letter",
                          path),
              "config.range");
      continue;
    }
    std::optional<std::int64_t> channel;
    const toml::table* sim = nullptr;
    if (const auto* i = node.as_integer()) {
      channel = i->get();
    } else if (const toml::table* entry = node.as_table()) {
      Section e(*entry, path,
                inputs ? std::initializer_list<std::string_view>{"channel", "sim"}
                       : std::initializer_list<std::string_view>{"channel"},
                r);
      channel = e.integer("channel", 0, machine::kDigitalChannels - 1);
      if (!channel && !e.has("channel")) e.missing("channel");
      sim = inputs ? e.subtable("sim") : nullptr;
    } else {
      r.error(&node.source(), fmt::format("{} must be a channel number{}", path, inputs ? " or a table" : ""),
              "config.type");
      continue;
    }
    if (!channel) continue;
    if (*channel < 0 || *channel >= channels) {
      r.error(&node.source(),
              fmt::format("{}: channel {} does not exist (io.digital_{} = {})", path, *channel,
                          inputs ? "inputs" : "outputs", channels),
              "config.range");
      continue;
    }
    (inputs ? p.interlocks.inputs : p.interlocks.outputs).push_back({name, static_cast<int>(*channel)});
    if (sim == nullptr) continue;
    Section m(*sim, path + ".sim", {"axis", "window", "hysteresis", "noise"}, r);
    machine::SimInputSwitch w;
    w.channel = static_cast<int>(*channel);
    if (const auto axis_name = m.string("axis")) {
      const auto axis = axis_from_letter(*axis_name);
      const AxisProfile* a = axis ? p.find(*axis) : nullptr;
      if (a == nullptr) {
        m.error("axis", fmt::format("{}.sim.axis (\"{}\") is not an axis of this profile", path, *axis_name),
                "config.range");
      } else {
        w.joint = a->joint;
      }
    } else if (!m.has("axis")) {
      m.missing("axis");
    }
    if (const auto win = read_window(m, "window")) {
      w.window = *win;
    } else if (!m.has("window")) {
      m.missing("window");
    }
    w.hysteresis = m.number_or("hysteresis", w.hysteresis, Bound::NonNegative);
    w.noise = m.number_or("noise", w.noise, Bound::NonNegative);
    if (p.sim_input_switches.size() == static_cast<std::size_t>(machine::kMaxSimInputSwitches)) {
      m.error("axis", fmt::format("at most {} simulated input switches", machine::kMaxSimInputSwitches),
              "config.range");
    } else if (w.joint >= 0 && w.window.present) {
      p.sim_input_switches.push_back(w);
    }
  }
}

/// The position of a character of a rule string: exact for a one-line string without escapes
/// (its value then stands between the quotes as written), else the string's start.
toml::source_region char_at(const toml::node& n, const std::string& value, std::size_t offset) {
  toml::source_region r = n.source();
  const bool exact = r.begin.line == r.end.line && r.end.column == r.begin.column + value.size() + 2;
  if (exact) r.begin.column = static_cast<toml::source_index>(r.begin.column + 1 + offset);
  r.end = r.begin;
  return r;
}

}  // namespace

void read_interlocks(Section& top, MachineProfile& p) {
  const toml::table* t = top.subtable("interlocks");
  if (t == nullptr) return;
  Section s(*t, "interlocks", {"inputs", "outputs", "rules"}, top.reporter());
  read_names(s, "inputs", p.io.digital_inputs, true, p);
  read_names(s, "outputs", p.io.digital_outputs, false, p);
  const toml::node* rules = s.find("rules");
  if (rules == nullptr) return;
  const toml::array* list = rules->as_array();
  if (list == nullptr) {
    s.error("rules", "interlocks.rules must be an array of rules (strings)", "config.type");
    return;
  }
  for (const toml::node& n : *list) {
    const auto* text = n.as_string();
    if (text == nullptr) {
      s.reporter().error(&n.source(), "interlocks.rules holds rules as strings", "config.type");
      continue;
    }
    if (p.interlocks.rules.count == machine::kMaxInterlockRules) {
      s.reporter().error(&n.source(), fmt::format("at most {} interlock rules", machine::kMaxInterlockRules),
                         "config.range");
      break;
    }
    const std::string& rule = text->get();
    RuleCompiler c(p, rule);
    const std::optional<machine::InterlockRule> compiled = c.compile();
    if (!compiled) {
      const toml::source_region at = char_at(n, rule, c.error_at());
      s.reporter().error(&at, fmt::format("interlock rule \"{}\": {}", rule, c.error()), "config.interlock");
      continue;
    }
    machine::InterlockRule& slot =
        p.interlocks.rules.rules[static_cast<std::size_t>(p.interlocks.rules.count++)];
    slot = *compiled;
    slot.line = static_cast<std::uint16_t>(n.source().begin.line);
    p.interlocks.rule_texts.push_back(rule);
  }
}

void read_handwheel(Section& top, MachineProfile& p) {
  const toml::table* t = top.subtable("handwheel");
  if (t == nullptr) return;
  Section s(*t, "handwheel", {"steps"}, top.reporter());
  p.handwheel.present = true;
  const toml::node* n = s.find("steps");
  if (n == nullptr) return;
  const toml::array* a = n->as_array();
  std::vector<double> steps;
  bool ok = a != nullptr && !a->empty() && a->size() <= 8;
  for (std::size_t i = 0; ok && i < a->size(); ++i) {
    const std::optional<double> v = (*a)[i].value<double>();
    ok = v && *v > 0 && std::isfinite(*v);
    if (ok) steps.push_back(*v);
  }
  if (!ok) {
    s.error("steps", "handwheel.steps must be 1 to 8 positive numbers (units per count)", "config.range");
    return;
  }
  p.handwheel.steps = std::move(steps);
}

}  // namespace opencnc::config::detail
