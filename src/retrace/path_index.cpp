// SPDX-License-Identifier: GPL-3.0-or-later
// The path index: feed moves stored in the order of a bounding-volume tree over them (leaves of a
// few moves in Morton order, median splits, boxes in floats rounded outward), nearest-point
// queries with a margin, and walking along the path in its own order.
#include "opencnc/retrace/path_index.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <limits>

#include "path_shape.hpp"

namespace opencnc::recovery {

using detail::ArcShape;
using detail::Box;
using detail::Shape;

namespace {

constexpr std::uint32_t kLeafSize = 4;

/// A box in floats, each bound rounded outward: half the memory of doubles, and a distance to
/// it never exceeds the distance to what it holds.
struct FloatBox {
  float lo[3], hi[3];
  static FloatBox of(const Box& b) noexcept {
    FloatBox f{};
    for (int i = 0; i < 3; ++i) {
      f.lo[i] = static_cast<float>(b.lo[i]);
      if (static_cast<double>(f.lo[i]) > b.lo[i])
        f.lo[i] = std::nextafter(f.lo[i], -std::numeric_limits<float>::infinity());
      f.hi[i] = static_cast<float>(b.hi[i]);
      if (static_cast<double>(f.hi[i]) < b.hi[i])
        f.hi[i] = std::nextafter(f.hi[i], std::numeric_limits<float>::infinity());
    }
    return f;
  }
  double distance2(const Vec3& q, Metric m) const noexcept {
    double d2 = 0;
    const int axes = m == Metric::Xyz ? 3 : 2;
    for (int i = 0; i < axes; ++i) {
      const double lo_i = lo[i], hi_i = hi[i];
      const double d = q[i] < lo_i ? lo_i - q[i] : (q[i] > hi_i ? q[i] - hi_i : 0.0);
      d2 += d * d;
    }
    return d2;
  }
};

/// A node of the tree in depth-first order: the left child follows its parent; a leaf holds
/// `count` shapes from `first` (shapes are stored in the tree's order). 32 bytes.
struct Node {
  FloatBox box;
  std::uint32_t first = 0;  ///< leaf: first shape; inner: index of the right child
  std::uint32_t count = 0;  ///< leaf: number of shapes (0: an inner node)
};

/// Spreads the low 21 bits of v to every third bit (Morton code).
std::uint64_t spread3(std::uint64_t v) noexcept {
  v &= 0x1fffff;
  v = (v | v << 32) & 0x1f00000000ffffULL;
  v = (v | v << 16) & 0x1f0000ff0000ffULL;
  v = (v | v << 8) & 0x100f00f00f00f00fULL;
  v = (v | v << 4) & 0x10c30c30c30c30c3ULL;
  v = (v | v << 2) & 0x1249249249249249ULL;
  return v;
}

/// A move found within the bound during a query (the PathPoint is made for the winners only).
struct Hit {
  std::uint32_t shape;
  double t, d2;
};

}  // namespace

struct PathIndex::Impl {
  std::vector<Shape> shapes;  ///< path order while adding; the tree's order once finished
  std::vector<ArcShape> arcs;
  std::vector<Box> boxes;               ///< per shape while building
  std::vector<std::uint32_t> by_entry;  ///< path order → index in shapes (once finished)
  std::vector<Node> nodes;
  /// Where the segment id differs from the move number (a spline split into chords, a scan
  /// that does not start at segment 0): from `move` on, segment = move − `less`.
  struct Shift {
    std::uint64_t move;
    std::int64_t less;
  };
  std::vector<Shift> shifts;
  std::shared_ptr<const canon::SourceMap> sources;
  bool finished = false;

  const ArcShape* arc_of(const Shape& s) const noexcept {
    return s.arc == detail::kNoArc ? nullptr : &arcs[s.arc];
  }

  canon::SegmentId segment_of(std::uint64_t move) const noexcept {
    const auto it = std::upper_bound(shifts.begin(), shifts.end(), move,
                                     [](std::uint64_t m, const Shift& s) { return m < s.move; });
    return it == shifts.begin()
               ? move
               : static_cast<canon::SegmentId>(static_cast<std::int64_t>(move) - (it - 1)->less);
  }

