#include "reports/svg_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>

namespace armfault::svg {

namespace {

constexpr double kTitleFont = 14, kFont = 11, kLabelFont = 12;
constexpr double kLabelRow = 14;      // px per stacked marker-label row above the plot area
constexpr double kLegendRow = 17;     // px per legend row
constexpr double kPixelLimit = 1e5;   // keeps wild data from producing absurd coordinates

bool Finite(double v) { return std::isfinite(v); }

// Pixel coordinates: one decimal is finer than any screen and keeps the page small.
std::string Px(double v) { return Fixed(std::clamp(v, -kPixelLimit, kPixelLimit), 1); }

double NiceStep(double span, int target) {
  if (!(span > 0) || !Finite(span)) return 1;
  const double raw = span / target;
  const double magnitude = std::pow(10.0, std::floor(std::log10(raw)));
  const double f = raw / magnitude;
  const double nice = f < 1.5 ? 1 : f < 3 ? 2 : f < 7 ? 5 : 10;
  return nice * magnitude;
}

int DecimalsFor(double step) {
  if (!(step > 0) || !Finite(step)) return 0;
  return std::max(0, static_cast<int>(std::ceil(-std::log10(step) - 1e-9)));
}

struct TickMark {
  double value;
  std::string label;
};

// The resolved range and ticks of one axis.
struct Scale {
  double lo = 0, hi = 1;  // data range
  double p0 = 0, p1 = 1;  // pixels of lo and hi
  bool log = false;
  std::vector<TickMark> ticks;

