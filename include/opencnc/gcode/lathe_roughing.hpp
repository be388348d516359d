// SPDX-License-Identifier: GPL-3.0-or-later
// Lathe roughing and finishing passes (G70, G71, G72) computed from a profile of lines and arcs
// in the XZ plane, reproducing LinuxCNC 2.9's pass layout; independent of any G-code dialect.
#pragma once

#include <complex>
#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace opencnc::gcode::lathe {

/// A point of the XZ plane as a complex number: real part Z (along the spindle), imaginary part
/// X (the radius, or what the program calls X). Complex arithmetic keeps rotations and mirrors
/// of the profile one-liners.
using Point = std::complex<double>;

/// One element of a profile, in program order. Lines and arcs carry their own start so that
/// a caller can build gaps (LinuxCNC does, for motion modes other than G0-G3).
struct ProfileElement {
  enum class Kind : std::uint8_t {
    Line,     ///< straight from start to end
    Arc,      ///< circular arc about `center`; `ccw` is G3 (X up, Z to the right)
    Fillet,   ///< round the corner at `end` (== start) with radius `size` (LinuxCNC's A word)
    Chamfer,  ///< cut the corner at `end` (== start) where a fillet of `size` would touch
  };
  Kind kind = Kind::Line;
  Point start, end;
  Point center;
  bool ccw = false;
  double size = 0;
};

/// The profile of a cycle. Element 0 runs from the cycle's start point (the X and Z of the
/// G7x block) to the first point of the finished contour; the rest is the contour in the order
/// the program gives it. Fillets and chamfers follow the element whose end they round.
using Profile = std::vector<ProfileElement>;

/// What G71/G72 leave unmachined: LinuxCNC's G7x, G7x.1 (no pockets: after the first pass
/// along the contour the tool follows the contour only) and G7x.2 (only the pockets that
/// G7x.1 left).
enum class Pockets : std::uint8_t { All = 0, None = 1, OnlyPockets = 2 };

/// G71 (turning: passes along Z, depth steps in X) or G72 (facing: passes along X, steps in Z).
enum class Direction : std::uint8_t { Turning, Facing };

/// Whose reading of the profile the cycle follows. The two differ where a profile leaves
/// the choice open; on ordinary profiles they cut the same.
enum class Convention : std::uint8_t {
  /// LinuxCNC's G7x: the cutting side from where the contour's first point lies against its
  /// last; `shift` applies in the working frame and moves the start point with the contour.
  LinuxCnc,
  /// Fanuc's G71/G72 P Q: the stock side from the approach (from the start point towards the
  /// contour's first point, across the passes), so that a contour may start with a face that
  /// falls towards the axis; `shift` (Fanuc's W and U/2) moves the contour, not the start
  /// point, in the program's frame; the approach stays as programmed; straight elements at
  /// the contour's end that lie at or beyond the start point's depth (where the start point
  /// says there is no stock, such as a retract back to the start) are left out; the first
  /// layer is one depth below the start point, not at its height.
  Fanuc,
};

struct RoughingParams {
  Direction direction = Direction::Turning;
  Pockets pockets = Pockets::All;
  Point start;               ///< the cycle's start point (G7x X and Z, in the program's X)
  double allowance = 0;      ///< D: finishing allowance, an offset normal to the profile (≥ 0)
  double depth = 1;          ///< I: depth of cut of each pass (> 0)
  double retract = 0.5;      ///< R: lift-off at 45° after each pass
  /// W (real) and U (imaginary): the roughing profile is moved by this. LinuxCnc: after it
  /// has been mirrored or rotated into the cycle's working frame (cutting towards -Z, X rising
  /// along the profile); for outside turning towards -Z, positive values leave stock on the
  /// outside and on faces that look towards +Z. Fanuc: in the program's frame, as Fanuc's W
  /// and U/2 (U here is a radius), the start point staying where it is.
  Point shift = 0;
  Convention convention = Convention::LinuxCnc;
};

struct FinishingParams {
  Point start;               ///< the cycle's start point; every pass starts with a rapid here
  double first_allowance = 0;   ///< D: offset of the first pass
  double last_allowance = 0;    ///< E: offset of the last pass
  double passes = 1;            ///< P: number of passes (LinuxCNC truncates it for the count)
};

/// Receives the cycle's moves in program coordinates (the same frame as the profile).
class PathSink {
 public:
  virtual ~PathSink() = default;
  virtual void rapid(Point end) = 0;
  virtual void feed(Point end) = 0;
  virtual void arc(Point end, Point center, bool ccw) = 0;
};

/// A profile the cycle cannot machine. `kind` says which problem; the text is a sentence
/// for a person.
class RoughingError : public std::runtime_error {
 public:
  enum class Kind : std::uint8_t {
    NotMonotonic,     ///< the profile turns back on itself in the cutting direction
    ParallelLines,    ///< two consecutive offset lines do not meet (collinear elements)
    CornerFinish,     ///< a fillet or chamfer does not fit between its neighbours
    LostPath,         ///< the passes lost the profile (a degenerate contour)
    NoProgress,       ///< the passes stopped advancing (runaway protection)
  };
  RoughingError(Kind kind, const std::string& message) : std::runtime_error(message), kind_(kind) {}
  Kind kind() const noexcept { return kind_; }

 private:
  Kind kind_;
};

/// G71/G72 roughing. Profiles with fewer than two elements produce no motion. Throws
/// RoughingError; moves already sent stay sent. Non-real-time; any thread (no shared state).
void rough(const Profile& profile, const RoughingParams& params, PathSink& out);

/// G70 finishing: `passes` passes along the profile, the allowance going from D to E.
/// Throws RoughingError. Non-real-time; any thread.
void finish(const Profile& profile, const FinishingParams& params, PathSink& out);

}  // namespace opencnc::gcode::lathe
