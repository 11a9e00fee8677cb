#include "html_report.hpp"

#include <gtest/gtest.h>

namespace pitchlab::mission {
namespace {

TEST(Base64, MatchesRfc4648TestVectors) {
  EXPECT_EQ(Base64(""), "");
  EXPECT_EQ(Base64("f"), "Zg==");
  EXPECT_EQ(Base64("fo"), "Zm8=");
  EXPECT_EQ(Base64("foo"), "Zm9v");
  EXPECT_EQ(Base64("foob"), "Zm9vYg==");
  EXPECT_EQ(Base64("fooba"), "Zm9vYmE=");
  EXPECT_EQ(Base64("foobar"), "Zm9vYmFy");
  EXPECT_EQ(Base64(std::string("\xff\x00\x80", 3)), "/wCA");
}

std::size_t Count(const std::string& text, const std::string& what) {
  std::size_t n = 0;
  for (std::size_t at = text.find(what); at != std::string::npos; at = text.find(what, at + 1)) ++n;
  return n;
}

TEST(HtmlReport, IsSelfContainedAndEscapesText) {
  HtmlReport report("run <1>");
  report.KeyValues({{"reason", "goal & more"}});
  report.Png(std::string("\x89PNG\r\n", 6), "map", 600, "elevation.png");
  report.Plot({{"estimated", "#c00", {{0, 0}, {1, 1}}, false}}, "trajectory");
  const std::string html = report.Render();
  EXPECT_NE(html.find("<title>run &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("goal &amp; more"), std::string::npos);
  EXPECT_NE(html.find("src=\"data:image/png;base64,iVBORw0K\""), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  // Nothing to fetch: no external sources (the SVG namespace is a name, not a fetch) and every
  // script inline.
  EXPECT_EQ(html.find("http://", html.find("<body>")), html.find("http://www.w3.org/2000/svg"));
  EXPECT_EQ(html.find("https://"), std::string::npos);
  EXPECT_EQ(html.find("<script src"), std::string::npos);
  EXPECT_EQ(Count(html, "<script>"), Count(html, "</script>"));
}

TEST(HtmlReport, PicturesLinkTheirFileAndOpenFullSize) {
  HtmlReport report("t");
  report.Png("png", "the map", 600, "elevation.png");
  report.PngStrip({{"a", "stop 0", "stops/000/map.png"}}, 240);
  report.PngStrip({{"b", "stop 1", ""}}, 240);
  const std::string html = report.Render();
  EXPECT_NE(html.find("<a href=\"elevation.png\">elevation.png</a>"), std::string::npos);
  EXPECT_NE(html.find("<a href=\"stops/000/map.png\">stop 0</a>"), std::string::npos);
  // The thumbnail links its full-size file, which the lightbox opens.
  EXPECT_NE(html.find("<a href=\"stops/000/map.png\"><img class=zoom"), std::string::npos);
  EXPECT_NE(html.find("<figure><img class=zoom alt=\"stop 1\""), std::string::npos);
  EXPECT_EQ(Count(html, "<img class=zoom"), 3u);  // the lightbox script opens class=zoom
  EXPECT_NE(html.find("id=lightbox"), std::string::npos);
  EXPECT_NE(html.find("style=\"width:600px\""), std::string::npos);
}

TEST(HtmlReport, PlotHasAxesInMetresAndMarkers) {
  HtmlReport report("t");
  report.Plot({{"true", "#00f", {{-3, 0}, {4, 2}}, true}}, "trajectories",
              {{"goal", "#d01010", {4, 2}}});
  const std::string html = report.Render();
  EXPECT_NE(html.find(">x [m]</text>"), std::string::npos);
  EXPECT_NE(html.find(">y [m]</text>"), std::string::npos);
  // A 7.7 m span (7 m and 10 % around): ticks every 2 m, zero and the negative side labelled.
  EXPECT_NE(html.find("text-anchor=\"middle\">-2</text>"), std::string::npos);
  EXPECT_NE(html.find("text-anchor=\"middle\">0</text>"), std::string::npos);
  EXPECT_NE(html.find("text-anchor=\"middle\">4</text>"), std::string::npos);
  EXPECT_NE(html.find("<circle"), std::string::npos);
  EXPECT_NE(html.find("goal</text>"), std::string::npos);
}

TEST(HtmlReport, DetailsFoldTheirContent) {
  HtmlReport report("t");
  report.BeginDetails("all metrics");
  report.Preformatted("{\"a\": 1}");
  report.EndDetails();
  const std::string html = report.Render();
  const std::size_t open = html.find("<details><summary>all metrics</summary>");
  ASSERT_NE(open, std::string::npos);
  EXPECT_LT(open, html.find("<pre>{&quot;a&quot;: 1}</pre>"));
  EXPECT_LT(html.find("<pre>{&quot;a&quot;"), html.find("</details>"));
  EXPECT_THROW(report.EndDetails(), std::logic_error);
}

TEST(HtmlReport, RejectsARaggedTable) {
  HtmlReport report("t");
  EXPECT_THROW(report.Table({"a", "b"}, {{"1"}}), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mission