  double operator()(double v) const {
    double t;
    if (log) {
      v = std::max(v, lo);
      t = (std::log10(v) - std::log10(lo)) / (std::log10(hi) - std::log10(lo));
    } else {
      t = (v - lo) / (hi - lo);
    }
    return p0 + t * (p1 - p0);
  }
};

// Range and ticks from the axis spec and the data extent [dmin, dmax] (NaN: no data).
Scale Resolve(const Axis& a, double dmin, double dmax) {
  Scale s;
  s.log = a.log && a.categories.empty();
  if (!a.categories.empty()) {
    s.lo = -0.5;
    s.hi = static_cast<double>(a.categories.size()) - 0.5;
    for (size_t k = 0; k < a.categories.size(); ++k) s.ticks.push_back({static_cast<double>(k), a.categories[k]});
    return s;
  }
  if (s.log) {
    double lo = a.min.value_or(Finite(dmin) && dmin > 0 ? std::pow(10.0, std::floor(std::log10(dmin))) : 0.1);
    double hi = a.max.value_or(Finite(dmax) && dmax > 0 ? std::pow(10.0, std::ceil(std::log10(dmax))) : 10);
    if (!(lo > 0)) lo = 1e-3;
    if (!(hi > lo)) hi = lo * 10;
    s.lo = lo;
    s.hi = hi;
    const int k0 = static_cast<int>(std::floor(std::log10(lo) + 1e-9));
    const int k1 = static_cast<int>(std::ceil(std::log10(hi) - 1e-9));
    const bool fine = k1 - k0 <= 2;
    for (int k = k0; k <= k1; ++k) {
      for (double m : {1.0, 2.0, 5.0}) {
        if (m != 1.0 && !fine) continue;
        const double v = m * std::pow(10.0, k);
        if (v < lo * (1 - 1e-9) || v > hi * (1 + 1e-9)) continue;
        s.ticks.push_back({v, Fixed(v, std::max(0, -k))});
      }
    }
    return s;
  }
  double lo = Finite(dmin) ? dmin : 0, hi = Finite(dmax) ? dmax : 1;
  if (a.include_zero) {
    lo = std::min(lo, 0.0);
    hi = std::max(hi, 0.0);
  }
  if (a.min) lo = *a.min;
  if (a.max) hi = *a.max;
  if (!(hi > lo)) {
    const double pad = lo == 0 ? 1 : std::fabs(lo) * 0.1;
    if (!a.min) lo -= pad;
    if (!a.max) hi += pad;
    if (!(hi > lo)) hi = lo + 1;
  }
  const double step = NiceStep(hi - lo, 5);
  if (!a.min) lo = std::floor(lo / step + 1e-9) * step;
  if (!a.max) hi = std::ceil(hi / step - 1e-9) * step;
  s.lo = lo;
  s.hi = hi;
  const int decimals = DecimalsFor(step);
  for (double v = std::ceil(lo / step - 1e-9) * step; v <= hi + step * 1e-9; v += step) {
    s.ticks.push_back({v, Fixed(std::fabs(v) < step * 1e-9 ? 0.0 : v, decimals)});
  }
  return s;
}

std::string MarkerPath(Marker m, double x, double y, double r) {
  switch (m) {
    case Marker::kNone:
      return "";
    case Marker::kCircle:
      return "M" + Px(x - r) + " " + Px(y) + "a" + Px(r) + " " + Px(r) + " 0 1 0 " + Px(2 * r) + " 0a" + Px(r) + " " +
             Px(r) + " 0 1 0 " + Px(-2 * r) + " 0Z";
    case Marker::kSquare:
      return "M" + Px(x - r) + " " + Px(y - r) + "h" + Px(2 * r) + "v" + Px(2 * r) + "h" + Px(-2 * r) + "Z";
    case Marker::kDiamond:
      return "M" + Px(x) + " " + Px(y - 1.3 * r) + "l" + Px(1.3 * r) + " " + Px(1.3 * r) + "l" + Px(-1.3 * r) + " " +
             Px(1.3 * r) + "l" + Px(-1.3 * r) + " " + Px(-1.3 * r) + "Z";
    case Marker::kTriangle:
      return "M" + Px(x) + " " + Px(y - 1.3 * r) + "l" + Px(1.2 * r) + " " + Px(2.1 * r) + "h" + Px(-2.4 * r) + "Z";
  }
  return "";
}

std::string StrokeAttrs(const Stroke& s) {
  std::string a = " stroke=\"" + Escape(s.color) + "\" stroke-width=\"" + Fixed(s.width, 2) + "\"";
  if (!s.dash.empty()) a += " stroke-dasharray=\"" + Escape(s.dash) + "\"";
  if (s.opacity < 1) a += " stroke-opacity=\"" + Fixed(s.opacity, 2) + "\"";
  return a;
}

std::string TextEl(double x, double y, const std::string& text, const std::string& anchor, double font,
                   const std::string& extra = "") {
  return "<text x=\"" + Px(x) + "\" y=\"" + Px(y) + "\" text-anchor=\"" + anchor + "\" font-size=\"" + Fixed(font, 0) +
         "\"" + extra + ">" + Escape(text) + "</text>";
}

std::string TitleEl(const std::string& tooltip) {
  return tooltip.empty() ? "" : "<title>" + Escape(tooltip) + "</title>";
}

// A path element; a tooltip goes in as its <title> child.
std::string PathEl(const std::string& cls, const std::string& d, const std::string& attrs,
                   const std::string& tooltip = "") {
  if (d.empty()) return "";
  const std::string open = "<path class=\"" + cls + "\" d=\"" + d + "\"" + attrs;
  return tooltip.empty() ? open + "/>" : open + ">" + TitleEl(tooltip) + "</path>";
}

}  // namespace

std::string Escape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&#39;"; break;
      default:
        // Control characters other than tab and newlines are not allowed in XML text.
        out += (static_cast<unsigned char>(c) < 0x20 && c != '\t' && c != '\n' && c != '\r') ? '?' : c;
    }
  }
  return out;
}

std::string Fixed(double x, int decimals) {
  if (std::isnan(x)) return "nan";
  if (std::isinf(x)) return x > 0 ? "inf" : "-inf";
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.*f", std::clamp(decimals, 0, 17), x);
  std::string s = buf;
  // "-0.00" is zero: print it without the sign so equal values print equally.
  if (s[0] == '-' && s.find_first_not_of("-0.") == std::string::npos) s.erase(0, 1);
  return s;
}

double TextWidth(const std::string& text, double font_px) {
  double units = 0;
  for (size_t i = 0; i < text.size(); ++i) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    if ((c & 0xC0) == 0x80) continue;  // UTF-8 continuation byte: part of the previous character
    if (c == ' ' || c == '.' || c == ',' || c == 'i' || c == 'l' || c == 'j' || c == '|' || c == '\'') {
      units += 0.32;
    } else if (c == 'm' || c == 'w' || c == 'M' || c == 'W') {
      units += 0.9;
    } else if (c >= 'A' && c <= 'Z') {
      units += 0.7;
    } else {
      units += 0.6;
    }
  }
  return units * font_px;
}

Plot::Plot(std::string id, std::string title, int width, int height)
    : id_(std::move(id)), title_(std::move(title)), width_(width), height_(height) {}

