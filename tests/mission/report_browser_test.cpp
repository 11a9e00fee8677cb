// report.html in a real browser (Debian's chromium, headless, software WebGL): what a reader sees
// at 1366 and 1920 px, checked in the page's layout and in the screenshot's pixels, and the 3D
// view checked by what it drew. Skipped only when chromium is not installed.
#include <array>
#include <cstdio>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "png_pixels.hpp"
#include "run_report.hpp"
#include "scoped_temp_dir.hpp"
#include "synthetic_report.hpp"

#ifndef PITCHLAB_CHROMIUM
#define PITCHLAB_CHROMIUM ""
#endif

namespace pitchlab::mission {
namespace {

namespace fs = std::filesystem;

constexpr int kHeight_px = 900;  // a laptop's first screen

// The page reports its own layout: the outcome's text boxes (their text, not their blocks, so a
// reason pushed off screen shows), the viewport and the page's scroll width.
constexpr const char* kLayoutProbe = R"JS(<script>
addEventListener('load', function () {
  function text(selector) {
    var range = document.createRange();
    range.selectNodeContents(document.querySelector(selector));
    var r = range.getBoundingClientRect();
    return [r.left, r.top, r.right, r.bottom];
  }
  var probe = {
    headline: text('#outcome .headline'), reason: text('#outcome .reason'),
    width: innerWidth, height: innerHeight,
    scroll_width: document.documentElement.scrollWidth};
  document.body.setAttribute('data-probe', JSON.stringify(probe));
  // A click on a stop's thumbnail opens its full-size file over the page.
  var thumb = document.querySelector('.strip img.zoom'), box = document.getElementById('lightbox');
  var big = box.querySelector('img');
  big.addEventListener('load', function () {
    document.body.setAttribute('data-lightbox', JSON.stringify({
      display: getComputedStyle(box).display, src: big.src, width: big.naturalWidth,
      thumb_width: thumb.naturalWidth}));
  });
  thumb.click();
});
</script>)JS";

std::string Slurp(const fs::path& file) {
  std::ifstream in(file, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

// The value of `attribute` on the element with `id` in chromium's --dump-dom output.
std::string Attribute(const std::string& dom, const std::string& id, const std::string& attribute) {
  const std::size_t element = dom.find("id=\"" + id + "\"");
  if (element == std::string::npos) return "";
  const std::size_t end = dom.find('>', element);
  const std::size_t at = dom.find(attribute + "=\"", element);
  if (at == std::string::npos || at > end) {
    // Attributes may come before the id.
    const std::size_t open = dom.rfind('<', element);
    const std::size_t before = dom.find(attribute + "=\"", open);
    if (before == std::string::npos || before > end) return "";
    return dom.substr(before + attribute.size() + 2,
                      dom.find('"', before + attribute.size() + 2) - before - attribute.size() - 2);
  }
  return dom.substr(at + attribute.size() + 2,
                    dom.find('"', at + attribute.size() + 2) - at - attribute.size() - 2);
}

std::string Unescape(std::string s) {
  for (const auto& [from, to] :
       {std::pair<std::string, std::string>{"&quot;", "\""}, {"&amp;", "&"}}) {
    for (std::size_t at = s.find(from); at != std::string::npos; at = s.find(from, at + 1))
      s.replace(at, from.size(), to);
  }
  return s;
}

using test_support::ReadPng;
using test_support::Rgb8;

// Chromium on the page; returns its standard output, its standard error in `err`.
std::string RunChromium(const fs::path& page, const fs::path& profile, int width_px,
                        const std::string& mode, std::string* err) {
  const fs::path log = page.parent_path() / "chromium.log";
  // Software WebGL (SwiftShader): the same pixels on any machine, no GPU needed. A fresh
  // profile per test suite: two chromiums never share one.
  const std::string command =
      "timeout 180 '" + std::string(PITCHLAB_CHROMIUM) +
      "' --headless --no-sandbox --enable-unsafe-swiftshader --use-angle=swiftshader "
      "--no-first-run --user-data-dir='" +
      profile.string() + "' --window-size=" + std::to_string(width_px) + "," +
      std::to_string(kHeight_px) + " --virtual-time-budget=5000 --enable-logging=stderr --v=0 " +
      mode + " 'file://" + page.string() + "' 2>'" + log.string() + "'";
  std::string out;
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  char buf[65536];
  for (std::size_t n; pipe && (n = std::fread(buf, 1, sizeof(buf), pipe.get())) > 0;)
    out.append(buf, n);
  *err = Slurp(log);
  return out;
}

// One browser run per width and one screenshot for the whole suite (each costs seconds); the
// tests read their results.
class ReportInBrowser : public ::testing::Test {
 protected:
  struct Seen {
    std::string dom, err;
  };
  static void SetUpTestSuite() {
    if (std::string(PITCHLAB_CHROMIUM).empty() || !fs::exists(PITCHLAB_CHROMIUM)) return;
    dir_ = new test_support::ScopedTempDir("report_browser");
    const Result<ThreeJs> three = LoadThreeJs(DefaultThreeJsDir());
    if (!three) {
      three_error_ = new std::string(three.error().message);
      return;
    }
    std::string html = RenderRunReport(testing::SyntheticReport(dir_->path()), three);
    std::ofstream(*dir_ / "report.html", std::ios::binary) << html;
    html.insert(html.rfind("</body>"), kLayoutProbe);
    std::ofstream(*dir_ / "probed.html", std::ios::binary) << html;
    seen_ = new std::map<int, Seen>;
    for (int width : {1366, 1920}) {
      Seen& s = (*seen_)[width];
      s.dom = RunChromium(*dir_ / "probed.html", *dir_ / "profile", width, "--dump-dom", &s.err);
    }
    std::string err;
    RunChromium(*dir_ / "report.html", *dir_ / "profile", 1366,
                "--screenshot='" + (*dir_ / "shot.png").string() + "'", &err);
    shot_ = new Rgb8(ReadPng(*dir_ / "shot.png"));
    shot_err_ = new std::string(err);
  }
  static void TearDownTestSuite() {
    delete dir_;  // and its folder with it
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!dir_) GTEST_SKIP() << "chromium is not installed (scripts/setup.sh installs it)";
    ASSERT_EQ(three_error_, nullptr) << *three_error_ << " (scripts/setup.sh installs libjs-three)";
  }

  static inline test_support::ScopedTempDir* dir_ = nullptr;
  static inline std::string* three_error_ = nullptr;
  static inline std::map<int, Seen>* seen_ = nullptr;
  static inline Rgb8* shot_ = nullptr;
  static inline std::string* shot_err_ = nullptr;
};

TEST_F(ReportInBrowser, TheThreeDViewDrawsAndNoScriptFails) {
  for (const auto& [width, s] : *seen_) {
    ASSERT_NE(s.dom.find("</html>"), std::string::npos) << s.err;
    EXPECT_EQ(Attribute(s.dom, "view3d", "data-status"), "ok")
        << width << ": " << s.dom.substr(0, 2000);
    // The scene (an 8 m plane with a block, seen whole) covers a large part of the canvas
    // (1240 px wide, 55 % as high); an empty canvas draws nothing that differs from the
    // background.
    const std::string drawn = Attribute(s.dom, "view3d", "data-drawn-pixels");
    ASSERT_FALSE(drawn.empty()) << width;
    EXPECT_GT(std::stol(drawn), 100000) << width;
    EXPECT_EQ(Attribute(s.dom, "page-errors", "data-count"), "0") << s.dom.substr(0, 4000);
    EXPECT_EQ(s.err.find("Uncaught"), std::string::npos) << s.err;
    EXPECT_EQ(s.err.find(":ERROR:CONSOLE"), std::string::npos) << s.err;
  }
}

// What kLayoutProbe recorded in the page; null when it did not run.
nlohmann::json Probe(const std::string& dom) {
  const std::size_t at = dom.find("data-probe=\"");
  if (at == std::string::npos) return nullptr;
  return nlohmann::json::parse(Unescape(dom.substr(at + 12, dom.find('"', at + 12) - at - 12)));
}

TEST_F(ReportInBrowser, TheOutcomeAndItsReasonAreOnTheFirstScreen) {
  for (const auto& [width, s] : *seen_) {
    const nlohmann::json p = Probe(s.dom);
    ASSERT_FALSE(p.is_null()) << width << " px: " << s.err;
    EXPECT_EQ(p["width"].get<int>(), width);
    EXPECT_LE(p["scroll_width"].get<int>(), width) << "the page scrolls sideways at " << width;
    for (const char* part : {"headline", "reason"}) {
      const auto& r = p[part];
      EXPECT_GE(r[0].get<double>(), 0) << part << " at " << width;
      EXPECT_GE(r[1].get<double>(), 0) << part << " at " << width;
      EXPECT_LE(r[2].get<double>(), width) << part << " at " << width;
      EXPECT_LE(r[3].get<double>(), kHeight_px) << part << " at " << width;
      EXPECT_GT(r[2].get<double>() - r[0].get<double>(), 50) << part << " has no text";
    }
  }
}

TEST_F(ReportInBrowser, AClickOnAThumbnailOpensItsFullSizeFile) {
  const std::string& dom = seen_->at(1366).dom;
  const std::size_t at = dom.find("data-lightbox=\"");
  ASSERT_NE(at, std::string::npos) << "the full-size picture did not load";
  const nlohmann::json p =
      nlohmann::json::parse(Unescape(dom.substr(at + 15, dom.find('"', at + 15) - at - 15)));
  EXPECT_EQ(p["display"], "block");
  const std::string src = p["src"].get<std::string>();
  EXPECT_EQ(src.substr(src.size() - 17), "stops/000/map.png");
  EXPECT_GT(p["width"].get<int>(), p["thumb_width"].get<int>());  // the synthetic 500 vs 240 px
}

TEST_F(ReportInBrowser, TheScreenshotAt1366ShowsTheFailedOutcome) {
  const Rgb8& img = *shot_;
  ASSERT_EQ(img.width, 1366) << *shot_err_;
  ASSERT_EQ(img.height, kHeight_px);
  // The failed banner's fill (#fdeaea) across the page and its border (#c02020), as
  // html_report.cpp's style draws them; a success would be green, an unsafe one orange.
  EXPECT_GT(img.Count({253, 234, 234}), 1000 * 60);
  EXPECT_GT(img.Count({192, 32, 32}), 2 * 1000);
  EXPECT_EQ(img.Count({232, 246, 232}), 0);  // no success fill (#e8f6e8)
}

}  // namespace
}  // namespace pitchlab::mission
