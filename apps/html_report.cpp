#include "html_report.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <stdexcept>

namespace pitchlab::apps {

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
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      default: out += c;
    }
  }
  return out;
}

HtmlReport::HtmlReport(std::string title) : title_(std::move(title)) {}

void HtmlReport::Heading(const std::string& text) { body_ += "<h2>" + HtmlEscape(text) + "</h2>\n"; }

void HtmlReport::Paragraph(const std::string& text) {
  body_ += "<p>" + HtmlEscape(text) + "</p>\n";
}

void HtmlReport::KeyValues(const std::vector<std::pair<std::string, std::string>>& rows) {
  body_ += "<table class=kv>\n";
  for (const auto& [k, v] : rows) {
    body_ += "<tr><th>" + HtmlEscape(k) + "</th><td>" + HtmlEscape(v) + "</td></tr>\n";
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

void HtmlReport::Png(const std::string& png_bytes, const std::string& caption, int width_px) {
  body_ += "<figure><img alt=\"" + HtmlEscape(caption) + "\" src=\"data:image/png;base64," +
           Base64(png_bytes) + "\"" +
           (width_px > 0 ? " width=" + std::to_string(width_px) : std::string()) +
           "><figcaption>" + HtmlEscape(caption) + "</figcaption></figure>\n";
}

void HtmlReport::PngStrip(const std::vector<std::pair<std::string, std::string>>& items,
                          int width_px) {
  body_ += "<div class=strip>\n";
  for (const auto& [png, caption] : items) {
    body_ += "<figure><img alt=\"" + HtmlEscape(caption) + "\" width=" +
             std::to_string(width_px) + " src=\"data:image/png;base64," + Base64(png) +
             "\"><figcaption>" + HtmlEscape(caption) + "</figcaption></figure>\n";
  }
  body_ += "</div>\n";
}

void HtmlReport::Plot(const std::vector<PlotSeries>& series, const std::string& caption) {
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector2d hi = -lo;
  for (const auto& s : series) {
    for (const auto& p : s.points_m) {
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
  }
  if (!std::isfinite(lo.x())) return;  // nothing to draw
  const double span = std::max({hi.x() - lo.x(), hi.y() - lo.y(), 1.0}) * 1.1;
  const Eigen::Vector2d centre = (lo + hi) / 2;
  constexpr double kSize_px = 520;
  auto px = [&](const Eigen::Vector2d& p) {  // y up, equal scales
    return Eigen::Vector2d((p.x() - centre.x()) / span * kSize_px + kSize_px / 2,
                           kSize_px / 2 - (p.y() - centre.y()) / span * kSize_px);
  };
  std::ostringstream svg;
  svg.setf(std::ios::fixed);
  svg.precision(1);
  svg << "<figure><svg xmlns=\"http://www.w3.org/2000/svg\" width=\"" << kSize_px << "\" height=\""
      << kSize_px + 24 << "\" style=\"background:#fff;border:1px solid #ccc\">\n";
  int legend_x = 8;
  for (const auto& s : series) {
    svg << "<polyline fill=\"none\" stroke=\"" << s.color << "\" stroke-width=\"2\""
        << (s.dashed ? " stroke-dasharray=\"6,4\"" : "") << " points=\"";
    for (const auto& p : s.points_m) {
      const Eigen::Vector2d q = px(p);
      svg << q.x() << "," << q.y() << " ";
    }
    svg << "\"/>\n<text x=\"" << legend_x << "\" y=\"" << kSize_px + 16 << "\" fill=\"" << s.color
        << "\" font-size=\"13\">" << HtmlEscape(s.label) << "</text>\n";
    legend_x += 14 + 8 * static_cast<int>(s.label.size());
  }
  svg << "<text x=\"" << kSize_px - 8 << "\" y=\"14\" text-anchor=\"end\" font-size=\"12\">"
      << "width " << span << " m</text>\n</svg><figcaption>" << HtmlEscape(caption)
      << "</figcaption></figure>\n";
  body_ += svg.str();
}

void HtmlReport::Preformatted(const std::string& text) {
  body_ += "<pre>" + HtmlEscape(text) + "</pre>\n";
}

std::string HtmlReport::Render() const {
  return "<!DOCTYPE html>\n<html lang=en><head><meta charset=utf-8><title>" + HtmlEscape(title_) +
         "</title>\n<style>body{font-family:sans-serif;margin:2em;max-width:1200px;color:#222}"
         "table{border-collapse:collapse;margin:1em 0}td,th{border:1px solid #ccc;padding:3px 8px;"
         "text-align:right;font-variant-numeric:tabular-nums}table.kv th{text-align:left}"
         "figure{display:inline-block;margin:0.5em}figcaption{font-size:0.9em;color:#555}"
         ".strip{display:flex;flex-wrap:wrap}pre{background:#f6f6f6;padding:1em;overflow:auto}"
         "</style></head>\n<body><h1>" +
         HtmlEscape(title_) + "</h1>\n" + body_ + "</body></html>\n";
}

}  // namespace pitchlab::apps
