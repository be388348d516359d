// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM codes M180/M181: the condition number checked against the machine's, one canonical
// process_code call each (the tick's gap servo applies it at an exact stop of no time).
#include "opencnc/edm/edm_codes.hpp"

#include <algorithm>
#include <cmath>

#include <fmt/format.h>

#include "opencnc/gcode/standard_extensions.hpp"

namespace opencnc::gcode {

namespace {

constexpr int kCondition = 180, kOff = 181;

std::string listed(const std::vector<int>& numbers) {
  std::string s;
  for (int n : numbers) s += (s.empty() ? "" : ", ") + std::to_string(n);
  return s;
}

class EdmCodes final : public CodeHandler {
 public:
  EdmCodes(std::vector<int> conditions, std::vector<double> orbits)
      : conditions_(std::move(conditions)), orbits_(std::move(orbits)) {}

  void execute(ExecContext& ctx, const Block& b, int code) override {
    canon::ProcessCode c;
    c.code = code;
    c.group = kCondition;  // M180 and M181 replace each other: the generator's condition or off
    if (code == kCondition) {
      const double p = b.p_or(0);
      const bool whole = b.has('p') && std::isfinite(p) && p == std::floor(p) && p >= 1 && p <= 99;
      const bool known = conditions_.empty() || std::find(conditions_.begin(), conditions_.end(),
                                                          static_cast<int>(p)) != conditions_.end();
      if (!whole || !known) {
        ctx.error(
            ErrorCode::EdmCondition,
            conditions_.empty()
                ? std::string("M180 needs the number of a machining condition as P (1 to 99)")
                : fmt::format("M180 needs the number of one of the machine's machining conditions as P ({})",
                              listed(conditions_)));
      }
      c.p = p;
      if (b.has('q')) c.q = orbit_word(ctx, b, static_cast<int>(p));
    }
    ctx.output().process_code(c);
  }

 private:
  // M180 P<n> Q<r>: this burn's orbit grows to r instead of the condition's orbit_radius_mm; at
  // most that radius (the reach the profile and the preflight checked), and only with an orbit.
  double orbit_word(ExecContext& ctx, const Block& b, int n) const {
    const double q = b.q_or(0);
    const auto at = std::find(conditions_.begin(), conditions_.end(), n);
    const std::size_t i = static_cast<std::size_t>(at - conditions_.begin());
    const double most = at != conditions_.end() && i < orbits_.size() ? orbits_[i] : -1;
    if (!std::isfinite(q) || q <= 0) {
      ctx.error(ErrorCode::EdmCondition, "M180's Q is the burn's orbit radius in mm: a number above 0");
    } else if (most == 0) {
      ctx.error(ErrorCode::EdmCondition,
                fmt::format("M180 P{} Q: condition {} has no orbit whose radius Q could set", n, n));
    } else if (most > 0 && q > most + 1e-12) {
      ctx.error(ErrorCode::EdmCondition,
                fmt::format("M180 P{} Q{}: the orbit's radius may be at most condition {}'s orbit_radius_mm "
                            "({} mm)",
                            n, q, n, most));
    }
    return q;
  }

  std::vector<int> conditions_;
  std::vector<double> orbits_;  ///< each condition's orbit radius (0: no orbit); empty: unknown
};

}  // namespace

void add_edm_codes(Extensions& ext, std::vector<int> conditions, std::vector<double> orbits) {
  auto codes = std::make_shared<EdmCodes>(std::move(conditions), std::move(orbits));
  for (int code : {kCondition, kOff}) ext.m[static_cast<std::size_t>(code)] = codes;
}

std::shared_ptr<const Extensions> edm_extensions(Dialect dialect, std::vector<int> conditions,
                                                 std::shared_ptr<const Extensions> base,
                                                 std::vector<double> orbits) {
  auto ext = std::make_shared<Extensions>(base ? *base : *standard_extensions(dialect));
  add_edm_codes(*ext, std::move(conditions), std::move(orbits));
  return ext;
}

}  // namespace opencnc::gcode
