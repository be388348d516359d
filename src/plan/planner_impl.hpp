// SPDX-License-Identifier: GPL-3.0-or-later
// The planner's private state, shared by planner.cpp (reading, emitting, publishing) and
// planner_g2.cpp (curvature-continuous corners).
#pragma once

#include <cmath>
#include <limits>
#include <optional>
#include <vector>

#include "block_limits.hpp"
#include "lookahead.hpp"
#include "opencnc/plan/planner.hpp"
#include "path_geometry.hpp"
#include "program_reader.hpp"

namespace opencnc::plan {

inline constexpr double kInf = std::numeric_limits<double>::infinity();

using detail::Element;
using traj::MotionBlock;

struct Planner::Impl {
  MachineLimits limits;
  PlannerConfig config;
  detail::LimitParams params;
  int ticks = 1;
  Diagnostics diags;
  PlanStats stats;
  bool config_ok = true;
  bool failed = false;

  const canon::Program* program = nullptr;
  std::optional<detail::ProgramReader> reader;
  std::optional<detail::Lookahead> window;
  bool reading_done = false;
  // Streams (start_stream): the program grows while it is planned.
  bool streaming = false;
  bool flush_asked = false;          ///< stream_flush(): plan what is readable to a stop
  bool flushing = false;             ///< a flush is being published; reading waits until it is
  bool input_waiting = false;        ///< everything readable has been read
  std::optional<Element> pending;    ///< last element; its end is decided by the next one
  std::vector<MotionBlock> reports;  ///< Report markers waiting after `pending`
  Pose last_end{};                   ///< exact end of the last emitted path block
  bool continues = false;            ///< `prev` runs on into the next path block (no stop)
  MotionBlock prev;                  ///< the last emitted path block (with jerk limits)
  /// With jerk limits: curvature-continuous (G2) blends, and the last one held back until the
  /// next corner says where it ends (planner_g2.cpp).
  bool g2 = false;
  double v_bound = 0;  ///< no speed along s exceeds this
  struct Held {
    MotionBlock curve;       ///< the blend, identity set
    detail::JoinPoint from;  ///< where it starts
    MotionBlock before;      ///< the programmed piece it leaves (for its deviation)
    MotionBlock after;       ///< the programmed piece it joins, whole (for its deviation)
    double tolerance = 0;    ///< the tolerance it was sized for (0: none)
    Pose mean_turn{};        ///< turn of its tangent per unit of the programmed length it replaces
  };
  std::optional<Held> held;

  Impl(const MachineLimits& l, const PlannerConfig& c);
  void check_config();
  void emit_path(const MotionBlock& b, double junction);
  void emit_pieces(const MotionBlock& b, double junction, int depth, bool piece);
  void emit_block(const MotionBlock& b, double junction, const detail::RawLimits* raw, bool piece);
  void emit_marker(const MotionBlock& m);
  void emit_reports();
  void publish_front(traj::BlockQueue& queue);
  void on_element(Element& e);
  void on_marker(const MotionBlock& m);
  void flush_pending();
  /// The corner between `a` and `e`: true when the motion goes on through it (blended or
  /// tangent), false when it stops there. Emits what comes before the corner.
  bool corner(Element& a, Element& e) { return g2 ? corner_g2(a, e) : corner_g1(a, e); }
  bool corner_g1(Element& a, Element& e);
  // planner_g2.cpp: curvature-continuous corners (with jerk limits).
  bool corner_g2(Element& a, Element& e);
  bool g2_blend(const Element& a, const Element& e, const detail::CornerTurn& turn, double tol,
                detail::Blend& out) const;
  bool share_junction(const Element& a, const Element& e, double tol, detail::Blend& blend);
  void pass_through(Element& a);
  void release_held();
  double commanded_max(const MotionBlock& b) const;
  /// No block's cap exceeds this (2·√(Σ V_i²): a line's speed bound, with room for curves whose
  /// |dp/ds| is below 1): the tick's bound of every speed along s.
  double speed_bound() const noexcept {
    double v = 0;
    for (int i = 0; i < kAxisCount; ++i) {
      if (limits.axes.has(static_cast<Axis>(i))) v += limits[i].max_velocity * limits[i].max_velocity;
    }
    return 2 * std::sqrt(v);
  }
  detail::BlendNeed blend_need(const MotionBlock& a, const MotionBlock& e) const;
  bool blend_pays(const Element& a, const Element& e, const detail::Blend& blend) const;
  bool read_one();
  bool begin(const canon::Program& program, bool stream);
  /// The reader has nothing for now: ends the program, a flush, or waits for input.
  void out_of_input();
};

}  // namespace opencnc::plan