  /// Where [lo, hi) of the Morton-sorted codes splits: at the highest bit in which its first and
  /// last codes differ (each side a cell of the Z-order grid, so boxes stay compact), or in the
  /// middle where they are all equal.
  static std::uint32_t split(const std::vector<std::pair<std::uint64_t, std::uint32_t>>& keys,
                             std::uint32_t lo, std::uint32_t hi) {
    const std::uint64_t first = keys[lo].first, last = keys[hi - 1].first;
    if (first == last) return lo + (hi - lo) / 2;
    const std::uint64_t bit = std::uint64_t{1} << (63 - std::countl_zero(first ^ last));
    const auto it = std::partition_point(keys.begin() + lo, keys.begin() + hi,
                                         [bit](const auto& k) { return (k.first & bit) == 0; });
    return static_cast<std::uint32_t>(it - keys.begin());
  }

  std::uint32_t build(std::uint32_t lo, std::uint32_t hi,
                      const std::vector<std::pair<std::uint64_t, std::uint32_t>>& order) {
    const auto self = static_cast<std::uint32_t>(nodes.size());
    nodes.emplace_back();
    Box b;
    if (hi - lo <= kLeafSize) {
      for (std::uint32_t i = lo; i < hi; ++i) b.add(boxes[order[i].second]);
      nodes[self] = Node{FloatBox::of(b), lo, hi - lo};
      return self;
    }
    const std::uint32_t mid = split(order, lo, hi);
    build(lo, mid, order);
    const std::uint32_t right = build(mid, hi, order);
    // The children's float boxes hold their shapes; their union holds both.
    Node& n = nodes[self];
    n.first = right;
    n.count = 0;
    for (int i = 0; i < 3; ++i) {
      n.box.lo[i] = std::min(nodes[self + 1].box.lo[i], nodes[right].box.lo[i]);
      n.box.hi[i] = std::max(nodes[self + 1].box.hi[i], nodes[right].box.hi[i]);
    }
    return self;
  }

  PathPoint make_point(std::uint32_t shape, double t, double d2) const {
    const Shape& s = shapes[shape];
    PathPoint p;
    p.segment = segment_of(s.move);
    p.move = s.move;
    p.entry = s.entry;
    p.param = t;
    p.point = detail::point_at(s, arc_of(s), t);
    p.distance_mm = std::sqrt(d2);
    p.context = s.context;
    p.line = s.line;
    return p;
  }

  /// Takes a move into the hits if it is within the bound, and tightens the bound.
  void consider(std::uint32_t shape, const Vec3& q, const QueryOptions& o, std::vector<Hit>& hits,
                double& best2, double& bound2) const {
    const Shape& s = shapes[shape];
    const detail::Closest c = detail::closest(s, arc_of(s), q, o.metric);
    if (c.d2 > bound2) return;
    hits.push_back({shape, c.t, c.d2});
    if (c.d2 < best2) {
      best2 = c.d2;
      const double reach = std::sqrt(c.d2) + o.margin_mm;
      // Never below the best squared distance itself: (√x)² may round below x, and a move at
      // exactly the best distance (a shared corner) must stay a candidate.
      bound2 = std::max(reach * reach, c.d2);
    }
  }

