// SPDX-License-Identifier: GPL-3.0-or-later
// Fanuc coordinate transforms: the point and arc mathematics, the G51.1/G50.1, G51/G50 and
// G68/G69 code handlers that set TransformState, and the CoordinateTransform that applies it.
#include "opencnc/gcode/transforms.hpp"

#include <cmath>
#include <memory>

#include "fanuc/codes.hpp"
#include "gcode_error.hpp"
#include "opencnc/canon/arc_geometry.hpp"
#include "opencnc/gcode/extension.hpp"

namespace opencnc::gcode {

void sin_cos_deg(double degrees, double& s, double& c) noexcept {
  const double turns = degrees / 90.0;
  if (turns == std::floor(turns) && std::fabs(turns) < 1e9) {
    static constexpr double kSin[4] = {0.0, 1.0, 0.0, -1.0};
    const auto quarter = static_cast<long long>(turns) % 4;
    const auto q = static_cast<std::size_t>(quarter < 0 ? quarter + 4 : quarter);
    s = kSin[q];
    c = kSin[(q + 1) % 4];
    return;
  }
  const double r = degrees * (3.14159265358979323846 / 180.0);
  s = std::sin(r);
  c = std::cos(r);
}

namespace {

bool has_stage(TransformStage last, TransformStage stage) noexcept {
  return static_cast<int>(stage) <= static_cast<int>(last);
}

// The factor G51 applies to an axis (1 for axes it does not scale).
double scale_of(const TransformState& t, int axis) noexcept {
  return t.scaling && axis < 3 ? t.scale[static_cast<std::size_t>(axis)] : 1.0;
}

bool mirrored(const TransformState& t, int axis) noexcept { return ((t.mirror_axes >> axis) & 1u) != 0; }

}  // namespace

Pose transform_point(const TransformState& t, const Pose& p, TransformStage last) noexcept {
  Pose q = p;
  for (int i = 0; i < kAxisCount; ++i) {
    if (mirrored(t, i)) q[i] = 2.0 * t.mirror_at[i] - q[i];
  }
  if (t.scaling && has_stage(last, TransformStage::Scale)) {
    for (int i = 0; i < 3; ++i) q[i] = t.scale_centre[i] + t.scale[static_cast<std::size_t>(i)] * (q[i] - t.scale_centre[i]);
  }
  if (t.rotating && has_stage(last, TransformStage::Rotate)) {
    const canon::PlaneAxes axes = canon::plane_axes(t.rotation_plane);
    double s, c;
    sin_cos_deg(t.rotation_deg, s, c);
    const double d1 = q[axes.first] - t.rotation_centre1;
    const double d2 = q[axes.second] - t.rotation_centre2;
    q[axes.first] = t.rotation_centre1 + d1 * c - d2 * s;
    q[axes.second] = t.rotation_centre2 + d1 * s + d2 * c;
  }
  return q;
}

ArcTransform transform_arc(const TransformState& t, canon::ArcFeed& arc) noexcept {
  const canon::PlaneAxes axes = canon::plane_axes(arc.plane);
  const double s1 = scale_of(t, axes.first), s2 = scale_of(t, axes.second);
  if (std::fabs(std::fabs(s1) - std::fabs(s2)) > 1e-12 * std::max(std::fabs(s1), std::fabs(s2)))
    return ArcTransform::NonUniformScale;
  if (t.rotating && t.rotation_plane != arc.plane) return ArcTransform::OtherPlane;
  Pose centre = arc.end;
  centre[axes.first] = arc.first_center;
  centre[axes.second] = arc.second_center;
  const Pose end = transform_point(t, arc.end);
  const Pose c = transform_point(t, centre);
  const bool flip = (mirrored(t, axes.first) != mirrored(t, axes.second)) != ((s1 < 0.0) != (s2 < 0.0));
  arc.first_end = end[axes.first];
  arc.second_end = end[axes.second];
  arc.axis_end = end[axes.normal];
  arc.first_center = c[axes.first];
  arc.second_center = c[axes.second];
  arc.end = end;
  if (flip) arc.rotation = -arc.rotation;
  return ArcTransform::Ok;
}

namespace {

constexpr std::uint32_t bit(char letter) noexcept { return 1u << (letter - 'a'); }
constexpr char kLetters[kAxisCount] = {'x', 'y', 'z', 'a', 'b', 'c', 'u', 'v', 'w'};

// A centre coordinate given by an axis word: absolute, or in G91 relative to the current point;
// the current point when the word is absent (Fanuc's rule for G68 and G51).
double centre_word(const InterpState& s, const Block& b, int axis) {
  const char letter = kLetters[axis];
  if (!b.has(letter)) return s.position.current[axis];
  const double v = b.get(letter);
  return s.modal.distance == DistanceMode::Incremental ? s.position.current[axis] + v : v;
}

// G51.1: mirror each axis named about the coordinate given.
class MirrorOn final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupMirror, 0, true}; }
  std::optional<Rejection> check(const Block& b, int, const InterpState&) const override {
    if (!b.any_axis())
      return Rejection{ErrorCode::FanucMirrorAxesMissing, "G51.1 needs an axis word for each mirror line (G51.1 X50)"};
    return std::nullopt;
  }
  void execute(ExecContext& ctx, const Block& b, int) override {
    TransformState& t = ctx.state().fanuc.transform;
    for (int i = 0; i < kAxisCount; ++i) {
      if (!b.has(kLetters[i])) continue;
      t.mirror_axes = static_cast<std::uint16_t>(t.mirror_axes | (1u << i));
      t.mirror_at[i] = centre_word(ctx.state(), b, i);
    }
  }
};

