// Plots of the self-contained HTML report (reports/campaign_report) as Vega-Lite specs, drawn
// in the browser by vega-embed (pinned in reports/web/package-lock.json; the build inlines the
// three minified libraries into the page, reports/page/report_js.h, so nothing is fetched).
//
// A Plot collects drawn elements in data coordinates, as the report's sections describe them
// (lines, window segments, bands, points with error bars, bars, rectangles, vertical and
// horizontal markers with labels, text), and Render() writes an empty <div class="plot"
// id="ID"> and the layered Vega-Lite spec beside it in <script type="application/json"
// class="vega-spec" data-plot="ID">; the page's script (ReportPlotScript) embeds every spec.
// Every plot zooms and pans (an interval selection bound to its scales: drag, wheel; double
// click resets), every mark with a tooltip shows it on hover, and a mark that carries a run
// (RunRef) shows the run's id, family, joint and magnitude and copies its
// `armfault trace CAMPAIGN --run RUN_ID` command to the clipboard when clicked.
//
// Output is deterministic: the same data gives the same bytes (numbers rounded to 6
// significant digits, NaN and infinities as null, which breaks a line).
#pragma once

#include <nlohmann/json.hpp>

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace armfault::vega {

struct Axis {
  std::string label;            // with unit, e.g. "time (s)"
  std::optional<double> min;    // fixed ends; unset: from the data
  std::optional<double> max;
  bool log = false;             // decades (values <= 0 are drawn at the axis minimum, or left out)
  bool include_zero = false;    // the range reaches 0
  std::vector<std::string> categories;  // categorical: value k sits at position k, labelled categories[k]
  bool reversed = false;        // larger values to the left / bottom
};

struct Stroke {
  std::string color = "#1f77b4";
  double width = 1.8;
  std::string dash;        // stroke dash pattern in px, e.g. "5 3"; empty: solid
  double opacity = 1;
};

enum class Marker { kNone, kCircle, kSquare, kDiamond, kTriangle };

// The run a mark stands for: its tooltip names it, and a click copies its trace command.
struct RunRef {
  std::string run_id;
  std::string family;                 // "" for a healthy run
  int joint = 0;                      // 1-based, 0: none
  std::optional<double> magnitude;    // the fault's magnitude, in its own unit (magnitude_key)
  std::string magnitude_key;          // e.g. "kt_factor"
};

class Plot {
 public:
  // `id` becomes the plot's element id: unique in the page. width x height [px]: the whole
  // plot with its title, axes and legend.
  Plot(std::string id, std::string title, int width = 660, int height = 320);

  Axis& x() { return x_; }
  Axis& y() { return y_; }
  void set_caption(std::string caption) { caption_ = std::move(caption); }  // small text under the title
  // At least this left margin [px] (kept for the callers that line up stacked plots; Vega-Lite
  // sizes the axes itself, so only the plot widths line them up).
  void set_min_left(double px) { min_left_ = px; }
  // Every mark of this plot stands for this run (the run view).
  void set_run(RunRef run) { run_ = std::move(run); }

  // A polyline through (xs[k], ys[k]); a NaN y breaks the line. `name` empty: no legend entry.
  void Line(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
            const Stroke& stroke, Marker marker = Marker::kNone);
  // Horizontal segments ys[k] over [x0s[k], x1s[k]] with a marker at each centre (window values).
  void Segments(const std::string& name, const std::vector<double>& x0s, const std::vector<double>& x1s,
                const std::vector<double>& ys, const Stroke& stroke, Marker marker = Marker::kCircle);
  // A filled band between lo and hi along xs.
  void Band(const std::string& name, const std::vector<double>& xs, const std::vector<double>& lo,
            const std::vector<double>& hi, const std::string& color, double opacity = 0.2);
  // Points with optional vertical error bars [lo, hi] (empty vectors: none), optional
  // per-point tooltips and optional per-point runs (empty: none; else one per point).
  void Points(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
              const std::vector<double>& lo, const std::vector<double>& hi, const std::string& color,
              Marker marker = Marker::kCircle, const std::vector<std::string>& tooltips = {}, double size = 4,
              const std::vector<RunRef>& runs = {});
  // A filled rectangle in data coordinates (bars, boxes); `stroke_color` empty: no outline.
  void Rect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity = 1,
            const std::string& stroke_color = "", const std::string& tooltip = "");
  // Histogram bars: counts[k] over [edges[k], edges[k+1]].
  void Bars(const std::string& name, const std::vector<double>& edges, const std::vector<double>& counts,
            const std::string& color, double opacity = 0.75);
  // A full-height vertical line at x with a label at the top (labels of several lines are
  // stacked in rows).
  void VLine(double x, const std::string& label, const Stroke& stroke);
  // A full-width horizontal line at y with a label at the right end.
  void HLine(double y, const std::string& label, const Stroke& stroke);
  // Text at a data position (anchor "start", "middle", "end").
  void Text(double x, double y, const std::string& text, const std::string& anchor = "middle",
            const std::string& color = "#333");
  // A legend entry without a series (e.g. for marks drawn with Rect).
  void LegendEntry(const std::string& name, const std::string& color, bool filled);

  // The Vega-Lite spec (JSON text), and the page's element: the <div> and the spec's <script>.
  std::string Spec() const;
  std::string Render() const;

 private:
  std::string id_, title_, caption_;
  int width_, height_;
  double min_left_ = 0;
  Axis x_, y_;
  std::optional<RunRef> run_;
  // One Vega-Lite unit spec each; `tip`: it has its own tooltip. The legend's names and
  // colours in order of appearance.
  struct Layer {
    nlohmann::json spec;
    bool tip = false;
    std::string name;
  };
  std::vector<Layer> layers_;
  std::vector<std::pair<std::string, std::string>> legend_;
  int vline_rows_ = 0;
  void AddLegend(const std::string& name, const std::string& color);
  // The x or y encoding of field `field` with this plot's scale, axis and title.
  nlohmann::json XEnc(const char* field = "x") const;
  nlohmann::json YEnc(const char* field = "y") const;
  // The colour of a named series (its legend entry) or a fixed colour.
  nlohmann::json ColorEnc(const std::string& name, const std::string& color) const;
  void Add(nlohmann::json spec, const std::string& name, bool tip = false);
};

// A heat map of counts: one row per row label, one column per column label, each cell shaded
// by its share of its row and printed with its count; each cell's tooltip names its row,
// column, count and share. Its data rows carry "row", "col" and "count" (for tests).
struct HeatMap {
  std::string id, title, caption;
  std::string row_axis, col_axis;  // e.g. "true class", "isolated as"
  std::vector<std::string> rows, cols;
  std::vector<std::vector<long>> counts;  // [row][col]
  std::string Spec() const;
  std::string Render() const;
};

// The page's script that embeds every plot (after the three libraries): vegaEmbed per spec
// with the SVG renderer, and the click handler that copies a run's trace command (the
// Clipboard API, else a hidden textarea and execCommand, else a prompt to copy by hand); the
// campaign file of that command is the <body>'s data-campaign attribute.
const char* ReportPlotScript();

}  // namespace armfault::vega