void Plot::Line(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
                const Stroke& stroke, Marker marker) {
  Item it;
  it.kind = Item::Kind::kLine;
  it.xs = xs;
  it.ys = ys;
  it.stroke = stroke;
  it.marker = marker;
  it.color = stroke.color;
  items_.push_back(std::move(it));
  if (!name.empty()) legend_.push_back({name, stroke.color, stroke.dash, marker, true, false});
}

void Plot::Segments(const std::string& name, const std::vector<double>& x0s, const std::vector<double>& x1s,
                    const std::vector<double>& ys, const Stroke& stroke, Marker marker) {
  Item it;
  it.kind = Item::Kind::kSegments;
  it.xs = x0s;
  it.x1s = x1s;
  it.ys = ys;
  it.stroke = stroke;
  it.marker = marker;
  it.color = stroke.color;
  items_.push_back(std::move(it));
  if (!name.empty()) legend_.push_back({name, stroke.color, stroke.dash, marker, true, false});
}

void Plot::Band(const std::string& name, const std::vector<double>& xs, const std::vector<double>& lo,
                const std::vector<double>& hi, const std::string& color, double opacity) {
  Item it;
  it.kind = Item::Kind::kBand;
  it.xs = xs;
  it.lo = lo;
  it.hi = hi;
  it.color = color;
  it.opacity = opacity;
  items_.push_back(std::move(it));
  if (!name.empty()) legend_.push_back({name, color, "", Marker::kNone, false, true});
}

void Plot::Points(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
                  const std::vector<double>& lo, const std::vector<double>& hi, const std::string& color,
                  Marker marker, const std::vector<std::string>& tooltips, double size) {
  Item it;
  it.kind = Item::Kind::kPoints;
  it.xs = xs;
  it.ys = ys;
  it.lo = lo;
  it.hi = hi;
  it.color = color;
  it.marker = marker == Marker::kNone ? Marker::kCircle : marker;
  it.tooltips = tooltips;
  it.size = size;
  items_.push_back(std::move(it));
  if (!name.empty()) legend_.push_back({name, color, "", it.marker, !lo.empty(), false});
}

void Plot::Rect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity,
                const std::string& stroke_color, const std::string& tooltip) {
  Item it;
  it.kind = Item::Kind::kRect;
  it.xs = {x0, x1};
  it.ys = {y0, y1};
  it.color = fill;
  it.opacity = opacity;
  it.stroke.color = stroke_color;
  if (!tooltip.empty()) it.tooltips = {tooltip};
  items_.push_back(std::move(it));
}

void Plot::Bars(const std::string& name, const std::vector<double>& edges, const std::vector<double>& counts,
                const std::string& color, double opacity) {
  for (size_t k = 0; k < counts.size() && k + 1 < edges.size(); ++k) {
    if (counts[k] <= 0) continue;
    Rect(edges[k], edges[k + 1], 0, counts[k], color, opacity, "#ffffff",
         Fixed(edges[k], 3) + " to " + Fixed(edges[k + 1], 3) + ": " + Fixed(counts[k], 0));
  }
  if (!name.empty()) LegendEntry(name, color, true);
}

void Plot::VLine(double x, const std::string& label, const Stroke& stroke) {
  Item it;
  it.kind = Item::Kind::kVLine;
  it.xs = {x};
  it.stroke = stroke;
  it.text = label;
  items_.push_back(std::move(it));
}

void Plot::HLine(double y, const std::string& label, const Stroke& stroke) {
  Item it;
  it.kind = Item::Kind::kHLine;
  it.ys = {y};
  it.stroke = stroke;
  it.text = label;
  items_.push_back(std::move(it));
}

void Plot::Text(double x, double y, const std::string& text, const std::string& anchor, const std::string& color) {
  Item it;
  it.kind = Item::Kind::kText;
  it.xs = {x};
  it.ys = {y};
  it.text = text;
  it.anchor = anchor;
  it.color = color;
  items_.push_back(std::move(it));
}

void Plot::LegendEntry(const std::string& name, const std::string& color, bool filled) {
  legend_.push_back({name, color, "", Marker::kNone, !filled, filled});
}

// Where Render puts everything, in pixels: the axes' scales (with their pixel ends), the plot
// area, the x labels, the legend entries and the total height.
struct Plot::Layout {
  Scale sx, sy;
  double title_h = 0, area_top = 0, area_h = 0, area_bottom = 0, px0 = 0, px1 = 0;
  bool turn_x = false;  // categorical x labels turned, as they do not fit their slots
  double xaxis_label_y = 0;
  struct Placed {
    const LegendItem* item;
    double x, y;
  };
  std::vector<Placed> placed;  // legend entries
  double total_h = 0;
};

