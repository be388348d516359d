// SPDX-License-Identifier: GPL-3.0-or-later
// SVG rendering of chart panels: data → pixel transform, axes with nice ticks, legend.
#include "opencnc/viz/svg_chart.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

#include <fmt/format.h>

namespace opencnc::viz {

namespace {

constexpr int kMarginLeft = 70, kMarginRight = 16, kMarginTop = 34, kMarginBottom = 46;

struct Range {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  void add(double v) {
    if (!std::isfinite(v)) return;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  bool valid() const { return lo <= hi; }
  void pad() {
    if (!valid()) { lo = 0; hi = 1; }
    if (hi - lo < 1e-12) {
      const double m = std::max(std::fabs(lo) * 0.05, 0.5);
      lo -= m;
      hi += m;
    }
  }
};

std::string escape(const std::string& s) {
  std::string out;
  for (char c : s) {
    switch (c) {
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '&': out += "&amp;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

std::string tick_label(double v, double step) {
  if (std::fabs(v) < step * 1e-9) v = 0;
  const int decimals = step >= 1 ? 0 : static_cast<int>(std::ceil(-std::log10(step)));
  if (std::fabs(v) >= 1e6 || (std::fabs(v) > 0 && std::fabs(v) < 1e-4)) return fmt::format("{:.3g}", v);
  return fmt::format("{:.{}f}", v, std::min(decimals, 6));
}

class PanelRenderer {
 public:
  PanelRenderer(const Panel& p, int x0, int y0, int w, int h) : p_(p), x0_(x0), y0_(y0), w_(w), h_(h) {}

  void render(std::string& out) {
    compute_ranges();
    out += fmt::format("<g><rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"#fff\" stroke=\"#ccc\"/>\n",
                       x0_, y0_, w_, h_);
    out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"14\" font-weight=\"bold\">{}</text>\n", x0_ + 8,
                       y0_ + 20, escape(p_.title));
    axes(out);
    for (const Series& s : p_.series) series(out, s);
    legend(out);
    out += "</g>\n";
  }

 private:
  double ty(double v) const { return p_.log_y ? std::log10(v) : v; }

  void compute_ranges() {
    for (const Series& s : p_.series) {
      for (double v : s.x) xr_.add(v);
      for (double v : s.y) {
        if (p_.log_y && v <= 0) continue;
        yr_.add(ty(v));
      }
      if (s.bars && !p_.log_y) yr_.add(0);
    }
    xr_.pad();
    yr_.pad();
    // On a log axis a count of 1 sits at log 0: lower the floor so single counts stay visible.
    if (p_.log_y) yr_.lo -= 0.3;
    pw_ = w_ - kMarginLeft - kMarginRight;
    ph_ = h_ - kMarginTop - kMarginBottom;
    if (p_.equal_scale) {
      // Grow the range of the tighter axis so one mm is the same number of pixels both ways.
      const double sx = (xr_.hi - xr_.lo) / pw_, sy = (yr_.hi - yr_.lo) / ph_;
      if (sx > sy) {
        const double c = (yr_.lo + yr_.hi) / 2, half = sx * ph_ / 2;
        yr_.lo = c - half;
        yr_.hi = c + half;
      } else {
        const double c = (xr_.lo + xr_.hi) / 2, half = sy * pw_ / 2;
        xr_.lo = c - half;
        xr_.hi = c + half;
      }
    }
  }

  double px(double x) const { return x0_ + kMarginLeft + (x - xr_.lo) / (xr_.hi - xr_.lo) * pw_; }
  double py(double y) const { return y0_ + kMarginTop + ph_ - (y - yr_.lo) / (yr_.hi - yr_.lo) * ph_; }

  void axes(std::string& out) const {
    const auto xt = nice_ticks(xr_.lo, xr_.hi);
    auto yt = nice_ticks(yr_.lo, yr_.hi);
    if (p_.log_y) {  // decades only: 1, 10, 100 ... read at a glance
      yt.clear();
      for (double e = std::ceil(yr_.lo); e <= yr_.hi; e += 1) yt.push_back(e);
    }
    const double xstep = xt.size() > 1 ? xt[1] - xt[0] : 1, ystep = yt.size() > 1 ? yt[1] - yt[0] : 1;
    for (double t : xt) {
      out += fmt::format("<line x1=\"{0:.1f}\" y1=\"{1}\" x2=\"{0:.1f}\" y2=\"{2}\" stroke=\"#eee\"/>"
                         "<text x=\"{0:.1f}\" y=\"{3}\" font-size=\"11\" text-anchor=\"middle\">{4}</text>\n",
                         px(t), y0_ + kMarginTop, y0_ + kMarginTop + ph_, y0_ + kMarginTop + ph_ + 15,
                         tick_label(t, xstep));
    }
    for (double t : yt) {
      const std::string label = p_.log_y ? tick_label(std::pow(10.0, t), 1) : tick_label(t, ystep);
      out += fmt::format("<line x1=\"{0}\" y1=\"{1:.1f}\" x2=\"{2}\" y2=\"{1:.1f}\" stroke=\"#eee\"/>"
                         "<text x=\"{3}\" y=\"{4:.1f}\" font-size=\"11\" text-anchor=\"end\">{5}</text>\n",
                         x0_ + kMarginLeft, py(t), x0_ + kMarginLeft + pw_, x0_ + kMarginLeft - 5, py(t) + 4,
                         label);
    }
    out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"{}\" height=\"{}\" fill=\"none\" stroke=\"#444\"/>\n",
                       x0_ + kMarginLeft, y0_ + kMarginTop, pw_, ph_);
    out += fmt::format("<text x=\"{}\" y=\"{}\" font-size=\"12\" text-anchor=\"middle\">{}</text>\n",
                       x0_ + kMarginLeft + pw_ / 2, y0_ + h_ - 8, escape(p_.x_label));
    out += fmt::format(
        "<text transform=\"translate({},{}) rotate(-90)\" font-size=\"12\" text-anchor=\"middle\">{}</text>\n",
        x0_ + 14, y0_ + kMarginTop + ph_ / 2, escape(p_.y_label));
  }

  void series(std::string& out, const Series& s) const {
    const std::size_t n = std::min(s.x.size(), s.y.size());
    if (s.bars) {
      const double base = p_.log_y ? yr_.lo : std::max(0.0, yr_.lo);
      const double bw = n > 1 ? std::max(1.0, (px(s.x[1]) - px(s.x[0])) * 0.9) : 4.0;
      for (std::size_t i = 0; i < n; ++i) {
        if (p_.log_y && s.y[i] <= 0) continue;
        const double top = py(ty(s.y[i])), bottom = py(base);
        out += fmt::format("<rect x=\"{:.1f}\" y=\"{:.1f}\" width=\"{:.1f}\" height=\"{:.1f}\" fill=\"{}\"/>\n",
                           px(s.x[i]) - bw / 2, top, bw, std::max(0.0, bottom - top), s.color);
      }
      return;
    }
    // Thin out points closer than a quarter pixel: big traces stay small files, shapes stay exact.
    out += fmt::format("<polyline fill=\"none\" stroke=\"{}\" stroke-width=\"{}\" points=\"", s.color, s.width);
    double lx = -1e9, ly = -1e9;
    for (std::size_t i = 0; i < n; ++i) {
      if (p_.log_y && s.y[i] <= 0) continue;
      const double x = px(s.x[i]), y = py(ty(s.y[i]));
      if (i + 1 < n && std::fabs(x - lx) < 0.25 && std::fabs(y - ly) < 0.25) continue;
      out += fmt::format("{:.2f},{:.2f} ", x, y);
      lx = x;
      ly = y;
    }
    out += "\"/>\n";
  }

  void legend(std::string& out) const {
    int row = 0;
    for (const Series& s : p_.series) {
      if (s.label.empty()) continue;
      const int y = y0_ + kMarginTop + 14 + row * 15;
      const int x = x0_ + w_ - kMarginRight - 150;
      out += fmt::format("<rect x=\"{}\" y=\"{}\" width=\"10\" height=\"10\" fill=\"{}\"/>"
                         "<text x=\"{}\" y=\"{}\" font-size=\"11\">{}</text>\n",
                         x, y - 9, s.color, x + 14, y, escape(s.label));
      ++row;
    }
  }

  const Panel& p_;
  int x0_, y0_, w_, h_;
  int pw_ = 0, ph_ = 0;
  Range xr_, yr_;
};

}  // namespace

std::vector<double> nice_ticks(double lo, double hi, int target) {
  std::vector<double> ticks;
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return ticks;
  const double raw = (hi - lo) / std::max(target, 1);
  const double mag = std::pow(10.0, std::floor(std::log10(raw)));
  double step = mag;
  for (double m : {1.0, 2.0, 5.0, 10.0}) {
    step = m * mag;
    if (step >= raw) break;
  }
  // Integer tick indices: accumulating `t += step` drifts and loses end ticks.
  const auto first = static_cast<long long>(std::ceil(lo / step - 1e-9));
  const auto last = static_cast<long long>(std::floor(hi / step + 1e-9));
  for (long long k = first; k <= last; ++k) ticks.push_back(static_cast<double>(k) * step);
  return ticks;
}

SvgChart::SvgChart(std::string title, int columns, int panel_width_px, int panel_height_px)
    : title_(std::move(title)), columns_(std::max(columns, 1)), width_(panel_width_px), height_(panel_height_px) {}

Panel& SvgChart::add_panel(Panel p) {
  panels_.push_back(std::move(p));
  return panels_.back();
}

std::string SvgChart::render() const {
  const int n = static_cast<int>(panels_.size());
  const int rows = (n + columns_ - 1) / columns_;
  const int page_w = columns_ * width_ + (columns_ + 1) * 10;
  const int page_h = 40 + rows * (height_ + 10);
  std::string out = fmt::format(
      "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"{0}\" height=\"{1}\" viewBox=\"0 0 {0} {1}\" "
      "font-family=\"DejaVu Sans, Arial, sans-serif\">\n<rect width=\"100%\" height=\"100%\" fill=\"#f7f7f7\"/>\n"
      "<text x=\"10\" y=\"26\" font-size=\"18\" font-weight=\"bold\">{2}</text>\n",
      page_w, page_h, escape(title_));
  for (int i = 0; i < n; ++i) {
    const int col = i % columns_, row = i / columns_;
    PanelRenderer r(panels_[static_cast<std::size_t>(i)], 10 + col * (width_ + 10), 40 + row * (height_ + 10),
                    width_, height_);
    r.render(out);
  }
  out += "</svg>\n";
  return out;
}

}  // namespace opencnc::viz
