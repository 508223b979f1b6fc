// The report's Vega-Lite plot specs (reports/page/vega_plot.h): what each drawn element becomes,
// that numbers are rounded and NaN breaks a line, that axes keep their settings, that runs are
// named for tooltips and clicks, that the spec cannot close its <script>, and the heat map.
#include "reports/page/vega_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>

namespace armfault::vega {
namespace {

using nlohmann::json;
using testing::HasSubstr;
using testing::Not;

json Layer(const json& spec, size_t k) { return spec.at("layer").at(k); }

TEST(VegaPlot, LineIsOneLayerWithRoundedNumbersAndNullForNaN) {
  Plot p("p", "title");
  p.Line("series", {0, 1, 2}, {0.123456789, std::nan(""), 2}, Stroke{"#123456", 2, "5 3", 1});
  const json spec = json::parse(p.Spec());
  ASSERT_EQ(spec.at("layer").size(), 1u);
  const json l = Layer(spec, 0);
  EXPECT_EQ(l["mark"]["type"], "line");
  EXPECT_EQ(l["mark"]["strokeDash"], json({5.0, 3.0}));
  EXPECT_EQ(l["data"]["values"][0]["y"], 0.123457);
  EXPECT_TRUE(l["data"]["values"][1]["y"].is_null());  // breaks the line
  // Named: a legend entry with its colour.
  EXPECT_EQ(l["encoding"]["color"]["scale"]["domain"], json({"series"}));
  EXPECT_EQ(l["encoding"]["color"]["scale"]["range"], json({"#123456"}));
  // Zoom: an interval selection bound to the scales.
  EXPECT_EQ(l["params"][0]["bind"], "scales");
  EXPECT_EQ(p.Spec(), p.Spec());
}

TEST(VegaPlot, UnsortedLineKeepsItsOrder) {
  Plot p("p", "t");
  p.Line("", {2, 1, 3}, {0, 1, 2}, Stroke{});
  const json l = Layer(json::parse(p.Spec()), 0);
  EXPECT_EQ(l["encoding"]["order"]["field"], "i");
  EXPECT_EQ(l["data"]["values"][1]["i"], 1);
  EXPECT_EQ(l["encoding"]["color"], json({{"value", "#1f77b4"}}));  // unnamed: no legend
}

TEST(VegaPlot, AxesKeepRangeLogReversalAndCategories) {
  Plot p("p", "t");
  p.x().log = true;
  p.x().min = 0.01;
  p.x().label = "latency (s)";
  p.y().categories = {"a", "b"};
  p.y().reversed = true;
  p.Points("", {0.0, 1.0}, {0, 1}, {}, {}, "#000");
  const json l = Layer(json::parse(p.Spec()), 0);
  EXPECT_EQ(l["encoding"]["x"]["scale"]["type"], "log");
  EXPECT_EQ(l["encoding"]["x"]["scale"]["domainMin"], 0.01);
  EXPECT_EQ(l["encoding"]["x"]["axis"]["title"], "latency (s)");
  EXPECT_EQ(l["data"]["values"][0]["x"], 0.01);  // 0 on a log axis: at its minimum
  EXPECT_EQ(l["encoding"]["y"]["scale"]["reverse"], true);
  EXPECT_EQ(l["encoding"]["y"]["scale"]["domain"], json({-0.5, 1.5}));
  EXPECT_EQ(l["encoding"]["y"]["axis"]["labelExpr"], "[\"a\",\"b\"][datum.value]");
}

TEST(VegaPlot, PointsOfRunsNameTheRunInRowsAndTooltip) {
  Plot p("p", "t");
  p.Points("runs", {0.5}, {1}, {}, {}, "#000", Marker::kSquare, {"detected"}, 3,
           {RunRef{"exp/kt#0/j3/r0", "kt_degradation", 3, 0.5, "kt_factor"}});
  const json l = Layer(json::parse(p.Spec()), 0);
  const json row = l["data"]["values"][0];
  EXPECT_EQ(row["run"], "exp/kt#0/j3/r0");
  EXPECT_EQ(row["family"], "kt_degradation");
  EXPECT_EQ(row["joint"], 3);
  EXPECT_EQ(row["magnitude"], 0.5);
  EXPECT_EQ(l["mark"]["shape"], "square");
  std::vector<std::string> fields;
  for (const json& t : l["encoding"]["tooltip"]) fields.push_back(t["field"]);
  EXPECT_EQ(fields, (std::vector<std::string>{"run", "family", "joint", "magnitude", "tip"}));
  EXPECT_EQ(l["encoding"]["tooltip"][3]["title"], "kt_factor");
}

TEST(VegaPlot, ErrorBarsSegmentsAndMarkersAreLayers) {
  Plot p("p", "t");
  p.Points("f", {1, 2}, {0.5, 0.6}, {0.4, 0.5}, {0.6, 0.7}, "#000");
  p.Segments("w", {0}, {1}, {0.3}, Stroke{}, Marker::kCircle);
  p.VLine(1.5, "onset", Stroke{"#d62728"});
  p.HLine(0.9, "90 %", Stroke{});
  const json spec = json::parse(p.Spec());
  std::vector<std::string> marks;
  for (const json& l : spec["layer"]) marks.push_back(l["mark"]["type"]);
  EXPECT_EQ(marks, (std::vector<std::string>{"rule", "point", "rule", "point", "rule", "text", "rule", "text"}));
  EXPECT_EQ(Layer(spec, 0)["data"]["values"][0]["y2"], 0.6);      // error bar to hi
  EXPECT_EQ(Layer(spec, 2)["data"]["values"][0]["x2"], 1);        // the window's span
  EXPECT_EQ(Layer(spec, 5)["data"]["values"][0]["label"], "onset");
}

TEST(VegaPlot, TheRunViewNamesItsRunInEveryLayer) {
  Plot p("p", "t");
  p.set_run(RunRef{"r1", "kt_degradation", 2, std::nullopt, ""});
  p.Line("current", {0, 1}, {0, 1}, Stroke{});
  p.VLine(0.5, "alarm", Stroke{});
  for (const json& l : json::parse(p.Spec())["layer"]) {
    const json& t = l["transform"];
    EXPECT_NE(std::find(t.begin(), t.end(), json({{"calculate", "\"r1\""}, {"as", "run"}})), t.end()) << l.dump();
    EXPECT_TRUE(l["encoding"].contains("tooltip"));
  }
}

TEST(VegaPlot, SpecCannotCloseItsScript) {
  Plot p("p", "</script><script>alert(1)</script>");
  p.Text(0, 0, "<b>");
  const std::string html = p.Render();
  EXPECT_THAT(p.Spec(), Not(HasSubstr("<")));
  EXPECT_EQ(json::parse(p.Spec())["title"]["text"], "</script><script>alert(1)</script>");
  EXPECT_THAT(html, HasSubstr("<div class=\"plot\" id=\"p\""));
  EXPECT_THAT(html, HasSubstr("<script type=\"application/json\" class=\"vega-spec\" data-plot=\"p\">"));
}

TEST(VegaHeatMap, OneCellPerCountWithItsShare) {
  HeatMap h;
  h.id = "confusion";
  h.rows = {"a", "b"};
  h.cols = {"x", "y"};
  h.counts = {{3, 1}, {0, 0}};
  h.row_axis = "true";
  h.col_axis = "named";
  const json spec = json::parse(h.Spec());
  const json& v = spec["data"]["values"];
  ASSERT_EQ(v.size(), 4u);
  EXPECT_EQ(v[0]["row"], "a");
  EXPECT_EQ(v[0]["col"], "x");
  EXPECT_EQ(v[0]["count"], 3);
  EXPECT_EQ(v[0]["share"], 0.75);
  EXPECT_EQ(v[3]["share"], 0);
  EXPECT_THAT(v[1]["tip"].get<std::string>(), HasSubstr("true a, named y: 1 runs (25.0 % of the row)"));
}

}  // namespace
}  // namespace armfault::vega
