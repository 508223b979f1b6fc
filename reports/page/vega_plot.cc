#include "reports/page/vega_plot.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include "reports/page/report_common.h"

namespace armfault::vega {

namespace {

using nlohmann::json;

// A number for the spec: 6 significant digits (finer than any screen, and the page stays
// small); NaN and infinities as null (a line breaks there; other marks leave it out).
json Num(double v) {
  if (!std::isfinite(v)) return nullptr;
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6g", v);
  return std::strtod(buf, nullptr);
}

// "5 3" as [5, 3].
json Dash(const std::string& dash) {
  json d = json::array();
  const char* p = dash.c_str();
  char* end = nullptr;
  for (double v = std::strtod(p, &end); end != p; v = std::strtod(p, &end)) {
    d.push_back(v);
    p = end;
  }
  return d;
}

const char* Shape(Marker m) {
  switch (m) {
    case Marker::kSquare: return "square";
    case Marker::kDiamond: return "diamond";
    case Marker::kTriangle: return "triangle-up";
    default: return "circle";
  }
}

// A marker of radius r [px] as a Vega symbol's area [px²].
double Area(double r) { return 4 * r * r; }

json Scale(const Axis& a) {
  json s = json::object();
  if (!a.categories.empty()) {
    s["domain"] = {-0.5, static_cast<double>(a.categories.size()) - 0.5};
    s["nice"] = false;
    s["zero"] = false;
  } else {
    if (a.log) s["type"] = "log";
    if (a.min && a.max) {
      s["domain"] = {Num(*a.min), Num(*a.max)};
      s["nice"] = false;
    } else if (a.min) {
      s["domainMin"] = Num(*a.min);
    } else if (a.max) {
      s["domainMax"] = Num(*a.max);
    }
    if (!a.log) s["zero"] = a.include_zero;
  }
  if (a.reversed) s["reverse"] = true;
  return s;
}

json AxisJson(const Axis& a) {
  json ax = {{"title", a.label}, {"labelFontSize", 11}, {"titleFontSize", 12}, {"titleFontWeight", "normal"}};
  if (!a.categories.empty()) {
    json values = json::array();
    for (size_t k = 0; k < a.categories.size(); ++k) values.push_back(k);
    ax["values"] = values;
    ax["labelExpr"] = json(a.categories).dump() + "[datum.value]";
    ax["labelLimit"] = 260;
  }
  return ax;
}

// A value on a log axis: <= 0 cannot be drawn; it sits at the axis minimum when there is one.
json AxisValue(const Axis& a, double v) {
  if (a.log && a.categories.empty() && !(v > 0)) return a.min ? Num(*a.min) : json(nullptr);
  return Num(v);
}

// Caption lines of at most about `chars` characters, broken between words.
json Wrap(const std::string& text, size_t chars) {
  json lines = json::array();
  std::string line, word;
  auto flush_word = [&] {
    if (word.empty()) return;
    if (!line.empty() && line.size() + 1 + word.size() > chars) {
      lines.push_back(line);
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
    word.clear();
  };
  for (char c : text) {
    if (c == ' ') {
      flush_word();
    } else {
      word += c;
    }
  }
  flush_word();
  if (!line.empty()) lines.push_back(line);
  return lines;
}

// The spec as text safe inside <script type="application/json">: no '<' (so no </script>).
std::string SafeDump(const json& spec) {
  const std::string text = spec.dump(-1, ' ', false, json::error_handler_t::replace);
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    if (c == '<') {
      out += "\\u003c";
    } else {
      out += c;
    }
  }
  return out;
}

json RunRow(const RunRef& r) {
  json row = {{"run", r.run_id}};
  if (!r.family.empty()) row["family"] = r.family;
  if (r.joint > 0) row["joint"] = r.joint;
  if (r.magnitude) row["magnitude"] = Num(*r.magnitude);
  return row;
}

// The tooltip fields of a run: those present in `rows`, then `extra` (e.g. the tip).
json RunTooltip(const json& rows, const std::string& magnitude_title, const json& extra) {
  json t = json::array();
  for (const char* f : {"run", "family", "joint", "magnitude"}) {
    const bool any = std::any_of(rows.begin(), rows.end(), [&](const json& r) { return r.contains(f); });
    if (!any) continue;
    json def = {{"field", f}, {"title", std::string(f) == "magnitude" && !magnitude_title.empty() ? magnitude_title : f}};
    if (std::string(f) == "joint" || std::string(f) == "magnitude") def["type"] = "quantitative";
    t.push_back(def);
  }
  for (const json& e : extra) t.push_back(e);
  return t;
}

}  // namespace

Plot::Plot(std::string id, std::string title, int width, int height)
    : id_(std::move(id)), title_(std::move(title)), width_(width), height_(height) {}

json Plot::XEnc(const char* field) const {
  return {{"field", field}, {"type", "quantitative"}, {"scale", Scale(x_)}, {"axis", AxisJson(x_)}};
}

json Plot::YEnc(const char* field) const {
  return {{"field", field}, {"type", "quantitative"}, {"scale", Scale(y_)}, {"axis", AxisJson(y_)}};
}

json Plot::ColorEnc(const std::string& name, const std::string& color) const {
  if (name.empty()) return {{"value", color}};
  return {{"field", "series"}, {"type", "nominal"}};  // scale and legend: Spec(), once all are known
}

void Plot::AddLegend(const std::string& name, const std::string& color) {
  if (name.empty()) return;
  for (const auto& [n, c] : legend_) {
    if (n == name) return;
  }
  legend_.emplace_back(name, color);
}

void Plot::Add(json spec, const std::string& name, bool tip) {
  spec["mark"]["clip"] = true;
  if (!name.empty()) spec["transform"] = json::array({{{"calculate", json(name).dump()}, {"as", "series"}}});
  layers_.push_back({std::move(spec), tip, name});
}

void Plot::Line(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
                const Stroke& stroke, Marker marker) {
  const size_t n = std::min(xs.size(), ys.size());
  if (n == 0) return;
  AddLegend(name, stroke.color);
  const bool sorted = std::is_sorted(xs.begin(), xs.begin() + static_cast<long>(n));
  json values = json::array();
  for (size_t k = 0; k < n; ++k) {
    json row = {{"x", AxisValue(x_, xs[k])}, {"y", AxisValue(y_, ys[k])}};
    if (!sorted) row["i"] = k;
    values.push_back(std::move(row));
  }
  json mark = {{"type", "line"}, {"strokeWidth", stroke.width}, {"opacity", stroke.opacity}};
  if (!stroke.dash.empty()) mark["strokeDash"] = Dash(stroke.dash);
  json enc = {{"x", XEnc()}, {"y", YEnc()}, {"color", ColorEnc(name, stroke.color)}};
  if (!sorted) enc["order"] = {{"field", "i"}, {"type", "quantitative"}};
  Add({{"data", {{"values", values}}}, {"mark", mark}, {"encoding", enc}}, name);
  if (marker != Marker::kNone) {
    json pmark = {{"type", "point"}, {"shape", Shape(marker)}, {"filled", true}, {"size", Area(3)},
                  {"opacity", stroke.opacity}};
    Add({{"data", {{"values", values}}}, {"mark", pmark},
         {"encoding", {{"x", XEnc()}, {"y", YEnc()}, {"color", ColorEnc(name, stroke.color)}}}},
        name);
  }
}

void Plot::Segments(const std::string& name, const std::vector<double>& x0s, const std::vector<double>& x1s,
                    const std::vector<double>& ys, const Stroke& stroke, Marker marker) {
  const size_t n = std::min({x0s.size(), x1s.size(), ys.size()});
  if (n == 0) return;
  AddLegend(name, stroke.color);
  json values = json::array(), centres = json::array();
  for (size_t k = 0; k < n; ++k) {
    values.push_back({{"x", AxisValue(x_, x0s[k])}, {"x2", AxisValue(x_, x1s[k])}, {"y", AxisValue(y_, ys[k])}});
    centres.push_back({{"x", AxisValue(x_, 0.5 * (x0s[k] + x1s[k]))}, {"y", AxisValue(y_, ys[k])}});
  }
  json mark = {{"type", "rule"}, {"strokeWidth", stroke.width}, {"opacity", stroke.opacity}};
  if (!stroke.dash.empty()) mark["strokeDash"] = Dash(stroke.dash);
  Add({{"data", {{"values", values}}},
       {"mark", mark},
       {"encoding", {{"x", XEnc()}, {"x2", {{"field", "x2"}}}, {"y", YEnc()}, {"color", ColorEnc(name, stroke.color)}}}},
      name);
  if (marker != Marker::kNone) {
    Add({{"data", {{"values", centres}}},
         {"mark", {{"type", "point"}, {"shape", Shape(marker)}, {"filled", true}, {"size", Area(3)}}},
         {"encoding", {{"x", XEnc()}, {"y", YEnc()}, {"color", ColorEnc(name, stroke.color)}}}},
        name);
  }
}

void Plot::Band(const std::string& name, const std::vector<double>& xs, const std::vector<double>& lo,
                const std::vector<double>& hi, const std::string& color, double opacity) {
  const size_t n = std::min({xs.size(), lo.size(), hi.size()});
  if (n == 0) return;
  AddLegend(name, color);
  json values = json::array();
  for (size_t k = 0; k < n; ++k) {
    values.push_back({{"x", AxisValue(x_, xs[k])}, {"y", AxisValue(y_, lo[k])}, {"y2", AxisValue(y_, hi[k])}});
  }
  Add({{"data", {{"values", values}}},
       {"mark", {{"type", "area"}, {"opacity", opacity}}},
       {"encoding", {{"x", XEnc()}, {"y", YEnc()}, {"y2", {{"field", "y2"}}}, {"color", ColorEnc(name, color)}}}},
      name);
}

void Plot::Points(const std::string& name, const std::vector<double>& xs, const std::vector<double>& ys,
                  const std::vector<double>& lo, const std::vector<double>& hi, const std::string& color, Marker marker,
                  const std::vector<std::string>& tooltips, double size, const std::vector<RunRef>& runs) {
  const size_t n = std::min(xs.size(), ys.size());
  if (n == 0) return;
  AddLegend(name, color);
  const bool bars = lo.size() >= n && hi.size() >= n;
  if (bars) {
    json values = json::array();
    for (size_t k = 0; k < n; ++k) {
      values.push_back({{"x", AxisValue(x_, xs[k])}, {"y", AxisValue(y_, lo[k])}, {"y2", AxisValue(y_, hi[k])}});
    }
    Add({{"data", {{"values", values}}},
         {"mark", {{"type", "rule"}, {"strokeWidth", 1.2}}},
         {"encoding", {{"x", XEnc()}, {"y", YEnc()}, {"y2", {{"field", "y2"}}}, {"color", ColorEnc(name, color)}}}},
        name);
  }
  json values = json::array();
  std::string magnitude_title;
  for (size_t k = 0; k < n; ++k) {
    json row = k < runs.size() ? RunRow(runs[k]) : json::object();
    row["x"] = AxisValue(x_, xs[k]);
    row["y"] = AxisValue(y_, ys[k]);
    if (k < tooltips.size() && !tooltips[k].empty()) row["tip"] = tooltips[k];
    if (k < runs.size() && magnitude_title.empty()) magnitude_title = runs[k].magnitude_key;
    values.push_back(std::move(row));
  }
  json enc = {{"x", XEnc()}, {"y", YEnc()}, {"color", ColorEnc(name, color)}};
  const bool tips = std::any_of(values.begin(), values.end(), [](const json& r) { return r.contains("tip"); });
  if (!runs.empty()) {
    enc["tooltip"] = RunTooltip(values, magnitude_title, tips ? json::array({{{"field", "tip"}, {"title", "outcome"}}})
                                                              : json::array());
  } else if (tips) {
    enc["tooltip"] = {{"field", "tip"}};
  }
  Add({{"data", {{"values", values}}},
       {"mark", {{"type", "point"}, {"shape", Shape(marker)}, {"filled", true}, {"size", Area(size)}, {"opacity", 0.9}}},
       {"encoding", enc}},
      name, tips || !runs.empty());
}

void Plot::Rect(double x0, double x1, double y0, double y1, const std::string& fill, double opacity,
                const std::string& stroke_color, const std::string& tooltip) {
  json row = {{"x", AxisValue(x_, x0)}, {"x2", AxisValue(x_, x1)}, {"y", AxisValue(y_, y0)}, {"y2", AxisValue(y_, y1)}};
  json enc = {{"x", XEnc()}, {"x2", {{"field", "x2"}}}, {"y", YEnc()}, {"y2", {{"field", "y2"}}}};
  if (!tooltip.empty()) {
    row["tip"] = tooltip;
    enc["tooltip"] = {{"field", "tip"}};
  }
  json mark = {{"type", "rect"}, {"fill", fill}, {"fillOpacity", opacity}};
  if (!stroke_color.empty()) mark["stroke"] = stroke_color, mark["strokeWidth"] = 1.2;
  Add({{"data", {{"values", json::array({row})}}}, {"mark", mark}, {"encoding", enc}}, "", !tooltip.empty());
}

void Plot::Bars(const std::string& name, const std::vector<double>& edges, const std::vector<double>& counts,
                const std::string& color, double opacity) {
  if (edges.size() < 2 || counts.empty()) return;
  AddLegend(name, color);
  json values = json::array();
  for (size_t k = 0; k + 1 < edges.size() && k < counts.size(); ++k) {
    values.push_back({{"x", AxisValue(x_, edges[k])}, {"x2", AxisValue(x_, edges[k + 1])}, {"y", 0},
                      {"y2", Num(counts[k])}, {"tip", std::to_string(static_cast<long>(counts[k]))}});
  }
  Add({{"data", {{"values", values}}},
       {"mark", {{"type", "rect"}, {"opacity", opacity}}},
       {"encoding",
        {{"x", XEnc()}, {"x2", {{"field", "x2"}}}, {"y", YEnc()}, {"y2", {{"field", "y2"}}},
         {"color", ColorEnc(name, color)}, {"tooltip", {{"field", "tip"}, {"title", "count"}}}}}},
      name, true);
}

void Plot::VLine(double x, const std::string& label, const Stroke& stroke) {
  if (!std::isfinite(x)) return;
  const int row = vline_rows_++ % 4;
  json values = json::array({{{"x", AxisValue(x_, x)}, {"label", label}}});
  json mark = {{"type", "rule"}, {"color", stroke.color}, {"strokeWidth", stroke.width}, {"opacity", stroke.opacity}};
  if (!stroke.dash.empty()) mark["strokeDash"] = Dash(stroke.dash);
  Add({{"data", {{"values", values}}}, {"mark", mark},
       {"encoding", {{"x", XEnc()}, {"tooltip", {{"field", "label"}}}}}},
      "", true);
  Add({{"data", {{"values", values}}},
       {"mark", {{"type", "text"}, {"align", "left"}, {"baseline", "top"}, {"dx", 3}, {"fontSize", 11},
                 {"color", stroke.color}}},
       {"encoding", {{"x", XEnc()}, {"y", {{"value", 4 + 13 * row}}}, {"text", {{"field", "label"}}}}}},
      "");
}

void Plot::HLine(double y, const std::string& label, const Stroke& stroke) {
  if (!std::isfinite(y)) return;
  json values = json::array({{{"y", AxisValue(y_, y)}, {"label", label}}});
  json mark = {{"type", "rule"}, {"color", stroke.color}, {"strokeWidth", stroke.width}, {"opacity", stroke.opacity}};
  if (!stroke.dash.empty()) mark["strokeDash"] = Dash(stroke.dash);
  Add({{"data", {{"values", values}}}, {"mark", mark},
       {"encoding", {{"y", YEnc()}, {"tooltip", {{"field", "label"}}}}}},
      "", true);
  Add({{"data", {{"values", values}}},
       {"mark", {{"type", "text"}, {"align", "right"}, {"baseline", "bottom"}, {"dx", -3}, {"dy", -2},
                 {"fontSize", 11}, {"color", stroke.color}}},
       {"encoding", {{"y", YEnc()}, {"x", {{"value", "width"}}}, {"text", {{"field", "label"}}}}}},
      "");
}

void Plot::Text(double x, double y, const std::string& text, const std::string& anchor, const std::string& color) {
  const std::string align = anchor == "start" ? "left" : anchor == "end" ? "right" : "center";
  Add({{"data", {{"values", json::array({{{"x", AxisValue(x_, x)}, {"y", AxisValue(y_, y)}, {"label", text}}})}}},
       {"mark", {{"type", "text"}, {"align", align}, {"fontSize", 11}, {"color", color}}},
       {"encoding", {{"x", XEnc()}, {"y", YEnc()}, {"text", {{"field", "label"}}}}}},
      "");
}

void Plot::LegendEntry(const std::string& name, const std::string& color, bool /*filled*/) { AddLegend(name, color); }

std::string Plot::Spec() const {
  json spec = {{"width", width_},
               {"height", height_},
               {"autosize", {{"type", "fit"}, {"contains", "padding"}}},
               {"padding", {{"left", std::max(5.0, min_left_ - 60)}, {"right", 10}, {"top", 5}, {"bottom", 5}}}};
  json title = {{"text", title_}, {"anchor", "start"}, {"fontSize", 14}};
  if (!caption_.empty()) {
    title["subtitle"] = Wrap(caption_, static_cast<size_t>(std::max(40, width_ / 6)));
    title["subtitleFontSize"] = 11;
    title["subtitleColor"] = "#555";
  }
  spec["title"] = title;
  json domain = json::array(), range = json::array();
  for (const auto& [name, color] : legend_) {
    domain.push_back(name);
    range.push_back(color);
  }
  json layers = json::array();
  bool zoom = false;
  for (const Layer& l : layers_) {
    json layer = l.spec;
    json& enc = layer["encoding"];
    // The axes as they are now (a section may set a range after adding the marks).
    if (enc.contains("x") && enc["x"].contains("field")) enc["x"] = XEnc();
    if (enc.contains("y") && enc["y"].contains("field")) enc["y"] = YEnc();
    if (enc.contains("color") && enc["color"].contains("field")) {
      enc["color"]["scale"] = {{"domain", domain}, {"range", range}};
      enc["color"]["legend"] = {{"title", nullptr}, {"orient", "bottom"}, {"direction", "horizontal"},
                                {"columns", std::max<size_t>(1, std::min<size_t>(legend_.size(), width_ >= 900 ? 3 : width_ >= 500 ? 2 : 1))},
                                {"labelLimit", 400}, {"labelFontSize", 11}};
    }
    if (run_) {
      // Every mark of the run view stands for its run: its fields by calculation, not per row.
      json calc = json::array();
      const json row = RunRow(*run_);
      for (const auto& [key, value] : row.items()) calc.push_back({{"calculate", value.dump()}, {"as", key}});
      if (layer.contains("transform")) {
        for (const json& t : layer["transform"]) calc.push_back(t);
      }
      layer["transform"] = calc;
      if (!l.tip) {
        json extra = json::array();
        if (!l.name.empty()) extra.push_back({{"field", "series"}, {"title", "series"}});
        enc["tooltip"] = RunTooltip(json::array({row}), run_->magnitude_key, extra);
      }
    }
    // Zoom and pan on the first layer with both axes: the layers share their scales.
    if (!zoom && enc.contains("x") && enc["x"].contains("field") && enc.contains("y") && enc["y"].contains("field")) {
      layer["params"] = json::array({{{"name", "zoom"}, {"select", "interval"}, {"bind", "scales"}}});
      zoom = true;
    }
    layers.push_back(std::move(layer));
  }
  if (layers.empty()) {
    // Nothing drawn: the axes alone, so the plot says what it would show.
    layers.push_back({{"data", {{"values", json::array()}}},
                      {"mark", "point"},
                      {"encoding", {{"x", XEnc()}, {"y", YEnc()}}}});
  }
  spec["layer"] = layers;
  spec["config"] = {{"view", {{"stroke", "#ddd"}}}, {"axis", {{"gridColor", "#eee"}}}};
  return SafeDump(spec);
}

std::string Plot::Render() const {
  // Spec() is already safe text: wrap it without parsing it again.
  return "<div class=\"plot\" id=\"" + report::Escape(id_) + "\" style=\"width:" + std::to_string(width_) +
         "px;min-height:" + std::to_string(height_) +
         "px\"></div><script type=\"application/json\" class=\"vega-spec\" data-plot=\"" + report::Escape(id_) + "\">" +
         Spec() + "</script>";
}

std::string HeatMap::Spec() const {
  json values = json::array();
  for (size_t r = 0; r < rows.size(); ++r) {
    long total = 0;
    for (size_t c = 0; c < cols.size(); ++c) total += r < counts.size() && c < counts[r].size() ? counts[r][c] : 0;
    for (size_t c = 0; c < cols.size(); ++c) {
      const long n = r < counts.size() && c < counts[r].size() ? counts[r][c] : 0;
      const double share = total > 0 ? static_cast<double>(n) / static_cast<double>(total) : 0;
      char pct[32];
      std::snprintf(pct, sizeof pct, "%.1f", 100 * share);
      values.push_back({{"row", rows[r]},
                        {"col", cols[c]},
                        {"count", n},
                        {"share", Num(share)},
                        {"tip", row_axis + " " + rows[r] + ", " + col_axis + " " + cols[c] + ": " + std::to_string(n) +
                                    " runs (" + pct + " % of the row)"}});
    }
  }
  const int width = 190 + 92 * static_cast<int>(cols.size());
  const int height = 130 + 36 * static_cast<int>(rows.size());
  json x = {{"field", "col"}, {"type", "ordinal"}, {"sort", cols},
            {"axis", {{"title", col_axis}, {"orient", "top"}, {"labelAngle", 0}, {"labelLimit", 120}}}};
  json y = {{"field", "row"}, {"type", "ordinal"}, {"sort", rows}, {"axis", {{"title", row_axis}, {"labelLimit", 200}}}};
  json spec = {{"width", width},
               {"height", height},
               {"autosize", {{"type", "fit"}, {"contains", "padding"}}},
               {"data", {{"values", values}}},
               {"encoding", {{"x", x}, {"y", y}}}};
  json head = {{"text", title}, {"anchor", "start"}, {"fontSize", 14}};
  if (!caption.empty()) {
    head["subtitle"] = Wrap(caption, static_cast<size_t>(std::max(40, width / 6)));
    head["subtitleFontSize"] = 11;
    head["subtitleColor"] = "#555";
  }
  spec["title"] = head;
  spec["layer"] = json::array(
      {{{"mark", {{"type", "rect"}, {"stroke", "#fff"}}},
        {"encoding",
         {{"color", {{"field", "share"}, {"type", "quantitative"}, {"scale", {{"scheme", "blues"}, {"domain", {0, 1}}}},
                     {"legend", nullptr}}},
          {"tooltip", {{"field", "tip"}}}}}},
       {{"mark", {{"type", "text"}, {"fontSize", 12}}},
        {"encoding",
         {{"text", {{"field", "count"}, {"type", "quantitative"}}},
          {"color", {{"condition", {{"test", "datum.share > 0.55"}, {"value", "#fff"}}}, {"value", "#222"}}},
          {"tooltip", {{"field", "tip"}}}}}}});
  return SafeDump(spec);
}

std::string HeatMap::Render() const {
  const int width = 190 + 92 * static_cast<int>(cols.size());
  const int height = 130 + 36 * static_cast<int>(rows.size());
  return "<div class=\"plot\" id=\"" + report::Escape(id) + "\" style=\"width:" + std::to_string(width) +
         "px;min-height:" + std::to_string(height) +
         "px\"></div><script type=\"application/json\" class=\"vega-spec\" data-plot=\"" + report::Escape(id) + "\">" +
         Spec() + "</script>";
}

const char* ReportPlotScript() {
  return R"js((function () {
  var campaign = document.body.getAttribute('data-campaign') || 'campaign.json';
  var status = document.getElementById('copy-status');
  function quote(s) {
    s = String(s);
    return /^[A-Za-z0-9_.\/:=+@%,-]+$/.test(s) ? s : "'" + s.replace(/'/g, "'\\''") + "'";
  }
  function say(text) {
    if (!status) return;
    status.textContent = text;
    status.style.display = 'block';
    clearTimeout(say.timer);
    say.timer = setTimeout(function () { status.style.display = 'none'; }, 4000);
  }
  function fallback(text) {
    var t = document.createElement('textarea');
    t.value = text;
    t.setAttribute('readonly', '');
    t.style.position = 'fixed';
    t.style.opacity = '0';
    document.body.appendChild(t);
    t.select();
    var ok = false;
    try { ok = document.execCommand('copy'); } catch (e) { ok = false; }
    document.body.removeChild(t);
    if (ok) say('Copied: ' + text); else window.prompt('Copy this command:', text);
  }
  function copy(text) {
    if (navigator.clipboard && window.isSecureContext) {
      navigator.clipboard.writeText(text).then(function () { say('Copied: ' + text); },
                                               function () { fallback(text); });
    } else {
      fallback(text);
    }
  }
  var specs = document.querySelectorAll('script.vega-spec');
  for (var k = 0; k < specs.length; ++k) {
    (function (script) {
      // The plot's <div> is the element just before its spec (its id may also be a section's).
      var el = script.previousElementSibling;
      if (!el || el.id !== script.getAttribute('data-plot')) return;
      vegaEmbed(el, JSON.parse(script.textContent), {actions: false, renderer: 'svg', mode: 'vega-lite'}).then(function (result) {
        el.setAttribute('data-rendered', 'true');
        result.view.addEventListener('click', function (event, item) {
          var d = item && item.datum;
          if (!d || !d.run) return;
          copy('armfault trace ' + quote(campaign) + ' --run ' + quote(d.run) + ' -o ' +
               quote(String(d.run).replace(/[^A-Za-z0-9_.-]+/g, '_') + '.csv'));
        });
      }).catch(function (e) {
        el.setAttribute('data-rendered', 'failed');
        el.textContent = 'This plot could not be drawn: ' + e;
      });
    })(specs[k]);
  }
})();
)js";
}

}  // namespace armfault::vega
