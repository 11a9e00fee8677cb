#include "run_report.hpp"

#include <map>

#include "report_summary.hpp"

namespace pitchlab::mission {
namespace {

// Display width of a map figure: two side by side on a 1366 px screen (the page is 1240 px).
constexpr int kFigureWidth_px = 600;
constexpr int kStripWidth_px = 240;

// What each of the run folder's own files holds, for the list of links.
const std::map<std::string, std::string>& FileDescriptions() {
  static const std::map<std::string, std::string> kDescriptions = {
      {"metrics.json", "every metric of this page, machine-readable"},
      {"config.yaml", "the configuration as used, with the seed"},
      {"map_cloud.pcd", "the merged cloud, world frame (PCD)"},
      {"elevation.plem", "the elevation map, lossless (pitchlab map/plan read it)"},
      {"elevation.asc", "the elevation map as an ESRI ASCII grid (GIS)"},
      {"elevation.prj", "the grid's projection (WKT)"},
      {"trajectory_estimated.csv", "the estimated trajectory"},
      {"trajectory_true.csv", "the true trajectory"},
      {"trajectories.geojson", "both trajectories in WGS84"},
  };
  return kDescriptions;
}

std::string OutcomeHtml(const nlohmann::json& m) {
  const Outcome o = ReadOutcome(m);
  const char* kind = !o.success ? "failed" : o.safe ? "ok" : "unsafe";
  std::string html = std::string("<div id=outcome class=\"outcome ") + kind +
                     "\" data-success=" + (o.success ? "true" : "false") +
                     " data-safe=" + (o.safe ? "true" : "false") + ">\n<div class=headline>" +
                     HtmlEscape(o.headline) +
                     "</div>\n<div class=reason>Reason: " + HtmlEscape(o.reason) + "</div>\n";
  if (!o.safety.empty()) {
    html += "<ul class=safety>";
    for (const std::string& s : o.safety) html += "<li>Unsafe: " + HtmlEscape(s) + "</li>";
    html += "</ul>\n";
  }
  std::string facts = m.value("world", std::string("?")) + ", robot " +
                      m.value("robot", std::string("?")) + ", seed " +
                      (m.contains("seed") ? m["seed"].dump() : std::string("?"));
  if (m.contains("stops")) facts += ", " + m["stops"].dump() + " stops";
  if (m.contains("distance_m"))
    facts += ", " + Significant(m["distance_m"].get<double>()) + " m driven";
  if (m.contains("sim_time_s"))
    facts += ", " + Significant(m["sim_time_s"].get<double>()) + " s simulated";
  if (const auto& d = m.find("closest_approach_to_forbidden_m"); d != m.end() && d->is_number()) {
    facts += ", closest approach to a true hazard " + Significant(d->get<double>(), 2) + " m";
  }
  return html + "<div class=facts>" + HtmlEscape(facts) + "</div>\n</div>\n";
}

std::string MetricsTableHtml(const nlohmann::json& m) {
  std::string html =
      "<table id=key-metrics><tr><th class=l>metric</th><th>value</th><th class=l>unit</th>"
      "<th class=l>how to read it</th></tr>\n";
  for (const MetricRow& r : KeyMetrics(m)) {
    html += "<tr><td class=l>" + HtmlEscape(r.label) + "</td><td>" + HtmlEscape(r.value) +
            "</td><td class=l>" + HtmlEscape(r.unit) + "</td><td class=l>" + HtmlEscape(r.note) +
            "</td></tr>\n";
  }
  return html + "</table>\n";
}

std::string Link(const std::string& file, const std::string& text) {
  return "<a href=\"" + HtmlEscape(file) + "\">" + HtmlEscape(text) + "</a>";
}

std::string FilesHtml(const std::vector<std::string>& files) {
  std::string top = "<ul>\n", stops;
  for (const std::string& f : files) {
    if (f.rfind("stops/", 0) == 0) {
      stops += (stops.empty() ? "" : ", ") + Link(f, f);
      continue;
    }
    const auto d = FileDescriptions().find(f);
    top += "<li>" + Link(f, f) +
           (d != FileDescriptions().end() ? ": " + HtmlEscape(d->second) : std::string()) +
           "</li>\n";
  }
  top += "</ul>\n";
  if (!stops.empty())
    top += "<details><summary>each stop's files</summary><p>" + stops + "</p></details>\n";
  return top;
}

}  // namespace

std::string RenderRunReport(const RunReportInput& in, const Result<ThreeJs>& three) {
  const nlohmann::json& m = in.metrics;
  HtmlReport page("pitchlab run: " + m.value("world", std::string("?")) + ", seed " +
                  (m.contains("seed") ? m["seed"].dump() : std::string("?")));
  page.Html(OutcomeHtml(m));
  page.Html(MetricsTableHtml(m));
  page.Html(
      std::string(
          "<p>Jump to: <a href=#view>3D view</a> &middot; <a href=#maps>map pictures</a> &middot; "
          "<a href=#trajectories>trajectories</a> &middot; <a href=#stops>stops</a> &middot; ") +
      std::string(m.contains("stages") ? "<a href=#stages>time by stage</a> &middot; " : "") +
      "<a href=#files>files</a> &middot; <a href=#details>all metrics, configuration</a></p>\n");

  page.Heading("3D view", "view");
  if (in.scene_json.empty()) {
    page.Html(ViewerUnavailableHtml("the run left no map to show"));
  } else if (!three) {
    page.Html(ViewerUnavailableHtml(three.error().message));
  } else {
    page.Paragraph(
        "The merged cloud (grey, darker is lower), the elevation surface coloured by "
        "traversability (legend under the map pictures), the true (blue) and estimated (orange) "
        "trajectories, the stops (green), start (black) and goal (red).");
    page.Html(ViewerHtml(in.scene_json, *three));
  }

  page.Heading("Map pictures", "maps");
  for (const ReportPicture& p : in.pictures) {
    if (!p.legend.empty()) page.Paragraph(p.legend);
    page.Png(ReadBinaryFile(in.folder / p.file), p.caption, kFigureWidth_px, p.file);
  }

  page.Heading("Trajectories", "trajectories");
  page.Plot(in.trajectories, "trajectories, world frame", in.markers);

  page.Heading("Stops", "stops");
  if (!in.stop_rows.empty()) page.Table(in.stop_header, in.stop_rows);
  std::vector<StripPicture> strip;
  for (const ReportPicture& p : in.stop_pictures) {
    strip.push_back(
        {ReadBinaryFile(in.folder / p.file), p.caption, p.full.empty() ? p.file : p.full});
  }
  page.PngStrip(strip, kStripWidth_px);

  if (const auto rows = StageRows(m); !rows.empty()) {
    page.Heading("Where the run's time went", "stages");
    page.Paragraph(
        "Wall-clock and CPU time per stage, up to writing metrics.json and this page; shares "
        "of the whole run. A stage's CPU time is the mission thread's and its parallel loops' "
        "helpers'. The ground truth, each stop's files and the next stop's registration target "
        "are made on threads beside the mission: their CPU time is theirs (the target's is "
        "registration's), their wall time only what the run waited for them. A scan's rays are "
        "cast on the simulated laser's own thread while the physics steps through the sweep: "
        "ray casting's CPU time is all of it, its wall time what the scan waited for it. The "
        "whole run's CPU time counts every thread; \"other\" is what no stage holds (set-up, "
        "the ray caster's scene).");
    page.Table(StageHeader(), rows);
  }

  page.Heading("Files of this run", "files");
  page.Html(FilesHtml(in.files));

  page.Heading("Details", "details");
  page.BeginDetails("all metrics (metrics.json)");
  page.Preformatted(m.dump(2));
  page.EndDetails();
  page.BeginDetails("configuration (config.yaml)");
  page.Preformatted(in.config_yaml);
  page.EndDetails();
  return page.Render();
}

}  // namespace pitchlab::mission
