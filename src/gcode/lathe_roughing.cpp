// SPDX-License-Identifier: GPL-3.0-or-later
// G70/G71/G72 pass generation: normalise the profile, offset it by the allowance, then cut it
// in horizontal layers (LinuxCNC 2.9's algorithm, rewritten; see docs/lathe.md for the outline).
#include "opencnc/gcode/lathe_roughing.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <span>
#include <utility>

#include "numeric.hpp"

namespace opencnc::gcode::lathe {

namespace {

// Tolerances of LinuxCNC's implementation; the pass layout depends on them.
constexpr double kTol = 1e-6;     // same height, same point, on an arc
constexpr double kTiny = 1e-3;    // elements this short vanish; arc moves this short are skipped
constexpr double kGap = 1e-2;     // offset neighbours further apart than this get a joining arc
constexpr std::uint64_t kMaxSteps = 5'000'000;   // runaway protection of the layer loop

const Point kJ{0, 1};

// --- pieces: one element of the working profile ---------------------------------------------

// A line or an arc of the working profile. Fillets are arcs and chamfers lines whose ends are
// not known until their neighbours are (`corner` is the pending size; 0 once resolved).
struct Piece {
  bool round = false;
  bool fillet = false;
  bool chamfer = false;
  bool ccw = false;
  Point a, b, c;        // start, end, centre
  double corner = 0;
};

// Where a piece crosses the horizontal line X = x: at most two Z values, in LinuxCNC's order.
struct Crossings {
  double z[2] = {0, 0};
  int n = 0;
  void push(double v) noexcept { z[n++] = v; }
  bool empty() const noexcept { return n == 0; }
  double front() const noexcept { return z[0]; }
  double back() const noexcept { return z[n - 1]; }
};

double cross(Point u, Point v) noexcept { return std::imag(std::conj(u) * v); }

// Length of a line; for an arc the smaller of chord and radius. Decides which pieces vanish.
double extent(const Piece& p) noexcept {
  return p.round ? std::min(std::abs(p.a - p.b), std::abs(p.a - p.c)) : std::abs(p.a - p.b);
}

// Moves a piece sideways: lines to their left by `d` (right for negative d), arcs outwards by
// `d` when they turn counterclockwise.
void offset(Piece& p, double d) {
  if (p.round) {
    const double r = std::abs(p.a - p.c);
    const double k = (r + (p.ccw ? d : -d)) / r;
    p.a = k * (p.a - p.c) + p.c;
    p.b = k * (p.b - p.c) + p.c;
  } else {
    const Point shift = kJ * d * (p.a - p.b) / std::abs(p.a - p.b);
    p.a += shift;
    p.b += shift;
  }
}

// True when the piece can be cut by layers that run towards -Z: it never goes towards +Z,
// and an arc stays on one side of its centre.
bool monotonic(const Piece& p) noexcept {
  if (!p.round) return std::real(p.b - p.a) <= kTiny;
  if (p.fillet && p.corner != 0) return true;   // not placed yet
  const double entry = std::imag(p.a - p.c), exit = std::imag(p.b - p.c), dz = std::real(p.b - p.a);
  if (p.ccw) return entry >= -kTiny && exit >= -kTiny && dz <= -kTiny;
  return entry <= kTiny && exit <= kTiny && dz <= -kTiny;
}

bool on_arc(const Piece& p, Point q) noexcept {
  const double s = cross(p.a - p.c, q - p.c), e = cross(p.b - p.c, q - p.c);
  return p.ccw ? s >= -kTol && e <= kTol : s <= kTol && e >= -kTol;
}

Crossings crossings(const Piece& p, double x) {
  Crossings out;
  if (!p.round) {
    if (std::min(p.a.imag(), p.b.imag()) > x + kTol || std::max(p.a.imag(), p.b.imag()) < x - kTol) return out;
    if (std::abs(std::imag(p.a - p.b)) < kTol) {
      out.push(p.a.real());
      out.push(p.b.real());
    } else {
      out.push((x - p.a.imag()) / (p.b.imag() - p.a.imag()) * (p.b.real() - p.a.real()) + p.a.real());
    }
    return out;
  }
  const double r = std::abs(p.a - p.c);
  double s = -(x - r - p.c.imag()) * (x + r - p.c.imag());
  if (s < -kTol) return out;
  s = std::sqrt(std::max(s, 0.0));
  if (const Point q(p.c.real() + s, x); on_arc(p, q)) out.push(q.real());
  if (const Point q(p.c.real() - s, x); on_arc(p, q)) out.push(q.real());
  return out;
}

// --- joining neighbours ---------------------------------------------------------------------

// Makes `p` end and `n` start where their carriers meet (LinuxCNC's choice of root included).
void join_lines(Piece& p, Piece& n) {
  const Point rot = std::conj(n.a - n.b) / std::abs(n.a - n.b);
  const Point ps = (p.a - n.b) * rot, pe = (p.b - n.b) * rot;
  if (std::imag(ps - pe) == 0)
    throw RoughingError(RoughingError::Kind::ParallelLines,
                        "two consecutive elements of the profile are parallel after the allowance is applied "
                        "(join collinear lines into one)");
  const double f = std::imag(ps) / std::imag(ps - pe);
  n.a = p.b = (ps + f * (pe - ps)) / rot + n.b;
}

// A line meeting a circle: the meeting point closest to `near` on the line through `base`
// with direction `dir` (unit, pointing from base backwards along the line).
Point line_circle(Point base, Point dir_rot, Point center, Point radius_point, Point near) {
  const Point pe = (radius_point - base) * dir_rot, pc = (center - base) * dir_rot;
  double b = std::norm(pc - pe) - std::imag(pc) * std::imag(pc);
  b = b < 0 ? 0 : std::sqrt(b);
  const Point s1 = (std::real(pc) + b) / dir_rot + base;
  const Point s2 = (std::real(pc) - b) / dir_rot + base;
  return std::abs(near - s1) < std::abs(near - s2) ? s1 : s2;
}

void join(Piece& p, Piece& n) {
  if (!p.round && !n.round) return join_lines(p, n);
  if (!n.round) {   // arc, then line
    if (std::abs(n.a - p.b) < kTol) return;
    const Point rot = std::conj(n.a - n.b) / std::abs(n.a - n.b);
    n.a = p.b = line_circle(n.b, rot, p.c, p.b, n.a);
    return;
  }
  if (!p.round) {   // line, then arc
    if (std::abs(n.a - p.b) < kTol) return;
    const Point rot = std::conj(p.a - p.b) / std::abs(p.a - p.b);
    n.a = p.b = line_circle(p.b, rot, n.c, n.b, n.a);
    return;
  }
  // Two arcs: the triangle of both centres and the meeting point (cosine rule).
  const double a = std::abs(n.a - n.c), b = std::abs(p.a - p.c), c = std::abs(n.c - p.c);
  const double cos_b = (c * c + a * a - b * b) / 2.0 / a / c;
  const double cos2 = std::min(cos_b * cos_b, 1.0);
  const Point rot(cos_b, std::sqrt(1 - cos2));
  p.b = n.a = rot * (p.c - n.c) / c * a + n.c;
}

// Places a fillet or chamfer between `prev` and `next`: offset both by the corner size, meet,
// and drop the meeting point back onto each (the tangent points of a fillet of that size).
void resolve_corner(Piece& k, Piece& prev, Piece& next) {
  Piece p = prev, n = next;
  offset(p, k.corner);
  offset(n, k.corner);
  if (std::real(p.b - n.a) > kGap) {
    k.corner = -k.corner;
    p = prev;
    n = next;
    offset(p, k.corner);
    offset(n, k.corner);
  }
  if (std::real(p.b - n.a) > kGap) {
    char where[80];
    std::snprintf(where, sizeof where, "X%.4f Z%.4f", prev.b.imag(), prev.b.real());
    throw RoughingError(RoughingError::Kind::CornerFinish,
                        std::string("the fillet or chamfer at ") + where + " does not fit between its neighbours");
  }
  join(p, n);
  const Point center = (p.b + n.a) / 2.0;
  offset(p, -k.corner);
  offset(n, -k.corner);
  k.a = prev.b = p.b;
  k.b = next.a = n.a;
  if (k.fillet) {
    k.c = center;
    k.ccw = std::imag(k.a - k.c) > 0 || std::imag(k.b - k.c) > 0;
    k.corner = 0;
  }
}

// --- the working profile and its frame ---------------------------------------------------------

// The profile mirrored and rotated so that the cycle always cuts towards -Z with X rising
// along the profile; `frame` records how (bit 4: rotated, 2: X mirrored, 1: Z mirrored), so
// that moves can be mapped back.
struct Work {
  std::vector<Piece> pieces;
  int frame = 0;

