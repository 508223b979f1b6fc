// A small SVG plotting helper for the self-contained HTML report (reports/campaign_report):
// axes with ticks, labels and a grid; line series, horizontal segments, bands, scatter points
// with error bars, bars and rectangles, vertical and horizontal markers with labels; a
// legend below the plot; and a heat map. Everything is inline SVG text meant to sit inside
// an HTML page (no xmlns, no external resources, no script).
//
// Output is deterministic: numbers are printed with fixed decimals (C locale), so the same
// data gives the same bytes. Every data mark is a <path class="data ..."> so tests and the
// headless-browser check can find the drawn data; points carry a <title> tooltip.
#pragma once

#include <optional>
#include <string>
#include <vector>

namespace armfault::svg {

// Escapes text for HTML/SVG text and attribute values (&, <, >, ", ').
std::string Escape(const std::string& text);

// x with `decimals` digits after the point ("%.*f"); "-0.00" prints as "0.00"; NaN and
// infinities print as "nan" / "inf" / "-inf" (callers skip them before drawing).
std::string Fixed(double x, int decimals);

// Estimated width [px] of `text` at `font_px` in a sans-serif font: enough to lay out
// labels and legends without measuring (generous, so labels do not overlap).
double TextWidth(const std::string& text, double font_px);

struct Axis {
  std::string label;            // with unit, e.g. "time (s)"
  std::optional<double> min;    // fixed ends; unset: from the data, widened to ticks
  std::optional<double> max;
  bool log = false;             // decades (values <= 0 are clipped to the axis minimum)
  bool include_zero = false;    // auto range reaches 0
  std::vector<std::string> categories;  // categorical: value k sits at position k
  bool reversed = false;        // larger values to the left / bottom
};

struct Stroke {
  std::string color = "#1f77b4";
  double width = 1.8;
  std::string dash;        // SVG stroke-dasharray, e.g. "5 3"; empty: solid
  double opacity = 1;
};

enum class Marker { kNone, kCircle, kSquare, kDiamond, kTriangle };

class Plot {
 public:
  // `id` becomes the <svg> id (also the prefix of its clip path id): unique in the page.
  Plot(std::string id, std::string title, int width = 660, int height = 320);

  Axis& x() { return x_; }
  Axis& y() { return y_; }
  void set_caption(std::string caption) { caption_ = std::move(caption); }  // small text under the title
  // At least this left margin [px], so that stacked plots line up their plot areas.
  void set_min_left(double px) { min_left_ = px; }

  // A polyline through (xs[k], ys[k]); a NaN y breaks the line. `name` empty: no legend entry.
  void Line(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
            const Stroke& stroke, Marker marker = Marker::kNone);
  // Horizontal segments ys[k] over [x0s[k], x1s[k]] with a marker at each centre (window values).
  void Segments(const std::string& name, const std::vector<double>& x0s, const std::vector<double>& x1s,
                const std::vector<double>& ys, const Stroke& stroke, Marker marker = Marker::kCircle);
  // A filled band between lo and hi along xs.
  void Band(const std::string& name, const std::vector<double>& xs, const std::vector<double>& lo,
            const std::vector<double>& hi, const std::string& color, double opacity = 0.2);
  // Points with optional vertical error bars [lo, hi] (empty vectors: none) and optional
  // per-point tooltips.
  void Points(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
              const std::vector<double>& lo, const std::vector<double>& hi, const std::string& color,
              Marker marker = Marker::kCircle, const std::vector<std::string>& tooltips = {}, double size = 4);
  // A filled rectangle in data coordinates (bars, boxes); `stroke_color` empty: no outline.
  void Rect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity = 1,
            const std::string& stroke_color = "", const std::string& tooltip = "");
  // Histogram bars: counts[k] over [edges[k], edges[k+1]].
  void Bars(const std::string& name, const std::vector<double>& edges, const std::vector<double>& counts,
            const std::string& color, double opacity = 0.75);
  // A full-height vertical line at x with a label at the top (labels of several lines are
  // stacked in rows so they never overlap).
  void VLine(double x, const std::string& label, const Stroke& stroke);
  // A full-width horizontal line at y with a label at the right end.
  void HLine(double y, const std::string& label, const Stroke& stroke);
  // Text at a data position (anchor "start", "middle", "end").
  void Text(double x, double y, const std::string& text, const std::string& anchor = "middle",
            const std::string& color = "#333");
  // A legend entry without a series (e.g. for marks drawn with Rect).
  void LegendEntry(const std::string& name, const std::string& color, bool filled);

  // The <svg> element (width x height plus the legend rows).
  std::string Render() const;

 private:
  // One drawn element, in data coordinates; the ranges come from all of them at Render().
  struct Item {
    enum class Kind { kLine, kSegments, kBand, kPoints, kRect, kVLine, kHLine, kText } kind = Kind::kLine;
    std::vector<double> xs, ys, x1s, lo, hi;
    Stroke stroke;
    std::string color;  // fill
    double opacity = 1;
    Marker marker = Marker::kNone;
    double size = 4;
    std::vector<std::string> tooltips;
    std::string text, anchor;
  };
  struct LegendItem {
    std::string name, color, dash;
    Marker marker = Marker::kNone;
    bool line = true, filled = false;
  };
  // Render's steps (svg_plot.cc): where everything goes, then each drawn element.
  struct Layout;
  Layout Arrange() const;
  void DrawItem(const Item& it, const Layout& l, int* vline_row, std::string* o, std::string* points,
                std::string* labels) const;

  std::string id_, title_, caption_;
  int width_, height_;
  double min_left_ = 0;
  Axis x_, y_;
  std::vector<Item> items_;
  std::vector<LegendItem> legend_;
};

// A heat map of counts: one row per row label, one column per column label, each cell shaded
// by its share of its row and printed with its count. Cells carry data-row, data-col and
// data-count attributes (for tests) and a tooltip.
struct HeatMap {
  std::string id, title, caption;
  std::string row_axis, col_axis;  // e.g. "true class", "isolated as"
  std::vector<std::string> rows, cols;
  std::vector<std::vector<long>> counts;  // [row][col]
  std::string Render() const;
};

}  // namespace armfault::svg
