// `.prj` (ESRI WKT1) reader (dem_io.hpp): which of local, geographic or Transverse Mercator a
// DEM's coordinates are, with the projection's parameters.

#include <cctype>
#include <cmath>
#include <cstdlib>
#include <string>
#include <vector>

#include "pitchlab/mapping/dem_io.hpp"

namespace pitchlab::mapping {
namespace {

// One WKT node: KEYWORD["text", 1.0, CHILD[...], ...].
struct WktNode {
  std::string keyword;              // upper case
  std::vector<std::string> values;  // quoted texts (unquoted) and numbers, in order
  std::vector<WktNode> children;

  const WktNode* Child(const std::string& key) const {
    for (const WktNode& c : children)
      if (c.keyword == key) return &c;
    return nullptr;
  }
  double Number(std::size_t i) const {
    return i < values.size() ? std::strtod(values[i].c_str(), nullptr) : std::nan("");
  }
};

std::string Upper(std::string s) {
  for (char& c : s) c = static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return s;
}

// Recursive descent over WKT1; false on text that is not WKT.
class WktParser {
 public:
  explicit WktParser(const std::string& text) : s_(text) {}
  bool Parse(WktNode* root) {
    if (!Node(root)) return false;
    Skip();
    return pos_ == s_.size();
  }

