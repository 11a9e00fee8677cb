#include "html_report.hpp"

#include <gtest/gtest.h>

namespace pitchlab::apps {
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

TEST(HtmlReport, IsSelfContainedAndEscapesText) {
  HtmlReport report("run <1>");
  report.KeyValues({{"reason", "goal & more"}});
  report.Png(std::string("\x89PNG\r\n", 6), "map");
  report.Plot({{"estimated", "#c00", {{0, 0}, {1, 1}}, false}}, "trajectory");
  const std::string html = report.Render();
  EXPECT_NE(html.find("<title>run &lt;1&gt;</title>"), std::string::npos);
  EXPECT_NE(html.find("goal &amp; more"), std::string::npos);
  EXPECT_NE(html.find("src=\"data:image/png;base64,iVBORw0K\""), std::string::npos);
  EXPECT_NE(html.find("<svg"), std::string::npos);
  // Nothing to fetch: no external sources, no scripts.
  EXPECT_EQ(html.find("http://", html.find("<body>")), html.find("http://www.w3.org/2000/svg"));
  EXPECT_EQ(html.find("<script"), std::string::npos);
}

TEST(HtmlReport, RejectsARaggedTable) {
  HtmlReport report("t");
  EXPECT_THROW(report.Table({"a", "b"}, {{"1"}}), std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::apps
