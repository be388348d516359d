// SPDX-License-Identifier: GPL-3.0-or-later
// The EDM stage on its own: the path memory (back across corners, never off the path), the
// gap servo's law (forward, hold, back; a short at the retract limit), the jump's lift and
// timing, the orbit's shapes and its growth in steps.
#include <gtest/gtest.h>

#include <cmath>

#include "opencnc/control/gap_servo.hpp"

namespace opencnc::control {
namespace {

Pose xyz(double x, double y, double z) {
  Pose p;
  p[0] = x;
  p[1] = y;
  p[2] = z;
  return p;
}

machine::EdmCondition roughing() {
  machine::EdmCondition c;
  c.number = 1;
  c.on_time_us = 100;
  c.off_time_us = 50;
  c.peak_current_a = 10;
  c.voltage_v = 100;
  c.servo_reference_v = 45;
  c.gain_mm_s_per_v = 0.02;
  c.max_forward_mm_s = 1;
  c.max_retract_mm_s = 3;
  c.filter_s = 0;  // the law on the raw voltage: exact expectations
  return c;
}

machine::EdmConfig config_with(const machine::EdmCondition& c) {
  machine::EdmConfig e;
  e.enabled = true;
  e.conditions[0] = c;
  e.condition_count = 1;
  return e;
}

TEST(PathMemory, WalksBackAcrossACornerOnThePath) {
  PathMemory m;
  m.reset(xyz(0, 0, 0));
  // Along X to (1, 0), an exact stop at the corner (a new block starts there), then along Y to
  // (1, 1), in 1 µm steps (points every 2 µm).
  for (int i = 1; i <= 1000; ++i) m.advance(xyz(i * 0.001, 0, 0), 0.002, i == 1000);
  for (int i = 1; i <= 1000; ++i) m.advance(xyz(1, i * 0.001, 0), 0.002, false);
  EXPECT_NEAR(m.head_s(), 2.0, 1e-9);
  for (double back : {0.0, 0.25, 0.999, 1.0, 1.001, 1.5, 2.0}) {
    const Pose p = m.at(m.head_s() - back);
    // On the path: either on the X leg (y = 0) or on the Y leg (x = 1), at the right length.
    const bool on_x = std::fabs(p[1]) < 1e-12, on_y = std::fabs(p[0] - 1) < 1e-12;
    EXPECT_TRUE(on_x || on_y) << back;
    const double s = on_y ? 1 + p[1] : p[0];
    EXPECT_NEAR(s, 2.0 - back, 1e-9) << back;
  }
}

TEST(PathMemory, ForgetsTheOldestPointsOnly) {
  PathMemory m;
  m.reset(xyz(0, 0, 0));
  const int n = 3 * PathMemory::kPoints;
  for (int i = 1; i <= n; ++i) m.advance(xyz(i * 0.002, 0, 0), 0.0015, false);
  EXPECT_NEAR(m.head_s() - m.tail_s(), (PathMemory::kPoints - 1) * 0.002, 1e-6);
  EXPECT_NEAR(m.at(m.tail_s() - 1)[0], m.tail_s(), 1e-9);  // clamped to what it remembers
}

/// Runs the stage on a straight feed move down Z (the head where the interpolator would be at
/// the feed scale the stage asked for), with the gap voltage given by `gap(t, z)`.
struct Rig {
  GapServo g;
  Pose head = xyz(0, 0, 0);
  double feed = 1.0;  // mm/s: the block's nominal speed
  double t = 0;
  Pose electrode = head;
  explicit Rig(const machine::EdmConfig& e) {
    g.configure(e, 0.001, 2000);
    g.begin_run(head);
    g.apply_code(180, e.conditions[0].number);
  }
  template <class F>
  void run(int ticks, F gap) {
    for (int i = 0; i < ticks; ++i) {
      head[2] -= g.feed_scale() * feed * 0.001;  // the interpolator at the scaled feed
      GapInputs in;
      in.head = head;
      in.head_feed = feed;
      const auto [v, st] = gap(t, electrode[2]);
      in.gap_voltage_v = v;
      in.gap_state = st;
      electrode = g.step(in);
      t += 0.001;
    }
  }
};

using machine::GapState;

TEST(GapServo, FeedsAnOpenGapAtTheForwardLimit) {
  Rig r(config_with(roughing()));
  r.run(1000, [](double, double) { return std::pair{100.0, GapState::Open}; });
  EXPECT_NEAR(r.g.status().path_speed_mm_s, 1.0, 1e-12);
  EXPECT_NEAR(r.electrode[2], r.head[2], 1e-12);  // at the head
  EXPECT_LT(r.head[2], -0.9);
  EXPECT_TRUE(r.g.generator_on());
}

TEST(GapServo, HoldsAtTheReferenceAndBacksOffAlongThePathBelowIt) {
  Rig r(config_with(roughing()));
  r.run(100, [](double, double) { return std::pair{100.0, GapState::Open}; });  // 0.1 mm of path behind
  r.run(100, [](double, double) { return std::pair{45.0, GapState::Normal}; });
  EXPECT_EQ(r.g.status().path_speed_mm_s, 0.0);
  const double z = r.electrode[2];
  r.run(300, [](double, double) { return std::pair{35.0, GapState::Normal}; });
  // 10 V below: back at 0.2 mm/s (after 0.1 ms of acceleration), the head waits.
  EXPECT_NEAR(r.g.status().path_speed_mm_s, -0.2, 1e-12);
  EXPECT_NEAR(r.electrode[2], z + 0.2 * 0.3, 1e-4);
  EXPECT_NEAR(r.g.status().backlog_mm, r.electrode[2] - r.head[2], 1e-9);
  EXPECT_EQ(r.g.feed_scale(), 0.0);
  EXPECT_TRUE(r.g.head_waits());  // rapids too: the interpolator goes on only with the electrode
  // The gap opens again: forward, up to the head first, then the head goes on.
  r.run(300, [](double, double) { return std::pair{90.0, GapState::Normal}; });
  EXPECT_NEAR(r.electrode[2], r.head[2], 1e-12);
  EXPECT_GT(r.g.feed_scale(), 0.0);
  EXPECT_FALSE(r.g.head_waits());
}

TEST(GapServo, AShortBacksOffAtTheRetractLimitWithinTheAcceleration) {
  Rig r(config_with(roughing()));
  r.run(50, [](double, double) { return std::pair{45.0, GapState::Normal}; });
  r.run(1, [](double, double) { return std::pair{0.5, GapState::Short}; });
  EXPECT_NEAR(r.g.status().path_speed_mm_s, -2.0, 1e-12);  // 2000 mm/s² × 1 ms
  r.run(10, [](double, double) { return std::pair{0.5, GapState::Short}; });
  EXPECT_NEAR(r.g.status().path_speed_mm_s, -3.0, 1e-12);
}

TEST(GapServo, JumpsEveryPeriodWithTheGeneratorOff) {
  machine::EdmCondition c = roughing();
  c.jump_period_s = 0.1;
  c.jump_height_mm = 0.5;
  c.jump_speed_mm_s = 50;
  Rig r(config_with(c));
  int jumps = 0, off = 0;
  double lift_max = 0;
  for (int i = 0; i < 1000; ++i) {
    r.run(1, [](double, double) { return std::pair{45.0, GapState::Normal}; });
    const EdmStatus& s = r.g.status();
    if (s.jumping) {
      ++off;
      EXPECT_FALSE(r.g.generator_on());
      lift_max = std::max(lift_max, s.jump_lift_mm);
      EXPECT_NEAR(r.electrode[2] - r.head[2], s.jump_lift_mm, 1e-9);  // along +Z
    }
    jumps = static_cast<int>(s.jumps);
  }
  // Each jump: 0.5 mm up and down at half the axis' 2 m/s² (its speed limit of 50 mm/s is not
  // reached): 2·2·√(0.25/1000) ≈ 89 ms; 0.1 s of machining between.
  EXPECT_EQ(jumps, 5);
  EXPECT_NEAR(lift_max, 0.5, 1e-12);
  EXPECT_NEAR(off / 5.0, 88, 3);
}

TEST(GapServo, AJumpAlongThePathWalksBackAndReturns) {
  machine::EdmCondition c = roughing();
  c.jump_period_s = 0.05;
  c.jump_height_mm = 0.02;
  c.jump_speed_mm_s = 10;
  c.jump_mode = machine::JumpMode::Path;
  Rig r(config_with(c));
  r.run(300, [](double, double) { return std::pair{100.0, GapState::Open}; });  // 0.3 mm of path
  double back_max = 0;
  for (int i = 0; i < 200; ++i) {
    r.run(1, [](double, double) { return std::pair{45.0, GapState::Normal}; });
    back_max = std::max(back_max, r.electrode[2] - r.head[2]);
    EXPECT_EQ(r.electrode[0], 0.0);  // never off the path
  }
  EXPECT_NEAR(back_max, 0.02, 1e-9);
  EXPECT_GE(r.g.status().jumps, 1u);
}

TEST(Orbit, ShapesHaveTheirRadiusAndNoStepInVelocity) {
  for (const auto kind : {machine::OrbitKind::Circle, machine::OrbitKind::Square, machine::OrbitKind::Star}) {
    double far = 0, prev[2], step_max = 0;
    orbit_offset(kind, 0, 1, prev);
    double v_prev[2] = {0, 0};
    double dv_max = 0;
    const int n = 100000;
    for (int i = 1; i <= n; ++i) {
      double p[2];
      orbit_offset(kind, static_cast<double>(i) / n, 1, p);
      const double v[2] = {p[0] - prev[0], p[1] - prev[1]};
      step_max = std::max(step_max, std::hypot(v[0], v[1]));
      if (i > 1) dv_max = std::max(dv_max, std::hypot(v[0] - v_prev[0], v[1] - v_prev[1]));
      far = std::max({far, std::fabs(p[0]), std::fabs(p[1])});
      v_prev[0] = v[0];
      v_prev[1] = v[1];
      prev[0] = p[0];
      prev[1] = p[1];
    }
    EXPECT_NEAR(far, 1.0, 1e-6) << static_cast<int>(kind);
    EXPECT_LT(step_max, 3e-4) << static_cast<int>(kind);  // continuous
    EXPECT_LT(dv_max, 5e-7) << static_cast<int>(kind);    // no corner (one would be ~1e-4)
  }
}

TEST(Orbit, GrowsInStepsToTheFinalRadius) {
  machine::EdmCondition c = roughing();
  c.orbit = machine::OrbitKind::Circle;
  c.orbit_radius_mm = 0.05;
  c.orbit_step_mm = 0.02;
  c.orbit_period_s = 0.5;
  Rig r(config_with(c));
  auto hold = [](double, double) { return std::pair{45.0, GapState::Normal}; };
  r.run(450, hold);  // the first turn: up to one step
  EXPECT_NEAR(r.g.status().orbit_radius_mm, 0.02, 1e-12);
  r.run(500, hold);
  EXPECT_NEAR(r.g.status().orbit_radius_mm, 0.04, 1e-12);
  r.run(1000, hold);
  EXPECT_NEAR(r.g.status().orbit_radius_mm, 0.05, 1e-12);
  EXPECT_NEAR(std::hypot(r.electrode[0], r.electrode[1]), 0.05, 1e-9);
  // Generator off: the orbit comes back to the centre.
  r.g.apply_code(181, 0);
  r.run(1000, hold);
  EXPECT_EQ(r.electrode[0], 0.0);
  EXPECT_EQ(r.electrode[1], 0.0);
}

TEST(GapServo, TheFinishingCycleHoldsTheBurnsEndUntilTheOrbitIsFullAndTurnedThere) {
  // A square growing 0.02 mm a turn to 0.06 mm; M181 comes after a quarter turn. The head stands
  // at the path's end (feed 0): the path rests.
  machine::EdmCondition c = roughing();
  c.orbit = machine::OrbitKind::Square;
  c.orbit_radius_mm = 0.06;
  c.orbit_step_mm = 0.02;
  c.orbit_period_s = 0.5;
  c.orbit_finish = true;
  c.lateral_servo = true;
  Rig r(config_with(c));
  r.feed = 0;
  const double z_end = r.electrode[2];
  // The gap 5 V above the reference while the orbit is short of its radius, at it once full.
  auto side = [&r](double, double) {
    return std::pair{r.g.status().orbit_radius_mm < 0.06 ? 50.0 : 45.0, GapState::Normal};
  };
  r.run(125, side);
  EXPECT_TRUE(r.g.apply_code(181, 0));  // accepted, but held: the burn goes on
  EXPECT_TRUE(r.g.status().on);
  r.run(1, side);
  EXPECT_TRUE(r.g.status().finishing);
  EXPECT_TRUE(r.g.head_waits());
  EXPECT_EQ(r.g.feed_scale(), 0.0);
  // The radius stands at the first step (0.02 mm after a quarter turn at the growth's rate); the
  // gap 5 V above the reference, the lateral servo drives it out at the forward limit (1 mm/s,
  // above gain × 5 V = 0.1 mm/s): the full 0.06 mm 40 ms later, then one turn there at twice the
  // period's speed (the gap at the reference): 0.25 s. After the cycle's first period: 1 µm out.
  EXPECT_NEAR(r.g.status().orbit_radius_mm, 0.021, 2e-4);
  int ticks = 1, full_at = -1;
  while (r.g.status().finishing && ticks < 5000) {
    r.run(1, side);
    ++ticks;
    if (full_at < 0 && r.g.status().orbit_radius_mm >= 0.06) full_at = ticks;
    EXPECT_EQ(r.electrode[2], z_end) << "the final depth is held";
  }
  EXPECT_NEAR(full_at, 40, 2);
  EXPECT_NEAR(ticks - full_at, 250, 3);
  EXPECT_FALSE(r.g.status().on);  // the held M181 applied at the end
  EXPECT_FALSE(r.g.status().finishing);
}

TEST(GapServo, TheFinishingCycleStopsTheOrbitForAJumpAndGoesOnWhereItLeft) {
  // A square growing to 0.06 mm with a jump every 0.1 s of machining; the finishing cycle from
  // 50 ms on, the gap at the reference.
  machine::EdmCondition c = roughing();
  c.orbit = machine::OrbitKind::Square;
  c.orbit_radius_mm = 0.06;
  c.orbit_step_mm = 0.02;
  c.orbit_period_s = 0.5;
  c.orbit_finish = true;
  c.lateral_servo = true;
  c.jump_period_s = 0.1;
  c.jump_height_mm = 0.2;
  c.jump_speed_mm_s = 50;
  c.jump_mode = machine::JumpMode::Axis;
  Rig r(config_with(c));
  r.feed = 0;
  auto at_reference = [](double, double) { return std::pair{45.0, GapState::Normal}; };
  r.run(50, at_reference);
  EXPECT_TRUE(r.g.apply_code(181, 0));
  r.run(1, at_reference);
  ASSERT_TRUE(r.g.status().finishing);
  // While a jump lifts the electrode the orbit stands where the jump began (and had stopped
  // turning there in the period before); between jumps it turns on from there.
  int jumps = 0, moving_between = 0;
  bool lifted = false;
  double x = r.electrode[0], y = r.electrode[1];
  for (int i = 0; i < 3000 && r.g.status().finishing; ++i) {
    r.run(1, at_reference);
    const bool now = r.g.status().jumping;
    if (now) {
      EXPECT_EQ(r.electrode[0], x) << "tick " << i;
      EXPECT_EQ(r.electrode[1], y) << "tick " << i;
    } else if (r.electrode[0] != x || r.electrode[1] != y) {
      ++moving_between;
    }
    jumps += now && !lifted ? 1 : 0;
    lifted = now;
    x = r.electrode[0];
    y = r.electrode[1];
  }
  EXPECT_FALSE(r.g.status().finishing);  // the cycle ended: full and turned once
  EXPECT_GE(jumps, 2);
  EXPECT_GT(moving_between, 200);
}

TEST(GapServo, TheLateralServoSlowsTheOrbitAndDrawsItInOnAShort) {
  machine::EdmCondition c = roughing();
  c.orbit = machine::OrbitKind::Circle;
  c.orbit_radius_mm = 0.05;
  c.orbit_period_s = 0.5;
  c.lateral_servo = true;
  Rig r(config_with(c));
  r.feed = 0;
  r.run(1000, [](double, double) { return std::pair{45.0, GapState::Normal}; });
  const double r_full = r.g.status().orbit_radius_mm;
  EXPECT_NEAR(r_full, 0.05, 1e-9);
  // A short: the orbit stops turning (within a quarter of the axis' acceleration) and draws in.
  r.run(20, [](double, double) { return std::pair{0.5, GapState::Short}; });
  const double x0 = r.electrode[0], y0 = r.electrode[1];
  EXPECT_LT(r.g.status().orbit_radius_mm, r_full);
  r.run(1, [](double, double) { return std::pair{0.5, GapState::Short}; });
  const double angle = std::atan2(r.electrode[1], r.electrode[0]) - std::atan2(y0, x0);
  EXPECT_NEAR(angle, 0.0, 1e-12) << "no turning while shorted";
}

TEST(EdmAdaptive, MovesTheSettingsWithinTheirBoundsByTheGapsState) {
  machine::EdmCondition base = roughing();
  base.adaptive = true;
  base.jump_period_s = 0.25;
  base.jump_height_mm = 0.4;
  base.jump_period_min_s = 0.1;
  base.jump_period_max_s = 0.5;
  base.jump_height_min_mm = 0.2;
  base.jump_height_max_mm = 0.6;
  base.servo_reference_min_v = 40;
  base.servo_reference_max_v = 50;
  base.gain_min_mm_s_per_v = 0.02;
  base.gain_max_mm_s_per_v = 0.05;
  machine::EdmCondition active = base;
  EdmAdaptive a;
  a.reset();
  // An unstable gap (a fifth of the periods arcing): the jump sooner and higher, the reference up.
  bool changed = false;
  for (int i = 0; i < EdmAdaptive::kWindow; ++i)
    changed = a.sample(i % 5 == 0 ? GapState::Arc : GapState::Normal, 45.0, base, active);
  EXPECT_TRUE(changed);
  EXPECT_NEAR(a.abnormal_share(), 0.2, 1e-12);
  EXPECT_NEAR(active.jump_period_s, 0.2, 1e-12);
  EXPECT_NEAR(active.jump_height_mm, 0.48, 1e-12);
  EXPECT_NEAR(active.servo_reference_v, 46, 1e-12);
  // Many windows of it: held at the bounds.
  for (int i = 0; i < 100 * EdmAdaptive::kWindow; ++i)
    a.sample(i % 5 == 0 ? GapState::Arc : GapState::Normal, 45.0, base, active);
  EXPECT_EQ(active.jump_period_s, 0.1);
  EXPECT_EQ(active.jump_height_mm, 0.6);
  EXPECT_EQ(active.servo_reference_v, 50);
  // A clean gap whose voltage lags 10 % above the reference: the gain up to its bound, the jump
  // later and lower again, the reference down to its bound.
  for (int i = 0; i < 100 * EdmAdaptive::kWindow; ++i)
    a.sample(GapState::Normal, 1.1 * active.servo_reference_v, base, active);
  EXPECT_EQ(active.gain_mm_s_per_v, 0.05);
  EXPECT_EQ(active.jump_period_s, 0.5);
  EXPECT_EQ(active.jump_height_mm, 0.2);
  EXPECT_EQ(active.servo_reference_v, 40);
  // Without bounds (min = max, as the profile reader sets them for absent keys) nothing moves.
  const machine::EdmCondition fixed = roughing();
  machine::EdmCondition same = fixed;
  for (int i = 0; i < 10 * EdmAdaptive::kWindow; ++i)
    EXPECT_FALSE(a.sample(GapState::Arc, 20.0, fixed, same));
  EXPECT_EQ(same.gain_mm_s_per_v, fixed.gain_mm_s_per_v);
}

TEST(GapServo, UnknownConditionSwitchesTheGeneratorOff) {
  Rig r(config_with(roughing()));
  EXPECT_FALSE(r.g.apply_code(180, 7));
  EXPECT_FALSE(r.g.status().on);
  EXPECT_TRUE(r.g.apply_code(181, 0));
}

}  // namespace
}  // namespace opencnc::control