// The data's extents on both axes and where everything goes: Render's first step.
Plot::Layout Plot::Arrange() const {
  // Data extents (log axes: positive values only).
  const double nan = std::numeric_limits<double>::quiet_NaN();
  double xmin = nan, xmax = nan, ymin = nan, ymax = nan;
  auto grow = [](double v, bool log, double* lo, double* hi) {
    if (!Finite(v) || (log && v <= 0)) return;
    if (!(v >= *lo)) *lo = v;  // NaN compares false: the first value sets both ends
    if (!(v <= *hi)) *hi = v;
  };
  for (const Item& it : items_) {
    if (it.kind == Item::Kind::kHLine) {
      for (double v : it.ys) grow(v, y_.log, &ymin, &ymax);
      continue;
    }
    if (it.kind == Item::Kind::kVLine) {
      for (double v : it.xs) grow(v, x_.log, &xmin, &xmax);
      continue;
    }
    for (double v : it.xs) grow(v, x_.log, &xmin, &xmax);
    for (double v : it.x1s) grow(v, x_.log, &xmin, &xmax);
    for (double v : it.ys) grow(v, y_.log, &ymin, &ymax);
    for (double v : it.lo) grow(v, y_.log, &ymin, &ymax);
    for (double v : it.hi) grow(v, y_.log, &ymin, &ymax);
  }
  Layout l;
  l.sx = Resolve(x_, xmin, xmax);
  l.sy = Resolve(y_, ymin, ymax);

  // Layout: title block, stacked marker-label rows, plot area, x ticks and label, legend.
  int vlines = 0;
  for (const Item& it : items_) vlines += it.kind == Item::Kind::kVLine && !it.text.empty() ? 1 : 0;
  double tick_w = 0;
  for (const TickMark& t : l.sy.ticks) tick_w = std::max(tick_w, TextWidth(t.label, kFont));
  const double left = std::max(min_left_, tick_w + (y_.label.empty() ? 14 : 34));
  const double right = 18;
  l.title_h = caption_.empty() ? 28 : 44;
  l.area_top = l.title_h + vlines * kLabelRow + (vlines > 0 ? 4 : 0);
  l.area_h = std::max(60.0, height_ - 28.0 - 50.0);
  l.area_bottom = l.area_top + l.area_h;
  l.px0 = left;
  l.px1 = width_ - right;
  // Categorical x labels that do not fit their slot are turned.
  double xcat_w = 0;
  for (const TickMark& t : l.sx.ticks) xcat_w = std::max(xcat_w, TextWidth(t.label, kFont));
  l.turn_x = !x_.categories.empty() && xcat_w + 6 > (l.px1 - l.px0) / std::max<size_t>(1, l.sx.ticks.size());
  const double xlabels_h = l.turn_x ? xcat_w * 0.6 + 16 : 18;
  l.xaxis_label_y = l.area_bottom + xlabels_h + 16;

  // Legend rows, wrapped to the width.
  double lx = l.px0, ly = l.xaxis_label_y + (x_.label.empty() ? 4 : 20);
  for (const LegendItem& entry : legend_) {
    const double w = 30 + TextWidth(entry.name, kFont) + 16;
    if (lx > l.px0 && lx + w > width_ - 4) {
      lx = l.px0;
      ly += kLegendRow;
    }
    l.placed.push_back({&entry, lx, ly});
    lx += w;
  }
  l.total_h = (l.placed.empty() ? l.xaxis_label_y + 8 : ly + 10);

  l.sx.p0 = x_.reversed ? l.px1 : l.px0;
  l.sx.p1 = x_.reversed ? l.px0 : l.px1;
  l.sy.p0 = y_.reversed ? l.area_top : l.area_bottom;
  l.sy.p1 = y_.reversed ? l.area_bottom : l.area_top;
  return l;
}