 private:
  void Skip() {
    while (pos_ < s_.size() && std::isspace(static_cast<unsigned char>(s_[pos_]))) ++pos_;
  }
  bool Node(WktNode* node) {
    Skip();
    const std::size_t start = pos_;
    while (pos_ < s_.size() &&
           (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_'))
      ++pos_;
    if (pos_ == start) return false;
    node->keyword = Upper(s_.substr(start, pos_ - start));
    Skip();
    if (pos_ >= s_.size() || (s_[pos_] != '[' && s_[pos_] != '(')) return false;
    const char close = s_[pos_++] == '[' ? ']' : ')';
    for (;;) {
      Skip();
      if (pos_ >= s_.size()) return false;
      if (s_[pos_] == '"') {
        const std::size_t end = s_.find('"', pos_ + 1);
        if (end == std::string::npos) return false;
        node->values.push_back(s_.substr(pos_ + 1, end - pos_ - 1));
        pos_ = end + 1;
      } else if (std::isalpha(static_cast<unsigned char>(s_[pos_]))) {
        // A child node KEYWORD[...], or a bare enumeration value (AXIS["X",EAST]).
        const std::size_t start_word = pos_;
        while (pos_ < s_.size() &&
               (std::isalnum(static_cast<unsigned char>(s_[pos_])) || s_[pos_] == '_'))
          ++pos_;
        const std::string word = s_.substr(start_word, pos_ - start_word);
        Skip();
        if (pos_ < s_.size() && (s_[pos_] == '[' || s_[pos_] == '(')) {
          pos_ = start_word;
          node->children.emplace_back();
          if (!Node(&node->children.back())) return false;
        } else {
          node->values.push_back(word);
        }
      } else {
        const std::size_t start_number = pos_;
        while (pos_ < s_.size() && s_[pos_] != ',' && s_[pos_] != close &&
               !std::isspace(static_cast<unsigned char>(s_[pos_])))
          ++pos_;
        node->values.push_back(s_.substr(start_number, pos_ - start_number));
      }
      Skip();
      if (pos_ < s_.size() && s_[pos_] == ',') {
        ++pos_;
        continue;
      }
      if (pos_ < s_.size() && s_[pos_] == close) {
        ++pos_;
        return true;
      }
      return false;
    }
  }
  const std::string& s_;
  std::size_t pos_ = 0;
};

// The ellipsoid of a GEOGCS node, when it names one.
void ReadEllipsoid(const WktNode& geogcs, DemCrs* crs) {
  const WktNode* datum = geogcs.Child("DATUM");
  const WktNode* spheroid = datum ? datum->Child("SPHEROID") : nullptr;
  if (!spheroid) return;
  const double a = spheroid->Number(1), inv_f = spheroid->Number(2);
  if (a > 6e6 && a < 7e6 && inv_f > 250 && inv_f < 350) {  // an Earth ellipsoid
    crs->semi_major_m = a;
    crs->inverse_flattening = inv_f;
  }
}

std::string Lowered(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

Result<DemCrs> ParsePrj(const std::string& wkt, const std::string& source) {
  const auto bad = [&](const std::string& why) {
    return Fail(Error::Code::kInvalidArgument, source + ": " + why);
  };
  WktNode root;
  if (!WktParser(wkt).Parse(&root))
    return bad("not ESRI WKT1 (expected PROJCS[...], GEOGCS[...] or LOCAL_CS[...])");
  DemCrs crs;
  crs.name = root.values.empty() ? root.keyword : root.values.front();
  const WktNode* unit = root.Child("UNIT");
  const double unit_factor = unit ? unit->Number(1) : std::nan("");
  if (root.keyword == "LOCAL_CS") {
    if (unit && std::abs(unit_factor - 1.0) > 1e-9)
      return bad("LOCAL_CS unit '" + unit->values.front() + "' is not the metre");
    crs.kind = DemCrs::Kind::kLocal;
    return crs;
  }
  if (root.keyword == "GEOGCS") {
    // Degrees: pi / 180 radians per unit (ESRI writes 0.0174532925199433).
    if (!(std::abs(unit_factor - M_PI / 180) < 1e-9)) return bad("GEOGCS unit is not the degree");
    const WktNode* primem = root.Child("PRIMEM");
    if (primem && primem->Number(1) != 0)
      return bad("prime meridian '" + primem->values.front() + "' is not Greenwich");
    crs.kind = DemCrs::Kind::kGeographic;
    ReadEllipsoid(root, &crs);
    return crs;
  }
  if (root.keyword != "PROJCS") return bad("'" + root.keyword + "' is not a coordinate system");
  const WktNode* projection = root.Child("PROJECTION");
  const std::string method = projection && !projection->values.empty()
                                 ? Lowered(projection->values.front())
                                 : std::string("none");
  if (method != "transverse_mercator" && method != "transverse mercator")
    return bad("projection '" + method +
               "' is not supported (Transverse Mercator, UTM, "
               "longitude/latitude or local metres are): reproject the grid, e.g. `gdalwarp "
               "-t_srs EPSG:326NN` for UTM zone NN north");
  if (!(std::abs(unit_factor - 1.0) < 1e-9))
    return bad("PROJCS '" + crs.name + "' has a unit other than the metre");
  for (const WktNode& p : root.children) {
    if (p.keyword != "PARAMETER" || p.values.size() < 2) continue;
    const std::string name = Lowered(p.values[0]);
    const double v = p.Number(1);
    if (!std::isfinite(v)) return bad("parameter '" + p.values[0] + "' is not a number");
    if (name == "false_easting") crs.false_easting_m = v;
    if (name == "false_northing") crs.false_northing_m = v;
    if (name == "central_meridian") crs.central_meridian_deg = v;
    if (name == "scale_factor") crs.scale_factor = v;
    if (name == "latitude_of_origin") crs.latitude_of_origin_deg = v;
  }
  if (!(crs.scale_factor > 0.5 && crs.scale_factor < 1.5) ||
      !(std::abs(crs.central_meridian_deg) <= 360) || !(std::abs(crs.latitude_of_origin_deg) < 90))
    return bad(
        "Transverse Mercator parameters out of range (scale factor, central meridian or "
        "latitude of origin)");
  crs.kind = DemCrs::Kind::kTransverseMercator;
  if (const WktNode* geogcs = root.Child("GEOGCS")) ReadEllipsoid(*geogcs, &crs);
  return crs;
}

}  // namespace pitchlab::mapping