  /// One candidate per stretch of connected moves (the nearest of it), nearest first.
  Nearest gather(std::vector<Hit>& hits, double bound2) const {
    Nearest out;
    if (hits.empty()) return out;
    std::erase_if(hits, [bound2](const Hit& h) { return h.d2 > bound2; });
    std::sort(hits.begin(), hits.end(),
              [this](const Hit& a, const Hit& b) { return shapes[a.shape].entry < shapes[b.shape].entry; });
    std::vector<Hit> best;
    for (std::size_t i = 0; i < hits.size(); ++i) {
      const Shape& s = shapes[hits[i].shape];
      const bool joined =
          i > 0 && s.entry == shapes[hits[i - 1].shape].entry + 1 && shapes[hits[i - 1].shape].b == s.a;
      if (!joined) {
        best.push_back(hits[i]);
      } else if (hits[i].d2 <= best.back().d2) {
        best.back() = hits[i];  // on a tie at a shared corner: the later move
      }
    }
    std::stable_sort(best.begin(), best.end(), [](const Hit& a, const Hit& b) { return a.d2 < b.d2; });
    for (const Hit& h : best) out.candidates.push_back(make_point(h.shape, h.t, h.d2));
    out.found = true;
    out.nearest = out.candidates.front();
    return out;
  }
};

PathIndex::PathIndex() : impl_(std::make_unique<Impl>()) {}
PathIndex::~PathIndex() = default;
PathIndex::PathIndex(PathIndex&&) noexcept = default;
PathIndex& PathIndex::operator=(PathIndex&&) noexcept = default;

void PathIndex::add(const canon::Program& program, std::size_t move) {
  const canon::Move& m = program.move(move);
  if (m.kind != canon::MoveKind::Feed && m.kind != canon::MoveKind::Arc) return;
  Impl& im = *impl_;
  if (!im.sources) im.sources = program.sources_ptr();
  Shape s;
  const Pose a = program.start_of(move), b = program.end(move);
  s.a = {a[0], a[1], a[2]};
  s.b = {b[0], b[1], b[2]};
  s.context = m.context;
  s.line = m.line;
  s.move = move;
  s.entry = static_cast<std::uint32_t>(im.shapes.size());
  const auto less = static_cast<std::int64_t>(move) - static_cast<std::int64_t>(program.segment_of(move));
  if ((im.shifts.empty() ? 0 : im.shifts.back().less) != less) im.shifts.push_back({move, less});
  ArcShape arc;
  if (m.kind == canon::MoveKind::Arc && detail::make_arc_shape(program, move, arc)) {
    s.arc = static_cast<std::uint32_t>(im.arcs.size());
    im.arcs.push_back(arc);
  }
  im.shapes.push_back(s);
  im.boxes.push_back(detail::bounds(s, im.arc_of(s)));
}

void PathIndex::finish() {
  Impl& im = *impl_;
  const auto n = static_cast<std::uint32_t>(im.shapes.size());
  im.nodes.clear();
  im.finished = true;
  if (n == 0) return;
  Box all;
  for (const Box& b : im.boxes) all.add(b);
  // Morton order of the boxes' centres: neighbours in space become neighbours in the order, so
  // leaves and the nodes above them stay small, and a query reads memory that lies together.
  std::vector<std::pair<std::uint64_t, std::uint32_t>> keys(n);
  for (std::uint32_t i = 0; i < n; ++i) {
    std::uint64_t code = 0;
    for (int k = 0; k < 3; ++k) {
      const double span = all.hi[k] - all.lo[k];
      const double c = 0.5 * (im.boxes[i].lo[k] + im.boxes[i].hi[k]);
      const double f = span > 0 ? (c - all.lo[k]) / span : 0.0;
      code |= spread3(static_cast<std::uint64_t>(std::clamp(f, 0.0, 1.0) * 2097151.0)) << k;
    }
    keys[i] = {code, i};
  }
  std::sort(keys.begin(), keys.end());
  im.nodes.reserve(2 * (n / 2 + 1));
  im.build(0, n, keys);
  // The shapes in the tree's order (exactly as many as there are), and the way back.
  std::vector<Shape> sorted(n);
  im.by_entry.assign(n, 0);
  for (std::uint32_t i = 0; i < n; ++i) {
    sorted[i] = im.shapes[keys[i].second];
    im.by_entry[sorted[i].entry] = i;
  }
  im.shapes = std::move(sorted);
  std::vector<Box>().swap(im.boxes);  // (= {} would keep the capacity)
  im.arcs.shrink_to_fit();
  im.nodes.shrink_to_fit();
}

Nearest PathIndex::nearest(const Vec3& b, const QueryOptions& options) const {
  const Impl& im = *impl_;
  if (!im.finished || im.nodes.empty()) return {};
  std::vector<Hit> hits;
  double best2 = std::numeric_limits<double>::infinity(), bound2 = best2;
  // Depth first, the nearer child first; a node farther than the best distance plus the margin
  // cannot hold a candidate. A path from the root splits at most at every one of the 63 code bits
  // and then halves equal codes (at most 32 times): the stack never holds 256.
  std::uint32_t stack[256];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const std::uint32_t at = stack[--top];
    const Node& node = im.nodes[at];
    if (node.box.distance2(b, options.metric) > bound2) continue;
    if (node.count == 0) {
      const std::uint32_t left = at + 1, right = node.first;
      const double dl = im.nodes[left].box.distance2(b, options.metric);
      const double dr = im.nodes[right].box.distance2(b, options.metric);
      stack[top++] = dl <= dr ? right : left;
      stack[top++] = dl <= dr ? left : right;
      continue;
    }
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i)
      im.consider(i, b, options, hits, best2, bound2);
  }
  return im.gather(hits, bound2);
}