// G50.1: cancel mirroring on the axes named (their values are ignored), or on all axes.
class MirrorOff final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupMirror, 0, true}; }
  void execute(ExecContext& ctx, const Block& b, int) override {
    TransformState& t = ctx.state().fanuc.transform;
    if (!b.any_axis()) {
      t.mirror_axes = 0;
      return;
    }
    for (int i = 0; i < kAxisCount; ++i) {
      if (b.has(kLetters[i])) t.mirror_axes = static_cast<std::uint16_t>(t.mirror_axes & ~(1u << i));
    }
  }
};

// G51 X Y Z P (one factor) or I J K (per axis; negative mirrors), about the point given.
class ScaleOn final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupScaling, bit('p') | bit('i') | bit('j') | bit('k'), true}; }
  std::optional<Rejection> check(const Block& b, int, const InterpState& s) const override {
    const bool per_axis = b.has('i') || b.has('j') || b.has('k');
    if (b.has('p') && per_axis) return Rejection{ErrorCode::FanucScaleWords, "G51 takes P (one factor) or I, J, K (per axis), not both"};
    if (!b.has('p') && !per_axis) return Rejection{ErrorCode::FanucScaleWords, "G51 needs P (scale factor) or I, J, K (per-axis factors)"};
    for (char w : {'p', 'i', 'j', 'k'}) {
      if (b.has(w) && b.get(w) == 0.0)
        return Rejection{ErrorCode::FanucScaleZero,
                         fmt::format("G51 {}0: a scale factor of zero collapses the geometry", static_cast<char>(w - 32))};
    }
    if (s.modal.cutter_comp != CutterComp::Off)
      return Rejection{ErrorCode::Unsupported, "G51 scaling while cutter compensation is on is not supported"};
    return std::nullopt;
  }
  void execute(ExecContext& ctx, const Block& b, int) override {
    InterpState& s = ctx.state();
    TransformState& t = s.fanuc.transform;
    Pose centre = s.position.current;
    for (int i = 0; i < 3; ++i) centre[i] = centre_word(s, b, i);
    // The centre is a program point: it goes through the mirroring programmed before.
    t.scale_centre = transform_point(t, centre, TransformStage::Mirror);
    if (b.has('p')) {
      t.scale = {b.get('p'), b.get('p'), b.get('p')};
    } else {
      t.scale = {b.has('i') ? b.get('i') : 1.0, b.has('j') ? b.get('j') : 1.0, b.has('k') ? b.get('k') : 1.0};
    }
    t.scaling = true;
  }
};

class ScaleOff final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupScaling, 0, false}; }
  void execute(ExecContext& ctx, const Block&, int) override {
    TransformState& t = ctx.state().fanuc.transform;
    t.scaling = false;
    t.scale = {1.0, 1.0, 1.0};
  }
};