  void rotate() {
    for (Piece& p : pieces) {   // written -p·j, not p·(-j): the signed zeros differ
      p.a = -p.a * kJ;
      p.b = -p.b * kJ;
      p.c = -p.c * kJ;
    }
    frame ^= 4;
  }
  void mirror_x() {
    for (Piece& p : pieces) {
      p.a = std::conj(p.a), p.b = std::conj(p.b), p.c = std::conj(p.c);
      p.ccw = !p.ccw;
    }
    frame ^= 2;
  }
  void mirror_z() {
    for (Piece& p : pieces) {
      p.a = -std::conj(p.a), p.b = -std::conj(p.b), p.c = -std::conj(p.c);
      p.ccw = !p.ccw;
    }
    frame ^= 1;
  }
  // Mirror so that the first element's end lies below (in X) and right of (in Z) the last one's.
  void normalise() {
    const Point d = pieces.front().b - pieces.back().b;
    if (d.imag() > 0) mirror_x();
    if (d.real() < 0) mirror_z();
  }
  // Fanuc: the approach (start point to the contour's first point) goes into the stock, so it
  // must fall in X; an approach along Z alone leaves the choice to the end points.
  void orient_from_approach() {
    const Piece& a = pieces.front();
    const double across = a.b.imag() - a.a.imag();
    if (across > 0 || (across == 0 && a.b.imag() > pieces.back().b.imag())) mirror_x();
  }
  // Fanuc: lines at the contour's end that lie at or above the start height run where the
  // start point says there is no stock (a retract to the start, a move along the bar's
  // surface); the cycle has nothing to cut there.
  void drop_stockless_tail() {
    const double top = pieces.front().a.imag();
    while (pieces.size() > 2) {
      const Piece& p = pieces.back();
      if (p.round || p.chamfer || std::min(p.a.imag(), p.b.imag()) < top - kTol) break;
      pieces.pop_back();
    }
  }
  // A vector of the program's frame in the working frame (the same turn and mirrors).
  Point to_frame(Point v) const {
    if ((frame & 4) != 0) v = -v * kJ;
    if ((frame & 2) != 0) v = std::conj(v);
    if ((frame & 1) != 0) v = -std::conj(v);
    return v;
  }
  // Fanuc's U/W: the contour moves, the start point stays; the approach follows the contour.
  void shift_contour(Point d) {
    for (std::size_t i = 1; i < pieces.size(); ++i) pieces[i].a += d, pieces[i].b += d, pieces[i].c += d;
    pieces.front().b = pieces[1].a;
  }
  void resolve_corners() {
    for (std::size_t i = 1; i + 1 < pieces.size(); ++i) {
      if (pieces[i].fillet || pieces[i].chamfer) resolve_corner(pieces[i], pieces[i - 1], pieces[i + 1]);
    }
    std::erase_if(pieces, [](const Piece& p) { return extent(p) < kTiny; });
  }
  // The first element may dive on the wrong side; LinuxCNC straightens it (moving the start
  // point), then requires every element to be monotonic. Fanuc's start point is where the
  // tool is: the approach stays as programmed and only the contour must be monotonic.
  void require_monotonic(bool keep_approach = false) {
    Piece& f = pieces.front();
    if (!keep_approach && std::real(f.b - f.a) > 0) f.a.real(f.b.real());
    for (const Piece& p : std::span(pieces).subspan(keep_approach ? 1 : 0)) {
      if (!monotonic(p))
        throw RoughingError(RoughingError::Kind::NotMonotonic,
                            "the profile is not monotonic: it turns back in the cutting direction (use a type II "
                            "cycle order or split the profile)");
    }
  }
  void translate(Point d) {
    for (Piece& p : pieces) p.a += d, p.b += d, p.c += d;
  }
  void offset_profile(double distance);
  void join_offset_neighbours(double step, bool outward);
  void tidy_after_offset();
};

// Offsets the contour (all pieces but the approach) by `distance` to the side away from the
// material, in steps no larger than half the shortest piece so that vanishing pieces are
// noticed, re-joining neighbours after each step.
void Work::offset_profile(double distance) {
  const Point v1 = pieces.front().b - pieces.front().a;
  const Point v2 = pieces.back().a - pieces.front().a;
  if (std::imag(v1 / v2) < 0) distance = -distance;
  Piece approach = pieces.front();
  pieces.erase(pieces.begin());
  double done = 0;
  for (int guard = 0; done != distance; ++guard) {
    if (pieces.empty() || guard > 100000)
      throw RoughingError(RoughingError::Kind::LostPath, "the profile vanishes under the finishing allowance");
    double step = 1e9;
    for (const Piece& p : pieces) step = std::min(step, extent(p) / 2);
    step = std::min(step, std::abs(distance - done));
    if (distance < 0) step = -step;
    for (std::size_t i = 0; i < pieces.size();) {
      offset(pieces[i], step);
      if (extent(pieces[i]) < kTiny) pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(i));
      else ++i;
    }
    join_offset_neighbours(step, distance > 0);
    tidy_after_offset();
    done += step;
  }
  for (std::size_t i = 0; i + 1 < pieces.size(); ++i) {
    const Point mid = (pieces[i].b + pieces[i + 1].a) / 2.0;
    pieces[i].b = pieces[i + 1].a = mid;
  }
  if (pieces.empty()) throw RoughingError(RoughingError::Kind::LostPath, "the profile vanishes under the finishing allowance");
  approach.b = pieces.front().a;
  pieces.insert(pieces.begin(), approach);
}

// Neighbours that moved apart along Z (an outside corner) get an arc about the old corner.
void Work::join_offset_neighbours(double step, bool outward) {
  for (std::size_t i = 0; i + 1 < pieces.size(); ++i) {
    if (std::real(pieces[i].b - pieces[i + 1].a) <= kGap) continue;
    Piece s = pieces[i], e = pieces[i + 1];
    offset(s, -step);
    offset(e, -step);
    Piece arc;
    arc.round = true;
    arc.ccw = outward;
    arc.a = pieces[i].b;
    arc.c = (s.b + e.a) / 2.0;
    arc.b = pieces[i + 1].a;
    pieces.insert(pieces.begin() + static_cast<std::ptrdiff_t>(i + 1), arc);
    ++i;
  }
}

// Drops pieces the offset turned round or shrank away, and meets the rest (LinuxCNC restarts
// from the front after each removal, without re-joining the first piece).
void Work::tidy_after_offset() {
  std::size_t i = 0;
  while (i + 1 < pieces.size()) {
    if (!monotonic(pieces[i])) {
      // LinuxCNC drops the shorter of this piece and the one before; for the first piece it
      // reads before the start of its list (undefined; rs274 crashes), so that is an error here.
      if (i == 0)
        throw RoughingError(RoughingError::Kind::LostPath,
                            "the finishing allowance turns the start of the profile round (make D smaller)");
      if (extent(pieces[i]) < extent(pieces[i - 1])) pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(i));
      else pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(i - 1));
      i = 0;
      if (pieces.size() < 2) break;
    }
    if (extent(pieces[i]) < kTiny) {
      pieces.erase(pieces.begin() + static_cast<std::ptrdiff_t>(i));
      i = 0;
    } else {
      join(pieces[i], pieces[i + 1]);
    }
    ++i;
  }
}