// One drawn element into `o` (lines, bands, rectangles, markers), `points` (point markers, on
// top in the padded clip) or `labels` (vertical markers' labels, outside the clip); `vline_row`
// counts the labelled vertical markers so far.
void Plot::DrawItem(const Item& it, const Layout& l, int* vline_row, std::string* o, std::string* points,
                    std::string* labels) const {
  switch (it.kind) {
    case Item::Kind::kLine: {
      std::string d, marks;
      bool pen = false;
      for (size_t k = 0; k < it.xs.size() && k < it.ys.size(); ++k) {
        if (!Finite(it.xs[k]) || !Finite(it.ys[k])) {
          pen = false;
          continue;
        }
        const double x = l.sx(it.xs[k]), y = l.sy(it.ys[k]);
        d += (pen ? "L" : "M") + Px(x) + " " + Px(y);
        pen = true;
        marks += MarkerPath(it.marker, x, y, 3.2);
      }
      *o += PathEl("data line", d, " fill=\"none\"" + StrokeAttrs(it.stroke) + " stroke-linejoin=\"round\"");
      *o += PathEl("data marks", marks, " fill=\"" + Escape(it.color) + "\" stroke=\"none\"");
      break;
    }
    case Item::Kind::kSegments: {
      std::string d, marks;
      for (size_t k = 0; k < it.xs.size() && k < it.x1s.size() && k < it.ys.size(); ++k) {
        if (!Finite(it.xs[k]) || !Finite(it.x1s[k]) || !Finite(it.ys[k])) continue;
        const double y = l.sy(it.ys[k]);
        d += "M" + Px(l.sx(it.xs[k])) + " " + Px(y) + "H" + Px(l.sx(it.x1s[k]));
        marks += MarkerPath(it.marker, (l.sx(it.xs[k]) + l.sx(it.x1s[k])) / 2, y, 3.2);
      }
      *o += PathEl("data segments", d, " fill=\"none\"" + StrokeAttrs(it.stroke));
      *o += PathEl("data marks", marks, " fill=\"" + Escape(it.color) + "\" stroke=\"none\"");
      break;
    }
    case Item::Kind::kBand: {
      std::string upper, lower;
      for (size_t k = 0; k < it.xs.size() && k < it.lo.size() && k < it.hi.size(); ++k) {
        if (!Finite(it.xs[k]) || !Finite(it.lo[k]) || !Finite(it.hi[k])) continue;
        upper += (upper.empty() ? "M" : "L") + Px(l.sx(it.xs[k])) + " " + Px(l.sy(it.hi[k]));
        lower = "L" + Px(l.sx(it.xs[k])) + " " + Px(l.sy(it.lo[k])) + lower;
      }
      if (!upper.empty()) {
        *o += PathEl("data band", upper + lower + "Z",
                    " fill=\"" + Escape(it.color) + "\" fill-opacity=\"" + Fixed(it.opacity, 2) + "\" stroke=\"none\"");
      }
      break;
    }
    case Item::Kind::kPoints: {
      for (size_t k = 0; k < it.xs.size() && k < it.ys.size(); ++k) {
        if (!Finite(it.xs[k]) || !Finite(it.ys[k])) continue;
        const double x = l.sx(it.xs[k]), y = l.sy(it.ys[k]);
        if (k < it.lo.size() && k < it.hi.size() && Finite(it.lo[k]) && Finite(it.hi[k])) {
          const double y0 = l.sy(it.lo[k]), y1 = l.sy(it.hi[k]);
          *points += PathEl("data errorbar",
                      "M" + Px(x) + " " + Px(y0) + "V" + Px(y1) + "M" + Px(x - 3.5) + " " + Px(y0) + "h7M" +
                          Px(x - 3.5) + " " + Px(y1) + "h7",
                      " fill=\"none\" stroke=\"" + Escape(it.color) + "\" stroke-width=\"1.3\"");
        }
        *points += PathEl("data point", MarkerPath(it.marker, x, y, it.size),
                    " fill=\"" + Escape(it.color) + "\" stroke=\"#fff\" stroke-width=\"0.8\"",
                    k < it.tooltips.size() ? it.tooltips[k] : "");
      }
      break;
    }
    case Item::Kind::kRect: {
      const double x0 = l.sx(it.xs[0]), x1 = l.sx(it.xs[1]), y0 = l.sy(it.ys[0]), y1 = l.sy(it.ys[1]);
      if (!Finite(x0) || !Finite(x1) || !Finite(y0) || !Finite(y1)) break;
      std::string attrs = " fill=\"" + Escape(it.color) + "\"";
      if (it.opacity < 1) attrs += " fill-opacity=\"" + Fixed(it.opacity, 2) + "\"";
      attrs += it.stroke.color.empty() ? " stroke=\"none\""
                                       : " stroke=\"" + Escape(it.stroke.color) + "\" stroke-width=\"1\"";
      *o += PathEl("data rect",
                  "M" + Px(std::min(x0, x1)) + " " + Px(std::min(y0, y1)) + "H" + Px(std::max(x0, x1)) + "V" +
                      Px(std::max(y0, y1)) + "H" + Px(std::min(x0, x1)) + "Z",
                  attrs, it.tooltips.empty() ? "" : it.tooltips[0]);
      break;
    }
    case Item::Kind::kVLine: {
      if (!Finite(it.xs[0])) break;
      const double x = l.sx(it.xs[0]);
      *o += PathEl("marker vline", "M" + Px(x) + " " + Px(l.area_top) + "V" + Px(l.area_bottom),
                  " fill=\"none\"" + StrokeAttrs(it.stroke));
      if (!it.text.empty()) {
        const double y = l.title_h + kLabelRow * ((*vline_row)++) + 11;
        const bool to_left = x + 4 + TextWidth(it.text, kFont) > width_ - 2;
        *labels += PathEl("marker tick", "M" + Px(x) + " " + Px(y + 2) + "V" + Px(l.area_top),
                         " fill=\"none\"" + StrokeAttrs(Stroke{it.stroke.color, 1, "2 2", 0.6}));
        *labels += TextEl(to_left ? x - 4 : x + 4, y, it.text, to_left ? "end" : "start", kFont,
                         " fill=\"" + Escape(it.stroke.color) + "\"");
      }
      break;
    }
    case Item::Kind::kHLine: {
      if (!Finite(it.ys[0])) break;
      const double y = l.sy(it.ys[0]);
      *o += PathEl("marker hline", "M" + Px(l.px0) + " " + Px(y) + "H" + Px(l.px1),
                  " fill=\"none\"" + StrokeAttrs(it.stroke));
      if (!it.text.empty()) {
        *o += TextEl(l.px1 - 4, y - 4, it.text, "end", kFont, " fill=\"" + Escape(it.stroke.color) + "\"");
      }
      break;
    }
    case Item::Kind::kText: {
      if (!Finite(it.xs[0]) || !Finite(it.ys[0])) break;
      *o += TextEl(l.sx(it.xs[0]), l.sy(it.ys[0]), it.text, it.anchor, kFont, " fill=\"" + Escape(it.color) + "\"");
      break;
    }
  }
}

