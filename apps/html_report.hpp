#pragma once
// A single self-contained HTML page (pictures inlined as data URIs, no scripts, no network):
// what a run shows a person in any browser, offline.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace pitchlab::apps {

/// One polyline of a trajectory plot, in metres, with its CSS colour and legend label.
struct PlotSeries {
  std::string label, color;
  std::vector<Eigen::Vector2d> points_m;
  bool dashed = false;
};

class HtmlReport {
 public:
  explicit HtmlReport(std::string title);

  void Heading(const std::string& text);
  void Paragraph(const std::string& text);
  /// A two-column key/value table.
  void KeyValues(const std::vector<std::pair<std::string, std::string>>& rows);
  /// A table with a header row; every row must have the header's width.
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows);
  /// A PNG (its file bytes) inlined, with a caption; `width_px` 0 keeps its size.
  void Png(const std::string& png_bytes, const std::string& caption, int width_px = 0);
  /// A row of small PNGs with captions (the per-stop strip).
  void PngStrip(const std::vector<std::pair<std::string, std::string>>& pngs_and_captions,
                int width_px);
  /// An x-y plot of the series (equal axis scales, metres), as inline SVG.
  void Plot(const std::vector<PlotSeries>& series, const std::string& caption);
  /// Preformatted text (config, logs).
  void Preformatted(const std::string& text);

  std::string Render() const;

 private:
  std::string title_;
  std::string body_;
};

/// Standard base64 (RFC 4648) of arbitrary bytes.
std::string Base64(const std::string& bytes);
/// Text with &, <, >, " escaped for HTML.
std::string HtmlEscape(const std::string& text);

}  // namespace pitchlab::apps
