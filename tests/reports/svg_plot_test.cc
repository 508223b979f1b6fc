// The SVG plotting helper: escaping, deterministic numbers, ticks, data paths, stacked marker
// labels, legends and the heat map's cells.
#include "reports/svg_plot.h"

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <regex>

namespace armfault::svg {
namespace {

using testing::HasSubstr;
using testing::Not;

int Count(const std::string& text, const std::string& what) {
  int n = 0;
  for (size_t p = text.find(what); p != std::string::npos; p = text.find(what, p + 1)) ++n;
  return n;
}

TEST(SvgEscape, EscapesMarkupAndQuotes) {
  EXPECT_EQ(Escape("<b a=\"1\">Tom & 'Jerry'</b>"), "&lt;b a=&quot;1&quot;&gt;Tom &amp; &#39;Jerry&#39;&lt;/b&gt;");
  EXPECT_EQ(Escape("η_m ≥ 0.9"), "η_m ≥ 0.9");  // UTF-8 passes through
  EXPECT_EQ(Escape(std::string("a\x01" "b")), "a?b");
}

TEST(SvgFixed, IsDeterministicAndHasNoNegativeZero) {
  EXPECT_EQ(Fixed(0.5, 2), "0.50");
  EXPECT_EQ(Fixed(-0.0001, 2), "0.00");
  EXPECT_EQ(Fixed(-1.25, 1), "-1.2");  // round half to even in binary: -1.25 is exact, printf rounds to even
  EXPECT_EQ(Fixed(1234.5678, 0), "1235");
  EXPECT_EQ(Fixed(NAN, 2), "nan");
  EXPECT_EQ(Fixed(-INFINITY, 2), "-inf");
}

TEST(SvgTextWidth, GrowsWithLengthAndCountsUtf8Once) {
  EXPECT_GT(TextWidth("kt_degradation", 11), TextWidth("kt", 11));
  EXPECT_DOUBLE_EQ(TextWidth("η", 10), TextWidth("n", 10));
}

TEST(SvgPlot, DrawsLinesPointsAndBandsAsNonEmptyDataPaths) {
  Plot p("p1", "A <title>", 500, 300);
  p.x().label = "time (s)";
  p.y().label = "current (A)";
  p.Line("line", {0, 1, 2}, {0, 1, 4}, Stroke{"#123456", 2, "", 1});
  p.Points("points", {0.5, 1.5}, {1, 2}, {0.5, 1.5}, {1.5, 2.5}, "#abcdef", Marker::kSquare, {"first", "second"});
  p.Band("band", {0, 2}, {0, 1}, {1, 3}, "#00ff00");
  const std::string s = p.Render();
  EXPECT_THAT(s, testing::StartsWith("<svg id=\"p1\" class=\"plot\""));
  EXPECT_THAT(s, HasSubstr("A &lt;title&gt;"));
  EXPECT_THAT(s, Not(HasSubstr("A <title>")));
  EXPECT_THAT(s, HasSubstr(">time (s)</text>"));
  EXPECT_THAT(s, HasSubstr(">current (A)</text>"));
  EXPECT_EQ(Count(s, "class=\"data line\" d=\"M"), 1);
  EXPECT_EQ(Count(s, "class=\"data point\" d=\"M"), 2);
  EXPECT_EQ(Count(s, "class=\"data errorbar\" d=\"M"), 2);
  EXPECT_EQ(Count(s, "class=\"data band\" d=\"M"), 1);
  EXPECT_THAT(s, HasSubstr("<title>first</title>"));
  // Legend: one entry per named series.
  EXPECT_THAT(s, HasSubstr(">line</text>"));
  EXPECT_THAT(s, HasSubstr(">points</text>"));
  EXPECT_THAT(s, HasSubstr(">band</text>"));
  // Nothing external: an inline SVG needs no namespace URL.
  EXPECT_THAT(s, Not(HasSubstr("http")));
  EXPECT_EQ(s, p.Render());
}

TEST(SvgPlot, NaNBreaksALine) {
  Plot p("p2", "t");
  p.Line("", {0, 1, 2, 3}, {0, 1, NAN, 2}, Stroke{});
  const std::string s = p.Render();
  const std::smatch m = [&] {
    std::smatch r;
    std::regex_search(s, r, std::regex("class=\"data line\" d=\"([^\"]*)\""));
    return r;
  }();
  ASSERT_FALSE(m.empty());
  EXPECT_EQ(Count(m[1].str(), "M"), 2);
  EXPECT_EQ(Count(m[1].str(), "L"), 1);
}

TEST(SvgPlot, AutoRangeHasNiceTicks) {
  Plot p("p3", "t");
  p.Line("", {0, 1}, {0.03, 0.97}, Stroke{});
  const std::string s = p.Render();
  for (const char* tick : {">0.0<", ">0.2<", ">0.4<", ">0.6<", ">0.8<", ">1.0<"}) EXPECT_THAT(s, HasSubstr(tick));
}

TEST(SvgPlot, LogAxisHasDecadeTicks) {
  Plot p("p4", "t");
  p.x().log = true;
  p.Points("", {0.004, 0.5, 7}, {1, 2, 3}, {}, {}, "#000");
  const std::string s = p.Render();
  for (const char* tick : {">0.001<", ">0.01<", ">0.1<", ">1<", ">10<"}) EXPECT_THAT(s, HasSubstr(tick));
}

TEST(SvgPlot, CategoricalAxisLabelsTheSlots) {
  Plot p("p5", "t");
  p.x().categories = {"supply", "ground", "open & <x>"};
  p.Points("", {0, 1, 2}, {1, 1, 0.5}, {}, {}, "#000");
  const std::string s = p.Render();
  EXPECT_THAT(s, HasSubstr(">supply<"));
  EXPECT_THAT(s, HasSubstr(">open &amp; &lt;x&gt;<"));
}

TEST(SvgPlot, MarkerLabelsAreStackedInRows) {
  Plot p("p6", "t");
  p.Line("", {0, 10}, {0, 1}, Stroke{});
  p.VLine(2.0, "fault onset", Stroke{"#d62728", 1.5, "", 1});
  p.VLine(2.1, "first alarm", Stroke{"#000", 1.5, "", 1});
  const std::string s = p.Render();
  std::smatch a, b;
  ASSERT_TRUE(std::regex_search(s, a, std::regex("y=\"([0-9.]+)\"[^>]*>fault onset<")));
  ASSERT_TRUE(std::regex_search(s, b, std::regex("y=\"([0-9.]+)\"[^>]*>first alarm<")));
  EXPECT_GE(std::stod(b[1].str()) - std::stod(a[1].str()), 12.0);
  EXPECT_EQ(Count(s, "class=\"marker vline\""), 2);
}

TEST(SvgHeatMap, OneCellPerCountWithItsValue) {
  HeatMap h;
  h.id = "cm";
  h.title = "confusion";
  h.row_axis = "true";
  h.col_axis = "isolated";
  h.rows = {"a<b", "healthy"};
  h.cols = {"a<b", "healthy", "unknown"};
  h.counts = {{3, 1, 0}, {0, 7, 2}};
  const std::string s = h.Render();
  EXPECT_EQ(Count(s, "class=\"data cell\""), 6);
  EXPECT_THAT(s, HasSubstr("data-row=\"a&lt;b\" data-col=\"a&lt;b\" data-count=\"3\""));
  EXPECT_THAT(s, HasSubstr("data-row=\"healthy\" data-col=\"unknown\" data-count=\"2\""));
  EXPECT_THAT(s, HasSubstr("<title>true healthy, isolated as healthy: 7 of 9 runs (77.8 %)</title>"));
  EXPECT_EQ(s, h.Render());
}

}  // namespace
}  // namespace armfault::svg
