#pragma once
// A single self-contained HTML page (pictures inlined as data URIs, scripts inline, nothing
// fetched): what a run shows a person in any browser, offline. Two small scripts are always in
// the page: one records script errors in the DOM (#page-errors, for headless tests and for the
// reader), one opens a clicked picture full size over the page.

#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>

namespace pitchlab::mission {

/// One polyline of a trajectory plot, in metres, with its CSS colour and legend label.
struct PlotSeries {
  std::string label, color;
  std::vector<Eigen::Vector2d> points_m;
  bool dashed = false;
};

/// A labelled point of a plot (start, goal) [m].
struct PlotMarker {
  std::string label, color;
  Eigen::Vector2d point_m{0, 0};
};

/// A picture of a strip: the PNG's bytes (a thumbnail), its caption, and the run-folder file of
/// its full-size picture (opened on click; may be empty: the thumbnail itself).
struct StripPicture {
  std::string png, caption, file;
};

class HtmlReport {
 public:
  explicit HtmlReport(std::string title);

  /// A section heading; `id` (optional) makes it a link target.
  void Heading(const std::string& text, const std::string& id = "");
  void Paragraph(const std::string& text);
  /// A two-column key/value table.
  void KeyValues(const std::vector<std::pair<std::string, std::string>>& rows);
  /// A table with a header row; every row must have the header's width. Throws
  /// std::invalid_argument on a ragged row.
  void Table(const std::vector<std::string>& header,
             const std::vector<std::vector<std::string>>& rows);
  /// A PNG (its file bytes) inlined, with a caption, shown at most `width_px` wide (0: its own
  /// width, never wider than the page) and opened full size on click; `file` (optional) is the
  /// run-folder file it came from, linked under the caption.
  void Png(const std::string& png_bytes, const std::string& caption, int width_px = 0,
           const std::string& file = "");
  /// A row of thumbnails with captions (the per-stop strip), each opening its full-size file on
  /// click (the thumbnail itself when that file cannot be loaded: the page was moved alone).
  void PngStrip(const std::vector<StripPicture>& pictures, int width_px);
  /// An x-y plot of the series with axes in metres (equal scales), as inline SVG.
  void Plot(const std::vector<PlotSeries>& series, const std::string& caption,
            const std::vector<PlotMarker>& markers = {});
  /// Preformatted text (config, logs).
  void Preformatted(const std::string& text);
  /// Opens a folded part: everything added until EndDetails shows when the reader unfolds it.
  void BeginDetails(const std::string& summary);
  void EndDetails();
  /// HTML made elsewhere (the outcome banner, the 3D view), added as it is.
  void Html(const std::string& html);

  std::string Render() const;

 private:
  std::string title_;
  std::string body_;
  int open_details_ = 0;
};

/// Standard base64 (RFC 4648) of arbitrary bytes.
std::string Base64(const std::string& bytes);
/// Text with &, <, >, " escaped for HTML.
std::string HtmlEscape(const std::string& text);

}  // namespace pitchlab::mission