// --- output in the program's frame ---------------------------------------------------------------

// Maps moves of the working frame back to the program's frame.
class FramedSink {
 public:
  FramedSink(PathSink& out, int frame) : out_(out), frame_(frame) {}
  void rapid(Point p) { out_.rapid(map(p)); }
  void feed(Point p) { out_.feed(map(p)); }
  void arc(Point end, Point center, bool ccw) { out_.arc(map(end), map(center), mirrored() ? !ccw : ccw); }

 private:
  // Inverse of: rotate (p -> -jp) first, then mirror X (conj), then mirror Z (-conj); one
  // expression per frame so that signed zeros come out as LinuxCNC prints them.
  Point map(Point p) const {
    switch (frame_) {
      case 1: return -std::conj(p);
      case 2: return std::conj(p);
      case 3: return -p;
      case 4: return kJ * p;
      case 5: return std::conj(kJ * p);
      case 6: return -std::conj(kJ * p);
      case 7: return -kJ * p;
      default: return p;
    }
  }
  bool mirrored() const { return ((frame_ & 1) != 0) != ((frame_ & 2) != 0); }

  PathSink& out_;
  int frame_;
};

// --- moves along single pieces -----------------------------------------------------------------

// Moves along a falling piece from `at` down to height x (or to its end when that is higher).
// Returns false when the piece does not fall (the layer loop then climbs).
bool dive(const Piece& p, Point& at, double x, FramedSink& out, bool fast) {
  if (!p.round) {
    if (p.a.imag() <= p.b.imag() + kTol) return false;
    Point to = p.b;
    if (x >= p.b.imag()) {
      const Crossings c = crossings(p, x);
      if (c.empty()) throw RoughingError(RoughingError::Kind::LostPath, "a roughing pass lost the profile (dive)");
      to = Point(c.front(), x);
    }
    fast ? out.rapid(to) : out.feed(to);
    at = to;
    return true;
  }
  if (std::abs(at - p.b) < kTol || std::real(at - p.b) <= kTol) {
    at = p.b;
    return true;
  }
  Crossings c = crossings(p, x);
  if (c.empty()) c = crossings(p, x - kTol);
  if (p.ccw) {
    if (at.real() - kTol > p.c.real()) return false;
    const Point to = (c.empty() || c.back() > p.c.real()) ? p.b : Point(c.back(), x);
    out.arc(to, p.c, true);
    at = to;
    return true;
  }
  if (at.real() <= p.c.real()) return false;
  if (c.empty()) {
    out.arc(p.b, p.c, false);
    at = p.b;
  } else if (c.front() >= p.c.real()) {
    out.arc(Point(c.front(), x), p.c, false);
    at = Point(c.front(), x);
  }
  return true;
}