std::string Plot::Render() const {
  const Layout l = Arrange();
  std::string o = "<svg id=\"" + Escape(id_) + "\" class=\"plot\" width=\"" + std::to_string(width_) +
                  "\" height=\"" + Px(l.total_h) + "\" viewBox=\"0 0 " + std::to_string(width_) + " " + Px(l.total_h) +
                  "\" role=\"img\" font-family=\"sans-serif\">";
  o += "<title>" + Escape(title_) + "</title>";
  // Lines and bands are clipped to the plot area; point markers to a slightly larger one, so
  // a point on the frame (a rate of 1, a false-alarm rate of 0) is drawn whole.
  constexpr double kPointPad = 8;
  o += "<defs><clipPath id=\"" + Escape(id_) + "-clip\"><rect x=\"" + Px(l.px0) + "\" y=\"" + Px(l.area_top) +
       "\" width=\"" + Px(l.px1 - l.px0) + "\" height=\"" + Px(l.area_h) + "\"/></clipPath><clipPath id=\"" +
       Escape(id_) + "-clip-points\"><rect x=\"" + Px(l.px0 - kPointPad) + "\" y=\"" + Px(l.area_top - kPointPad) +
       "\" width=\"" + Px(l.px1 - l.px0 + 2 * kPointPad) + "\" height=\"" + Px(l.area_h + 2 * kPointPad) +
       "\"/></clipPath></defs>";
  o += TextEl(8, 18, title_, "start", kTitleFont, " font-weight=\"bold\" fill=\"#222\"");
  if (!caption_.empty()) o += TextEl(8, 35, caption_, "start", kFont, " fill=\"#555\"");

  // Grid and ticks.
  std::string grid, ticks;
  for (const TickMark& t : l.sx.ticks) {
    const double x = l.sx(t.value);
    grid += "M" + Px(x) + " " + Px(l.area_top) + "V" + Px(l.area_bottom);
    ticks += "M" + Px(x) + " " + Px(l.area_bottom) + "v4";
  }
  for (const TickMark& t : l.sy.ticks) {
    const double y = l.sy(t.value);
    grid += "M" + Px(l.px0) + " " + Px(y) + "H" + Px(l.px1);
    ticks += "M" + Px(l.px0) + " " + Px(y) + "h-4";
  }
  o += PathEl("grid", grid, " fill=\"none\" stroke=\"#e6e6e6\" stroke-width=\"1\"");
  o += PathEl("ticks", ticks, " fill=\"none\" stroke=\"#444\" stroke-width=\"1\"");
  o += PathEl("frame",
              "M" + Px(l.px0) + " " + Px(l.area_top) + "V" + Px(l.area_bottom) + "H" + Px(l.px1) + "V" +
                  Px(l.area_top) + "Z",
              " fill=\"none\" stroke=\"#888\" stroke-width=\"1\"");
  o += "<g class=\"xticks\" fill=\"#333\">";
  for (const TickMark& t : l.sx.ticks) {
    const double x = l.sx(t.value);
    if (l.turn_x) {
      o += "<text transform=\"translate(" + Px(x + 3) + " " + Px(l.area_bottom + 12) +
           ") rotate(-35)\" text-anchor=\"end\" font-size=\"" + Fixed(kFont, 0) + "\">" + Escape(t.label) + "</text>";
    } else {
      o += TextEl(x, l.area_bottom + 16, t.label, "middle", kFont);
    }
  }
  o += "</g><g class=\"yticks\" fill=\"#333\">";
  for (const TickMark& t : l.sy.ticks) o += TextEl(l.px0 - 7, l.sy(t.value) + 4, t.label, "end", kFont);
  o += "</g>";
  if (!x_.label.empty()) {
    o += TextEl((l.px0 + l.px1) / 2, l.xaxis_label_y, x_.label, "middle", kLabelFont, " fill=\"#222\"");
  }
  if (!y_.label.empty()) {
    const double cy = (l.area_top + l.area_bottom) / 2;
    o += "<text transform=\"translate(14 " + Px(cy) + ") rotate(-90)\" text-anchor=\"middle\" font-size=\"" +
         Fixed(kLabelFont, 0) + "\" fill=\"#222\">" + Escape(y_.label) + "</text>";
  }

  // Data, clipped to the plot area.
  o += "<g clip-path=\"url(#" + Escape(id_) + "-clip)\">";
  std::string labels;  // marker labels go outside the clip
  std::string points;  // point markers go on top, in the padded clip
  int vline_row = 0;
  for (const Item& it : items_) DrawItem(it, l, &vline_row, &o, &points, &labels);
  o += "</g>";
  if (!points.empty()) o += "<g clip-path=\"url(#" + Escape(id_) + "-clip-points)\">" + points + "</g>";
  o += labels;

  // Legend.
  if (!l.placed.empty()) {
    o += "<g class=\"legend\">";
    for (const Layout::Placed& p : l.placed) {
      const LegendItem& entry = *p.item;
      const double cy = p.y - 4;
      if (entry.filled) {
        o += PathEl("legend-key", "M" + Px(p.x) + " " + Px(cy - 6) + "h22v12h-22Z",
                    " fill=\"" + Escape(entry.color) + "\" fill-opacity=\"0.45\" stroke=\"" + Escape(entry.color) +
                        "\"");
      } else if (entry.line) {
        o += PathEl("legend-key", "M" + Px(p.x) + " " + Px(cy) + "h22",
                    " fill=\"none\"" + StrokeAttrs(Stroke{entry.color, 2, entry.dash, 1}));
      }
      o += PathEl("legend-key", MarkerPath(entry.marker, p.x + 11, cy, 3.5),
                  " fill=\"" + Escape(entry.color) + "\" stroke=\"none\"");
      o += TextEl(p.x + 28, p.y, entry.name, "start", kFont, " fill=\"#222\"");
    }
    o += "</g>";
  }
  o += "</svg>";
  return o;
}