Nearest PathIndex::nearest_linear(const Vec3& b, const QueryOptions& options) const {
  const Impl& im = *impl_;
  std::vector<Hit> hits;
  double best2 = std::numeric_limits<double>::infinity(), bound2 = best2;
  for (std::uint32_t e = 0; e < im.shapes.size(); ++e) {
    im.consider(im.finished ? im.by_entry[e] : e, b, options, hits, best2, bound2);
  }
  return im.gather(hits, bound2);
}

std::optional<PathPoint> PathIndex::at_move(std::uint64_t move, double offset_mm) const {
  const Impl& im = *impl_;
  const auto it = std::partition_point(im.by_entry.begin(), im.by_entry.end(),
                                       [&](std::uint32_t shape) { return im.shapes[shape].move < move; });
  if (it == im.by_entry.end()) return std::nullopt;
  const Shape& s = im.shapes[*it];
  const double len = detail::length(s, im.arc_of(s));
  const double t = s.move == move && len > 0 ? std::clamp(offset_mm / len, 0.0, 1.0) : 0.0;
  return im.make_point(*it, t, 0.0);
}

PathPoint PathIndex::point_on(std::uint32_t entry, double param) const {
  return impl_->make_point(impl_->by_entry.at(entry), std::clamp(param, 0.0, 1.0), 0.0);
}

PathPoint PathIndex::advance(const PathPoint& from, double distance_mm) const {
  const Impl& im = *impl_;
  if (im.by_entry.empty()) return from;
  const auto last = static_cast<std::uint32_t>(im.by_entry.size() - 1);
  std::uint32_t e = std::min(from.entry, last);
  const auto len_of = [&](std::uint32_t entry) {
    const Shape& s = im.shapes[im.by_entry[entry]];
    return detail::length(s, im.arc_of(s));
  };
  double len = len_of(e);
  double s = std::clamp(from.param, 0.0, 1.0) * len + distance_mm;
  while (s > len && e < last) {
    s -= len;
    len = len_of(++e);
  }
  while (s < 0 && e > 0) {
    len = len_of(--e);
    s += len;
  }
  const double t = len > 0 ? std::clamp(s / len, 0.0, 1.0) : 0.0;
  return im.make_point(im.by_entry[e], t, 0.0);
}

std::size_t PathIndex::size() const noexcept {
  return impl_->shapes.size();
}

std::size_t PathIndex::memory_bytes() const noexcept {
  const Impl& im = *impl_;
  return im.shapes.capacity() * sizeof(Shape) + im.arcs.capacity() * sizeof(ArcShape) +
         im.boxes.capacity() * sizeof(Box) + im.by_entry.capacity() * sizeof(std::uint32_t) +
         im.nodes.capacity() * sizeof(Node) + im.shifts.capacity() * sizeof(Impl::Shift);
}

const std::shared_ptr<const canon::SourceMap>& PathIndex::sources() const noexcept {
  return impl_->sources;
}

}  // namespace opencnc::recovery