// The top of a counterclockwise arc that ends past it, else its end.
Point climb_end(const Piece& p) {
  if (p.b.real() < p.c.real()) return Point(p.c.real(), p.c.imag() + std::abs(p.a - p.c));
  return p.b;
}

// Follows a rising piece to its end. Returns true when a pocket starts here (the piece falls,
// or a counterclockwise arc passes its top).
bool climb(const Piece& p, Point& at, FramedSink& out) {
  if (!p.round) {
    if (p.b.imag() + kTol < p.a.imag()) return true;
    if (std::abs(at - p.a) > kTol) throw RoughingError(RoughingError::Kind::LostPath, "a roughing pass lost the profile (climb)");
    out.feed(p.b);
    at = p.b;
    return false;
  }
  if (!p.ccw) {
    if (at.real() > p.c.real()) return true;
    if (std::abs(at - p.b) > kTiny) out.arc(p.b, p.c, false);
    at = p.b;
    return false;
  }
  if (at.real() < p.c.real()) return true;
  const Point to = climb_end(p);
  if (std::abs(at - to) > kTiny) out.arc(to, p.c, true);
  at = to;
  return true;
}

// G7x.1: after the first pass, follow the rising parts of the contour from the current height.
void climb_only(const Piece& p, Point& at, FramedSink& out) {
  if (!p.round && p.b.imag() < p.a.imag()) return;
  const Crossings c = crossings(p, at.imag());
  if (c.empty()) return;
  if (!p.round) {
    at.real(c.front());
    out.feed(at);
    out.feed(p.b);
    at = p.b;
    return;
  }
  if (!p.ccw) {
    if (c.back() > p.c.real()) return;
    at.real(c.back());
    out.feed(at);
    if (std::abs(at - p.b) > kTiny) out.arc(p.b, p.c, false);
    at = p.b;
    return;
  }
  if (c.front() < p.c.real()) return;
  at.real(c.front());
  out.feed(at);
  const Point to = climb_end(p);
  if (std::abs(at - to) > kTiny) out.arc(to, p.c, true);
  at = to;
}