namespace {

// White to a dark blue by `share` in [0, 1].
std::string Shade(double share) {
  share = std::clamp(Finite(share) ? share : 0.0, 0.0, 1.0);
  const int base[3] = {0x1f, 0x4e, 0x9c};
  char buf[8];
  int c[3];
  for (int k = 0; k < 3; ++k) c[k] = static_cast<int>(std::lround(255 + (base[k] - 255) * share));
  std::snprintf(buf, sizeof buf, "#%02x%02x%02x", c[0], c[1], c[2]);
  return buf;
}

}  // namespace

std::string HeatMap::Render() const {
  constexpr double kCellW = 74, kCellH = 32, kTurn = 0.5736;  // sin 35 deg
  double row_w = 0, col_w = 0;
  for (const std::string& r : rows) row_w = std::max(row_w, TextWidth(r, kLabelFont));
  for (const std::string& c : cols) col_w = std::max(col_w, TextWidth(c, kLabelFont));
  const double title_h = caption.empty() ? 28 : 44;
  const double left = row_w + 40;
  const double top = title_h + 22 + col_w * kTurn + 8;
  const double grid_w = kCellW * static_cast<double>(cols.size());
  // Turned column labels reach 0.82 (cos 35 deg) of their length right of their cell's centre.
  const double width = std::max({left + grid_w + 50, left + grid_w - kCellW / 2 + col_w * 0.82 + 12,
                                 TextWidth(title, kTitleFont) + 20, TextWidth(caption, kFont) + 20});
  const double height = top + kCellH * static_cast<double>(rows.size()) + 16;

  std::string o;
  o += "<svg id=\"" + Escape(id) + "\" class=\"plot heatmap\" width=\"" + Px(width) + "\" height=\"" + Px(height) +
       "\" viewBox=\"0 0 " + Px(width) + " " + Px(height) + "\" role=\"img\" font-family=\"sans-serif\">";
  o += "<title>" + Escape(title) + "</title>";
  o += TextEl(8, 18, title, "start", kTitleFont, " font-weight=\"bold\" fill=\"#222\"");
  if (!caption.empty()) o += TextEl(8, 35, caption, "start", kFont, " fill=\"#555\"");
  o += TextEl(left + grid_w / 2, title_h + 12, col_axis, "middle", kLabelFont, " fill=\"#222\" font-weight=\"bold\"");
  o += "<text transform=\"translate(14 " + Px(top + kCellH * rows.size() / 2.0) +
       ") rotate(-90)\" text-anchor=\"middle\" font-size=\"" + Fixed(kLabelFont, 0) +
       "\" fill=\"#222\" font-weight=\"bold\">" + Escape(row_axis) + "</text>";
  for (size_t c = 0; c < cols.size(); ++c) {
    const double x = left + kCellW * (c + 0.5);
    o += "<text transform=\"translate(" + Px(x - 4) + " " + Px(top - 6) +
         ") rotate(-35)\" text-anchor=\"start\" font-size=\"" + Fixed(kLabelFont, 0) + "\" fill=\"#222\">" +
         Escape(cols[c]) + "</text>";
  }
  o += TextEl(left + grid_w + 8, top - 6, "runs", "start", kFont, " fill=\"#555\"");
  for (size_t r = 0; r < rows.size(); ++r) {
    const double y = top + kCellH * r;
    long total = 0;
    for (size_t c = 0; c < cols.size(); ++c) total += r < counts.size() && c < counts[r].size() ? counts[r][c] : 0;
    o += TextEl(left - 8, y + kCellH / 2 + 4, rows[r], "end", kLabelFont, " fill=\"#222\"");
    for (size_t c = 0; c < cols.size(); ++c) {
      const long n = r < counts.size() && c < counts[r].size() ? counts[r][c] : 0;
      const double share = total > 0 ? static_cast<double>(n) / static_cast<double>(total) : 0;
      const double x = left + kCellW * c;
      const std::string tip = "true " + rows[r] + ", isolated as " + cols[c] + ": " + std::to_string(n) + " of " +
                              std::to_string(total) + " runs (" + Fixed(100 * share, 1) + " %)";
      o += "<path class=\"data cell\" data-row=\"" + Escape(rows[r]) + "\" data-col=\"" + Escape(cols[c]) +
           "\" data-count=\"" + std::to_string(n) + "\" d=\"M" + Px(x) + " " + Px(y) + "h" + Px(kCellW) + "v" +
           Px(kCellH) + "h" + Px(-kCellW) + "Z\" fill=\"" + Shade(share) + "\" stroke=\"" +
           (rows[r] == cols[c] ? "#222" : "#ccc") + "\" stroke-width=\"" + (rows[r] == cols[c] ? "1.5" : "1") +
           "\">" + TitleEl(tip) + "</path>";
      o += TextEl(x + kCellW / 2, y + kCellH / 2 + 4, std::to_string(n), "middle", kLabelFont,
                  std::string(" fill=\"") + (share > 0.5 ? "#fff" : n == 0 ? "#aaa" : "#222") + "\"");
    }
    o += TextEl(left + grid_w + 8, y + kCellH / 2 + 4, std::to_string(total), "start", kFont, " fill=\"#555\"");
  }
  o += "</svg>";
  return o;
}

}  // namespace armfault::svg
