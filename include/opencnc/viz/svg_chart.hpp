// SPDX-License-Identifier: GPL-3.0-or-later
// Minimal SVG charts for people: panels with axes, ticks, labels, line and bar series.
#pragma once

#include <string>
#include <vector>

namespace opencnc::viz {

/// One data series of a panel. `bars` draws columns from y = 0 (histograms).
struct Series {
  std::string label;
  std::string color = "#1f77b4";
  std::vector<double> x, y;
  bool bars = false;
  double width = 1.2;  ///< stroke width in px
};

/// A chart panel: title, axis labels, series; equal scales keep toolpath views undistorted.
struct Panel {
  std::string title, x_label, y_label;
  std::vector<Series> series;
  bool equal_scale = false;  ///< same mm per pixel on both axes (toolpaths)
  bool log_y = false;        ///< logarithmic y axis (histogram counts); values <= 0 are skipped
};

/// A page of panels laid out in a grid, rendered to a standalone SVG document.
/// Non-real-time; any thread.
class SvgChart {
 public:
  SvgChart(std::string title, int columns = 1, int panel_width_px = 560, int panel_height_px = 380);
  Panel& add_panel(Panel p);
  /// The document; the command line writes it through core::OutputFile.
  std::string render() const;

 private:
  std::string title_;
  int columns_, width_, height_;
  std::vector<Panel> panels_;
};

/// "Nice" tick positions covering [lo, hi] with about `target` ticks (1, 2, 5 × 10^k steps).
std::vector<double> nice_ticks(double lo, double hi, int target = 6);

}  // namespace opencnc::viz