// --- the layers --------------------------------------------------------------------------------

// Cuts the area between the profile and the start height in layers `delta` apart: each layer
// dives along the profile, feeds along Z to where the layer meets the profile again, lifts
// off by the escape vector and returns at rapid. Where the profile rises again, the tool
// follows it and starts a new pocket at the next falling piece.
class Layers {
 public:
  Layers(const std::vector<Piece>& pieces, FramedSink& out, double delta, Point escape)
      : p_(pieces), out_(out), delta_(delta), escape_(escape) {}

  // `below_start`: the first layer one depth below the start point (Fanuc's first cut)
  // rather than at its height (LinuxCNC's, which cuts nothing when the start clears the stock).
  void run(Pockets mode, Point start, bool below_start) {
    below_start_ = below_start;
    starts_.push_back(start);
    std::size_t i = 0;
    Point at = start;
    bool pockets_only = false;
    if (mode == Pockets::OnlyPockets) {
      for (; i < p_.size(); ++i) {
        if (!dive(p_[i], at, -1e9, out_, i == 0)) break;
      }
      pockets_only = true;
    }
    while (pocket(mode == Pockets::None, pockets_only, at, i)) {
    }
  }

 private:
  // One pocket from piece i; returns true when the next pocket starts (at, i updated).
  bool pocket(bool follow_only, bool pockets_only, Point& at, std::size_t& i) {
    double x = starts_.back().imag();
    if (std::exchange(below_start_, false)) x -= delta_;
    // The loop is deterministic: coming back to the same place, height and piece means it
    // would repeat for ever (LinuxCNC hangs there).
    Point last_at(NAN, NAN);
    double last_x = NAN;
    std::size_t last_i = p_.size();
    while (i < p_.size()) {
      count();
      if (at == last_at && x == last_x && i == last_i)
        throw RoughingError(RoughingError::Kind::NoProgress, "the roughing passes stopped advancing along the profile");
      last_at = at;
      last_x = x;
      last_i = i;
      while (x - kTol > at.imag()) {
        count();
        x -= delta_;
      }
      if (!dive(p_[i], at, x, out_, i == 0)) return climb_out(follow_only, pockets_only, at, i);
      if (std::abs(at.imag() - x) > kTol) {
        ++i;
        continue;
      }
      cut_layer(at, x, i);
    }
    return false;
  }

