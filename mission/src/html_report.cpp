#include "html_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

#include "axis_ticks.hpp"

namespace pitchlab::mission {
namespace {

// Layout for a screen from 1366 px wide up: nothing wider than the page, the first screen holds
// the outcome.
constexpr const char* kStyle = R"CSS(
body{font-family:sans-serif;margin:1.5em auto;max-width:1240px;padding:0 1em;color:#222;line-height:1.35}
h1{font-size:1.5em;margin:0 0 .4em}h2{margin:1.4em 0 .4em;font-size:1.25em}
table{border-collapse:collapse;margin:.6em 0}td,th{border:1px solid #ccc;padding:3px 8px;
text-align:right;font-variant-numeric:tabular-nums}th{background:#f3f3f3}
table.kv th,td.l,th.l{text-align:left}
figure{display:inline-block;margin:.5em;vertical-align:top;max-width:100%}
figure img,figure svg{max-width:100%;height:auto}
figcaption{font-size:.9em;color:#555;max-width:900px}
.strip{display:flex;flex-wrap:wrap}.strip figure{margin:.3em}
img.zoom{cursor:zoom-in}
pre{background:#f6f6f6;padding:1em;overflow:auto;max-height:40em}
details{margin:.8em 0}summary{cursor:pointer;font-weight:bold}
.outcome{border-radius:6px;padding:.7em 1em;margin:.6em 0 1em;border:2px solid}
.outcome .headline{font-size:1.6em;font-weight:bold}
.outcome .reason{font-size:1.15em;margin-top:.2em}
.outcome ul{margin:.4em 0 0;padding-left:1.3em}
.outcome.ok{background:#e8f6e8;border-color:#2a8a2a}.outcome.ok .headline{color:#1d6b1d}
.outcome.unsafe{background:#fff4e0;border-color:#d07000}.outcome.unsafe .headline{color:#a04f00}
.outcome.failed{background:#fdeaea;border-color:#c02020}.outcome.failed .headline{color:#a01515}
.facts{color:#444;margin:.2em 0}
#lightbox{position:fixed;inset:0;background:rgba(0,0,0,.85);display:none;overflow:auto;
z-index:10;cursor:zoom-out;text-align:center}#lightbox img{margin:1em auto;max-width:none}
#view3d .view3d-canvas{width:100%;border:1px solid #ccc;line-height:0}
#view3d .view3d-bar{margin:.3em 0}#view3d .hint{color:#666;font-size:.9em;margin-left:1em}
.note{background:#fff8d0;border:1px solid #d8c060;padding:.5em 1em}
)CSS";

// Errors of any script on the page, written into #page-errors (shown when there are some) so a
// reader sees them and a headless browser can read them from the DOM. First in <head>, so it
// also sees errors of the scripts after it.
constexpr const char* kErrorRecorder = R"JS(
(function () {
  var errors = [];
  function show() {
    var box = document.getElementById('page-errors');
    if (!box) return;
    box.setAttribute('data-count', String(errors.length));
    box.textContent = errors.join('\n');
    box.hidden = errors.length === 0;
  }
  window.addEventListener('error', function (e) { errors.push(String(e.message)); show(); });
  var original = console.error;
  console.error = function () {
    errors.push(Array.prototype.join.call(arguments, ' '));
    show();
    return original.apply(console, arguments);
  };
  document.addEventListener('DOMContentLoaded', show);
})();
)JS";

// A click on a picture shows it at its own size over the page; a click or Escape closes it.
constexpr const char* kLightbox = R"JS(
(function () {
  var box = document.getElementById('lightbox'), big = box.querySelector('img');
  document.addEventListener('click', function (e) {
    var t = e.target;
    if (t.classList && t.classList.contains('zoom')) {
      e.preventDefault();
      // A thumbnail opens the full-size file it links to; the thumbnail itself when that file
      // is not beside the page.
      var link = t.closest('a');
      big.onerror = function () { big.onerror = null; big.src = t.src; };
      big.src = link ? link.href : t.src;
      box.style.display = 'block';
    } else if (box.style.display === 'block' && box.contains(t)) {
      box.style.display = 'none';
    }
  });
  document.addEventListener('keydown', function (e) {
    if (e.key === 'Escape') box.style.display = 'none';
  });
})();
)JS";

std::string ImgTag(const std::string& png, const std::string& alt, int width_px) {
  return "<img class=zoom alt=\"" + HtmlEscape(alt) + "\" title=\"click: full size\"" +
         (width_px > 0 ? " width=" + std::to_string(width_px) : std::string()) +
         " src=\"data:image/png;base64," + Base64(png) + "\">";
}

}  // namespace

std::string Base64(const std::string& bytes) {
  static constexpr char kAlphabet[] =
      "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((bytes.size() + 2) / 3 * 4);
  std::size_t i = 0;
  for (; i + 2 < bytes.size(); i += 3) {
    const unsigned v = (static_cast<unsigned char>(bytes[i]) << 16) |
                       (static_cast<unsigned char>(bytes[i + 1]) << 8) |
                       static_cast<unsigned char>(bytes[i + 2]);
    out += {kAlphabet[v >> 18], kAlphabet[(v >> 12) & 63], kAlphabet[(v >> 6) & 63],
            kAlphabet[v & 63]};
  }
  if (const std::size_t rest = bytes.size() - i; rest > 0) {
    unsigned v = static_cast<unsigned char>(bytes[i]) << 16;
    if (rest == 2) v |= static_cast<unsigned char>(bytes[i + 1]) << 8;
    out += kAlphabet[v >> 18];
    out += kAlphabet[(v >> 12) & 63];
    out += rest == 2 ? kAlphabet[(v >> 6) & 63] : '=';
    out += '=';
  }
  return out;
}

std::string HtmlEscape(const std::string& text) {
  std::string out;
  out.reserve(text.size());
  for (char c : text) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::Heading(const std::string& text, const std::string& id) {
  body_ +=
      (id.empty() ? "<h2>" : "<h2 id=\"" + HtmlEscape(id) + "\">") + HtmlEscape(text) + "</h2>\n";
}

void HtmlReport::Paragraph(const std::string& text) {
  body_ += "<p>" + HtmlEscape(text) + "</p>\n";
}

void HtmlReport::KeyValues(const std::vector<std::pair<std::string, std::string>>& rows) {
  body_ += "<table class=kv>\n";
  for (const auto& [k, v] : rows) {
    body_ += "<tr><th>" + HtmlEscape(k) + "</th><td class=l>" + HtmlEscape(v) + "</td></tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::Table(const std::vector<std::string>& header,
                       const std::vector<std::vector<std::string>>& rows) {
  body_ += "<table><tr>";
  for (const auto& h : header) body_ += "<th>" + HtmlEscape(h) + "</th>";
  body_ += "</tr>\n";
  for (const auto& row : rows) {
    if (row.size() != header.size()) throw std::invalid_argument("report table: ragged row");
    body_ += "<tr>";
    for (const auto& cell : row) body_ += "<td>" + HtmlEscape(cell) + "</td>";
    body_ += "</tr>\n";
  }
  body_ += "</table>\n";
}

void HtmlReport::Png(const std::string& png_bytes, const std::string& caption, int width_px,
                     const std::string& file) {
  // The figure as wide as its picture: a long caption wraps instead of widening it, so two
  // pictures of kFigureWidth_px sit side by side.
  body_ += (width_px > 0 ? "<figure style=\"width:" + std::to_string(width_px) + "px\">"
                         : std::string("<figure>")) +
           ImgTag(png_bytes, caption, width_px) + "<figcaption>" + HtmlEscape(caption) +
           (file.empty() ? std::string()
                         : " (<a href=\"" + HtmlEscape(file) + "\">" + HtmlEscape(file) + "</a>)") +
           "</figcaption></figure>\n";
}

void HtmlReport::PngStrip(const std::vector<StripPicture>& pictures, int width_px) {
  body_ += "<div class=strip>\n";
  for (const StripPicture& p : pictures) {
    const std::string img = ImgTag(p.png, p.caption, width_px);
    body_ += "<figure>" +
             (p.file.empty() ? img : "<a href=\"" + HtmlEscape(p.file) + "\">" + img + "</a>") +
             "<figcaption>" +
             (p.file.empty()
                  ? HtmlEscape(p.caption)
                  : "<a href=\"" + HtmlEscape(p.file) + "\">" + HtmlEscape(p.caption) + "</a>") +
             "</figcaption></figure>\n";
  }
  body_ += "</div>\n";
}

void HtmlReport::Plot(const std::vector<PlotSeries>& series, const std::string& caption,
                      const std::vector<PlotMarker>& markers) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& s : series) {
    for (const auto& p : s.points_m) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  for (const auto& m : markers) {
    lo = lo.cwiseMin(m.point_m);
    hi = hi.cwiseMax(m.point_m);
  }
  if (!std::isfinite(lo.x())) return;  // nothing to draw
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0}) * 1.1;
  const Eigen::Vector2d centre = (lo + hi) / 2;
  const Eigen::Vector2d corner = centre - Eigen::Vector2d::Constant(span / 2);
  constexpr double kSize_px = 520, kLeft_px = 52, kTop_px = 10, kBottom_px = 62;
  auto px = [&](const Eigen::Vector2d& p) {  // y up, equal scales
    return Eigen::Vector2d(kLeft_px + (p.x() - corner.x()) / span * kSize_px,
                           kTop_px + kSize_px - (p.y() - corner.y()) / span * kSize_px);
  };
  std::ostringstream svg;
  svg.setf(std::ios::fixed);
  svg.precision(1);
  const double width = kLeft_px + kSize_px + 12, height = kTop_px + kSize_px + kBottom_px;
  svg << "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << width << "\" height=\""
      << height << "\" viewBox=\"0 0 " << width << " " << height
      << "\" font-family=\"sans-serif\" font-size=\"12\" style=\"background:#fff\">\n"
      << "<rect x=\"" << kLeft_px << "\" y=\"" << kTop_px << "\" width=\"" << kSize_px
      << "\" height=\"" << kSize_px << "\" fill=\"none\" stroke=\"#888\"/>\n";
  const double step = NiceStep(span, 7);
  for (double t : Ticks(corner.x(), corner.x() + span, step)) {
    const double x = px({t, 0}).x();
    svg << "<line x1=\"" << x << "\" x2=\"" << x << "\" y1=\"" << kTop_px << "\" y2=\""
        << kTop_px + kSize_px + 5 << "\" stroke=\"#e4e4e4\"/><text x=\"" << x << "\" y=\""
        << kTop_px + kSize_px + 18 << "\" text-anchor=\"middle\">" << TickLabel(t, step)
        << "</text>\n";
  }
  for (double t : Ticks(corner.y(), corner.y() + span, step)) {
    const double y = px({0, t}).y();
    svg << "<line x1=\"" << kLeft_px - 5 << "\" x2=\"" << kLeft_px + kSize_px << "\" y1=\"" << y
        << "\" y2=\"" << y << "\" stroke=\"#e4e4e4\"/><text x=\"" << kLeft_px - 8 << "\" y=\""
        << y + 4 << "\" text-anchor=\"end\">" << TickLabel(t, step) << "</text>\n";
  }
  svg << "<text x=\"" << kLeft_px + kSize_px / 2 << "\" y=\"" << kTop_px + kSize_px + 34
      << "\" text-anchor=\"middle\">x [m]</text><text x=\"12\" y=\"" << kTop_px + kSize_px / 2
      << "\" text-anchor=\"middle\" transform=\"rotate(-90 12 " << kTop_px + kSize_px / 2
      << ")\">y [m]</text>\n";
  double legend_x = kLeft_px;
  const double legend_y = kTop_px + kSize_px + 54;
  auto legend = [&](const std::string& label, const std::string& color) {
    svg << "<text x=\"" << legend_x << "\" y=\"" << legend_y << "\" fill=\"" << color
        << "\" font-size=\"13\">" << HtmlEscape(label) << "</text>\n";
    legend_x += 16 + 7.5 * label.size();
  };
  for (const auto& s : series) {
    svg << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"2\""
        << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"";
    for (const auto& p : s.points_m) {
      const Eigen::Vector2d q = px(p);
      svg << q.x() << "," << q.y() << " ";
    }
    svg << "\"/>\n";
    legend(s.label + (s.dashed ? " (dashed)" : ""), s.color);
  }
  for (const auto& m : markers) {
    const Eigen::Vector2d q = px(m.point_m);
    svg << "<circle cx=\"" << q.x() << "\" cy=\"" << q.y() << "\" r=\"6\" fill=\"#fff\" stroke=\""
        << m.color << "\" stroke-width=\"3\"/>\n";
    legend("\u25CB " + m.label, m.color);
  }
  svg << "</svg><figcaption>" << HtmlEscape(caption) << "</figcaption></figure>\n";
  body_ += svg.str();
}

void HtmlReport::Preformatted(const std::string& text) {
  body_ += "<pre>" + HtmlEscape(text) + "</pre>\n";
}

void HtmlReport::BeginDetails(const std::string& summary) {
  body_ += "<details><summary>" + HtmlEscape(summary) + "</summary>\n";
  ++open_details_;
}

void HtmlReport::EndDetails() {
  if (open_details_ == 0) throw std::logic_error("report: EndDetails without BeginDetails");
  body_ += "</details>\n";
  --open_details_;
}

void HtmlReport::Html(const std::string& html) { body_ += html; }

std::string HtmlReport::Render() const {
  std::string closing;
  for (int k = 0; k < open_details_; ++k) closing += "</details>\n";
  return "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8>"
         "<meta name=viewport content=\"width=device-width, initial-scale=1\"><title>" +
         HtmlEscape(title_) + "</title>\n<style>" + kStyle + "</style>\n<script>" + kErrorRecorder +
         "</script></head>\n<body><h1>" + HtmlEscape(title_) +
         "</h1>\n<pre id=page-errors data-count=0 hidden></pre>\n" + body_ + closing +
         "<div id=lightbox><img alt=\"full size\"></div>\n<script>" + kLightbox +
         "</script>\n</body></html>\n";
}

}  // namespace pitchlab::mission