// G68 a b R: rotate the active plane about (a, b) by R degrees counterclockwise.
class RotateOn final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupRotation, bit('r'), true}; }
  std::optional<Rejection> check(const Block& b, int, const InterpState& s) const override {
    if (!b.has('r')) return Rejection{ErrorCode::FanucRotationAngleMissing, "G68 needs R (the rotation angle in degrees)"};
    const canon::Plane p = b.g[kGroupPlane] != -1 ? plane_of(b.g[kGroupPlane]) : s.modal.plane;
    if (p != canon::Plane::XY && p != canon::Plane::XZ && p != canon::Plane::YZ)
      return Rejection{ErrorCode::FanucRotationPlane, "G68 rotates in the XY, ZX or YZ plane only (G17, G18, G19)"};
    const canon::PlaneAxes axes = canon::plane_axes(p);
    for (int i = 0; i < kAxisCount; ++i) {
      if (b.has(kLetters[i]) && i != axes.first && i != axes.second)
        return Rejection{ErrorCode::UnusedWord,
                         fmt::format("{} word with G68: the centre is given in the plane's two axes", static_cast<char>(kLetters[i] - 32))};
    }
    return std::nullopt;
  }
  void execute(ExecContext& ctx, const Block& b, int) override {
    InterpState& s = ctx.state();
    TransformState& t = s.fanuc.transform;
    const canon::PlaneAxes axes = canon::plane_axes(s.modal.plane);
    Pose centre = s.position.current;
    centre[axes.first] = centre_word(s, b, axes.first);
    centre[axes.second] = centre_word(s, b, axes.second);
    // Fanuc scales (and mirrors) the centre of a rotation programmed while G51 (G51.1) is on.
    const Pose c = transform_point(t, centre, TransformStage::Scale);
    t.rotation_plane = s.modal.plane;
    t.rotation_centre1 = c[axes.first];
    t.rotation_centre2 = c[axes.second];
    t.rotation_deg = b.get('r');
    t.rotating = true;
  }

 private:
  static canon::Plane plane_of(int code) noexcept {
    return code == 180 ? canon::Plane::XZ : code == 190 ? canon::Plane::YZ : code == 170 ? canon::Plane::XY : canon::Plane::UV;
  }
};

class RotateOff final : public CodeHandler {
 public:
  Traits traits(int) const override { return {kGroupRotation, 0, false}; }
  void execute(ExecContext& ctx, const Block&, int) override { ctx.state().fanuc.transform.rotating = false; }
};

// Applies the InterpState's TransformState to every motion on its way out.
class FanucTransform final : public CoordinateTransform {
 public:
  bool active(const InterpState& s) const override { return s.fanuc.transform.active(); }
  Pose point(const InterpState& s, const Pose& p) const override { return transform_point(s.fanuc.transform, p); }
  void arc(const InterpState& s, canon::ArcFeed& a) const override {
    const TransformState& t = s.fanuc.transform;
    switch (transform_arc(t, a)) {
      case ArcTransform::Ok: return;
      case ArcTransform::NonUniformScale: {
        const canon::PlaneAxes axes = canon::plane_axes(a.plane);
        fail(ErrorCode::FanucArcNonUniformScale,
             "G51 scales {} by {} and {} by {}: an arc in that plane would become an ellipse (use equal "
             "factors)",
             letter(static_cast<Axis>(axes.first)), scale_of(t, axes.first),
             letter(static_cast<Axis>(axes.second)), scale_of(t, axes.second));
      }
      case ArcTransform::OtherPlane:
        fail(ErrorCode::FanucRotationPlaneChange, "an arc outside the plane of the G68 rotation");
    }
  }
};

}  // namespace

void add_transform_codes(Extensions& ext) {
  ext.g[511] = std::make_shared<MirrorOn>();
  ext.g[501] = std::make_shared<MirrorOff>();
  ext.g[510] = std::make_shared<ScaleOn>();
  ext.g[500] = std::make_shared<ScaleOff>();
  ext.g[680] = std::make_shared<RotateOn>();
  ext.g[690] = std::make_shared<RotateOff>();
  ext.transform = std::make_shared<FanucTransform>();
}

}  // namespace opencnc::gcode