  // Along the rising contour to the next pocket (or to the end).
  bool climb_out(bool follow_only, bool pockets_only, Point& at, std::size_t& i) {
    if (follow_only) {
      for (; i < p_.size(); ++i) climb_only(p_[i], at, out_);
      return false;
    }
    for (; i < p_.size(); ++i) {
      if (!climb(p_[i], at, out_)) continue;
      if (pockets_only) {
        if (at.imag() > starts_.back().imag() && starts_.size() > 1) starts_.pop_back();
        if (starts_.size() == 1) starts_.push_back(at);
      }
      return true;
    }
    return false;
  }

  // Feeds along height x from `at` to the first piece the layer meets, then lifts off and returns.
  void cut_layer(Point& at, double& x, std::size_t& i) {
    for (std::size_t k = i; k < p_.size(); ++k) {
      const Crossings c = crossings(p_[k], at.imag());
      if (c.empty()) continue;
      const double z = k != i ? c.front() : c.back();
      const double distance = std::abs(z - at.real());
      if (z - kTol > at.real()) continue;   // met the diving piece only where the layer starts
      if (distance < kTol) {
        if (k == i) continue;
        if (std::abs(at - p_[k].a) < kTol) {
          i = k;   // the next piece starts here: dive along it
        } else {
          x -= delta_;   // a zero-length layer: done
        }
        return;
      }
      Point to = at;
      to.real(z);
      out_.feed(to);
      const double scale = std::min(1.0, distance / 2 / escape_.real());
      to += scale * escape_;
      out_.rapid(to);
      out_.rapid(at - std::conj(scale * escape_));
      i == 0 ? out_.rapid(at) : out_.feed(at);
      x -= delta_;
      return;
    }
  }

  void count() {
    if (++steps_ > kMaxSteps)
      throw RoughingError(RoughingError::Kind::NoProgress, "the roughing passes stopped advancing along the profile");
  }

  const std::vector<Piece>& p_;
  FramedSink& out_;
  double delta_;
  Point escape_;
  std::vector<Point> starts_;   // where the pockets being cut started (their top height)
  std::uint64_t steps_ = 0;
  bool below_start_ = false;
};

// --- from the caller's profile ---------------------------------------------------------------------

std::vector<Piece> to_pieces(const Profile& profile) {
  std::vector<Piece> out;
  out.reserve(profile.size() + 1);
  for (const ProfileElement& e : profile) {
    Piece p;
    p.a = e.start;
    p.b = e.end;
    p.c = e.center;
    p.ccw = e.ccw;
    switch (e.kind) {
      case ProfileElement::Kind::Line: break;
      case ProfileElement::Kind::Arc: p.round = true; break;
      case ProfileElement::Kind::Fillet:
        p.round = p.fillet = true;
        p.ccw = false;
        p.a = p.b = p.c = e.end;
        p.corner = e.size;
        break;
      case ProfileElement::Kind::Chamfer:
        p.chamfer = true;
        p.a = p.b = e.end;
        p.corner = e.size;
        break;
    }
    out.push_back(p);
  }
  return out;
}

}  // namespace

void rough(const Profile& profile, const RoughingParams& params, PathSink& out) {
  if (profile.size() < 2) return;
  Work w;
  w.pieces = to_pieces(profile);
  w.pieces.front().a = params.start;
  if (params.direction == Direction::Facing) w.rotate();
  const bool fanuc = params.convention == Convention::Fanuc;
  if (fanuc) {
    w.orient_from_approach();
    w.drop_stockless_tail();
    if (w.pieces.front().b.real() < w.pieces.back().b.real()) w.mirror_z();
  } else {
    w.normalise();
  }
  w.resolve_corners();
  w.require_monotonic(fanuc);
  w.offset_profile(params.allowance);
  if (fanuc) w.shift_contour(w.to_frame(params.shift));
  else w.translate(params.shift);
  FramedSink framed(out, w.frame);
  const double delta = std::max(params.depth, 2 * kTol);
  const Point escape = params.retract * Point(1, 1);
  const Point start = w.pieces.front().a;
  framed.rapid(start);
  if (w.pieces.back().b.imag() < start.imag()) {
    // Close the layers at the top: a line up from the profile's end to the start height.
    Piece up;
    up.a = w.pieces.back().b;
    up.b = Point(up.a.real(), start.imag());
    w.pieces.push_back(up);
  }
  Layers(w.pieces, framed, delta, escape).run(params.pockets, start, fanuc);
}

void finish(const Profile& profile, const FinishingParams& params, PathSink& out) {
  if (profile.size() < 2) return;
  Work w;
  w.pieces = to_pieces(profile);
  w.pieces.front().a = params.start;
  // Whether the contour needs the rotated frame is decided on the contour alone.
  Work probe;
  probe.pieces.assign(w.pieces.begin() + 1, w.pieces.end());
  probe.normalise();
  for (const Piece& p : probe.pieces) {
    if (!monotonic(p)) {
      probe.rotate();
      probe.normalise();
      break;
    }
  }
  probe.require_monotonic();
  if (probe.frame & 4) w.rotate();
  w.normalise();
  w.resolve_corners();
  w.require_monotonic();
  FramedSink framed(out, w.frame);
  const int passes = trunc_to_int(params.passes);  // (the G70 handler bounds it)
  for (int pass = passes; pass > 0; --pass) {
    const double distance =
        (pass - 1) * (params.first_allowance - params.last_allowance) / params.passes + params.last_allowance;
    Work path = w;
    path.offset_profile(distance);
    framed.rapid(path.pieces.front().a);
    framed.rapid(path.pieces.front().b);
    for (std::size_t i = 1; i < path.pieces.size(); ++i) {
      const Piece& p = path.pieces[i];
      p.round ? framed.arc(p.b, p.c, p.ccw) : framed.feed(p.b);
    }
  }
}

}  // namespace opencnc::gcode::lathe
