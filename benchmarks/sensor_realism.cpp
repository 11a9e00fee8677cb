// sensor_realism: is the simulated LMS200 as real as the data (issue 16, item 5)? Computes the same
// statistics on real pitching-LMS scans (3DTK "uos" .3d files) and on simulated scans of a similar
// scene (the corridor world), and prints them side by side as JSON with the ratio sim / real:
//   - local plane-fit residual (robust sigma of point-to-plane distances) by range and incidence;
//   - the range noise alone: each return's offset from its two neighbours in the same interlaced
//     sweep (no pitch error of the servo's or the sweeps' enters), by range and incidence, and on
//     the floor;
//   - mixed pixels at depth edges along the scan line;
//   - dropouts (no-returns) overall and, where neighbouring returns locate them, by range and
//     incidence;
//   - the scanner frame's tilt against the dominant floor plane, and that plane's residual.
// Every statistic is computed from a range grid (lines x beams, no-returns included) by one code
// path, so real and simulated scans are measured alike. benchmarks/README.md documents them.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <map>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Eigenvalues>
#include <nlohmann/json.hpp>

#include "pitchlab/mapping/line_pitch.hpp"
#include "pitchlab/sensors/cloud_file.hpp"
#include "pitchlab/sensors/grazing_returns.hpp"
#include "pitchlab/sensors/lms200.hpp"
#include "pitchlab/sensors/sensor_config.hpp"
#include "pitchlab/sim/sim_rig.hpp"

namespace {

using namespace pitchlab;
using json = nlohmann::json;
constexpr double kRadToDeg = 180.0 / M_PI;

// --- thresholds of the statistics, and what they rest on -----------------------------------------
// 3DTK's config.ini for these scans keeps 0.48 m < r < 32.76 m: nearer returns are the robot's own
// body, 32.76 m (3276 cm) is the no-return code the logger wrote [m].
constexpr double kRealMinRange_m = 0.48;
constexpr double kRealNoReturn_m = 32.7;
// Plane-fit neighbourhood: +-2 lines x +-2 beams (about +-1 deg at the 0.5 deg grid of both the
// real and the simulated scan), a neighbour counting when it lies within 0.1 m + 5 % of the range
// of the centre (the diagonal of the window is 2.8 x 0.5 deg = 2.5 % of the range; twice that
// admits incidence up to ~60 deg on the window's full width, more on part of it). At least 8 of
// the 24 neighbours, so a fit has 5 spare degrees of freedom.
constexpr int kHalfWindow = 2;
constexpr double kNeighbourBase_m = 0.1, kNeighbourPerRange = 0.05;
constexpr int kMinNeighbours = 8;
// Mixed pixels: a depth edge is a step of more than 2 x kEdgeMargin_m between runs of readings; a
// mixed pixel is a single reading between the two runs at least kEdgeMargin_m off both (10 cm:
// above 3 sigma of the noisiest real surface, 3 cm, and 10 x the 1 cm quantization of cm mode).
// Runs of at least kMinRun readings are surfaces (3 readings fit a line to extrapolate).
constexpr double kEdgeMargin_m = 0.10;
constexpr int kMinRun = 3;
// Floor: points whose local normal is within 20 deg of the frame's z (a tilt of 3-5 deg plus the
// normal's own scatter) and that lie 0.2 m or more below the scanner's origin; the floor is the
// most populated 4 cm height bin among them, refined by a plane fit in a +-5 cm band (3 x the worst
// residual measured on the real floor, 1.6 cm).
constexpr double kFloorNormalMax_deg = 20.0;
constexpr double kFloorBelow_m = 0.2;
constexpr double kFloorBin_m = 0.04;
constexpr double kFloorBand_m = 0.05;

// Range growth of the noise itself, apart from the footprint: surfaces met within 45 deg of head
// on (the footprint's depth spread, tan(incidence), stays below 1 footprint there).
constexpr double kLowIncidence_rad = 45.0 * M_PI / 180.0;
const std::vector<double> kRangeBins_m = {0, 2, 4, 8, 16, 1e9};
const std::vector<double> kIncidenceBins_deg = {0, 30, 60, 75, 90.01};

enum class Cell : std::uint8_t { kValid, kNoReturn, kExcluded };

// A scan as the scanner read it: lines x beams, in reading order, with each reading's point and
// the beam's origin (the mirror) in the frame the statistics use (REP-103, z up).
struct RangeGrid {
  std::string name;
  int lines = 0, beams = 0;
  std::vector<Cell> cell;
  std::vector<float> range;             // [m], valid cells only
  std::vector<Eigen::Vector3d> point;   // valid cells only
  std::vector<Eigen::Vector3d> origin;  // per line
  double beam_step_rad = 0;             // angle between adjacent readings of a line
  std::size_t Index(int l, int b) const { return static_cast<std::size_t>(l) * beams + b; }
};

// --- readers
// ---------------------------------------------------------------------------------------

// A 3DTK "uos" scan in reading order: one reading a line `x y z` in cm in 3DTK's left-handed frame,
// the scanner at the origin, converted to REP-103 metres by sensors::PointFrom3dtk. Not
// sensors::Read3dtkScan: that keeps the returns only, and these statistics need every reading in
// its place on the grid, no-returns and the robot's own body included. Lines of the pitch sweep are found where the beam's azimuth jumps back to the start of the fan; every line
// must have as many readings as the first.
RangeGrid ReadUos(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot be opened");
  std::vector<Eigen::Vector3d> p;
  std::vector<double> azimuth;
  std::string text;
  for (int line_no = 1; std::getline(in, text); ++line_no) {
    std::istringstream ls(text);
    double x3, y3, z3;
    if (!(ls >> x3 >> y3 >> z3) || !std::isfinite(x3 + y3 + z3)) {
      throw std::runtime_error(path + ":" + std::to_string(line_no) + ": not 'x y z'");
    }
    p.push_back(sensors::PointFrom3dtk(Eigen::Vector3d(x3, y3, z3)));
    azimuth.push_back(std::atan2(p.back().y(), std::hypot(p.back().x(), p.back().z())));
  }
  if (p.empty()) throw std::runtime_error(path + ": no readings");
  RangeGrid g;
  g.name = path;
  int beams = 0;
  for (std::size_t i = 1; i <= p.size(); ++i) {
    // The fan sweeps right to left or left to right; a jump of more than 90 deg against the
    // sweep starts the next line.
    if (i == p.size() || std::abs(azimuth[i] - azimuth[i - 1]) > M_PI / 2) {
      beams = static_cast<int>(i);
      break;
    }
  }
  if (p.size() % beams != 0) {
    throw std::runtime_error(path + ": " + std::to_string(p.size()) +
                             " readings are not whole lines of " + std::to_string(beams));
  }
  g.beams = beams;
  g.lines = static_cast<int>(p.size() / beams);
  // The fan spans its readings evenly; its first line's first and last azimuth give the step
  // (3DTK's 360 readings over 180 deg: 0.5 deg, two interlaced LMS200 sweeps).
  if (beams > 1) g.beam_step_rad = std::abs(azimuth[beams - 1] - azimuth[0]) / (beams - 1);
  g.cell.resize(p.size());
  g.range.assign(p.size(), 0.0f);
  g.point.resize(p.size());
  g.origin.assign(g.lines, Eigen::Vector3d::Zero());
  for (std::size_t i = 0; i < p.size(); ++i) {
    const double r = p[i].norm();
    g.cell[i] = r >= kRealNoReturn_m   ? Cell::kNoReturn
                : r <= kRealMinRange_m ? Cell::kExcluded
                                       : Cell::kValid;
    g.range[i] = static_cast<float>(r);
    g.point[i] = p[i];
  }
  return g;
}

// A simulated scan's lines as the same grid, in base_link with the NOMINAL mount: what the
// pipeline sees (a mount misalignment drawn by the simulator shows as a tilted floor, as on the
// real scanner). Over-range counts as no return (the real logger writes both as 3276 cm).
RangeGrid FromScan(const sensors::Scan3D& scan, const sensors::MountConfig& mount,
                   const std::string& name) {
  RangeGrid g;
  g.name = name;
  g.lines = static_cast<int>(scan.lines.size());
  g.beams = g.lines ? static_cast<int>(scan.lines[0].ranges_m.size()) : 0;
  g.beam_step_rad = g.lines ? std::abs(scan.lines[0].angle_increment_rad) : 0.0;
  g.cell.assign(static_cast<std::size_t>(g.lines) * g.beams, Cell::kNoReturn);
  g.range.assign(g.cell.size(), 0.0f);
  g.point.assign(g.cell.size(), Eigen::Vector3d::Zero());
  for (int l = 0; l < g.lines; ++l) {
    const sensors::LaserLine& line = scan.lines[l];
    g.origin.push_back(mount.BaseToLaser(line.pitch_rad).translation());
    for (int b = 0; b < g.beams; ++b) {
      if (line.status[b] != sensors::ReadingStatus::kValid) continue;
      const std::size_t i = g.Index(l, b);
      g.cell[i] = Cell::kValid;
      g.range[i] = line.ranges_m[b];
      g.point[i] = sensors::BeamPointInBase(line.ranges_m[b],
                                            line.angle_min_rad + b * line.angle_increment_rad,
                                            line.pitch_rad, mount);
    }
  }
  return g;
}

// --- statistics
// ------------------------------------------------------------------------------------

int Bin(const std::vector<double>& edges, double v) {
  for (std::size_t k = 0; k + 1 < edges.size(); ++k) {
    if (v >= edges[k] && v < edges[k + 1]) return static_cast<int>(k);
  }
  return -1;
}

std::string BinName(const std::vector<double>& edges, int k, const char* unit) {
  std::ostringstream os;
  if (edges[k + 1] > 1e3 || edges[k + 1] > 90.0) {
    os << edges[k] << "+" << unit;
  } else {
    os << edges[k] << "-" << edges[k + 1] << unit;
  }
  return os.str();
}

double Median(std::vector<double> v) {
  if (v.empty()) return NAN;
  const auto mid = v.begin() + static_cast<std::ptrdiff_t>(v.size() / 2);
  std::nth_element(v.begin(), mid, v.end());
  return *mid;
}

// 1.4826 x the median absolute value: sigma of a zero-mean Gaussian, unmoved by the minority of
// windows that straddle a corner or an edge.
double RobustSigma(const std::vector<double>& d) {
  std::vector<double> a;
  a.reserve(d.size());
  for (double x : d) a.push_back(std::abs(x));
  return 1.4826 * Median(a);
}

// A return's residual by its range bin, its incidence bin, and its range bin when met within
// kLowIncidence_rad of head-on (the range growth apart from the footprint's).
struct Binned {
  std::vector<std::vector<double>> by_range = std::vector<std::vector<double>>(5);
  std::vector<std::vector<double>> by_incidence = std::vector<std::vector<double>>(4);
  std::vector<std::vector<double>> by_range_low_incidence = std::vector<std::vector<double>>(5);

  void Add(double range_m, double incidence_rad, double d) {
    const int rb = Bin(kRangeBins_m, range_m);
    const int ib = Bin(kIncidenceBins_deg, incidence_rad * kRadToDeg);
    if (rb >= 0) by_range[rb].push_back(d);
    if (rb >= 0 && incidence_rad < kLowIncidence_rad) by_range_low_incidence[rb].push_back(d);
    if (ib >= 0) by_incidence[ib].push_back(d);
  }
};

struct Accumulator {
  // Plane fits: the centre's distance to its neighbours' plane.
  Binned plane;
  std::vector<double> all;
  // Dropouts located by neighbouring returns, per bin; returns per bin are the fitted points.
  std::vector<double> dropouts_by_range = std::vector<double>(5, 0.0);
  std::vector<double> dropouts_by_incidence = std::vector<double>(4, 0.0);
  double readings = 0, no_returns = 0, located_dropouts = 0, valid = 0;
  // Mixed pixels.
  double edges = 0, mixed = 0, line_checked = 0;
  // Floor.
  std::vector<double> floor_tilt_deg, floor_roll_deg, floor_pitch_deg, floor_sigma_m, floor_rms_m;
  std::vector<double> floor_points;
  // Per range bin: a floor return's height off the floor plane less the mean of its two in-line
  // neighbours', over sqrt(1.5): one beam's own height scatter on the floor. A line's pitch error
  // moves its three returns alike and cancels; what is left is what each beam adds on its own,
  // which on a floor met at grazing incidence is the range noise times cos(incidence).
  std::vector<std::vector<double>> floor_inline = std::vector<std::vector<double>>(5);
  // Every surface's range noise alone: a return's offset along its patch normal from the midpoint
  // of its two neighbours in the same interlaced sweep (beams b -+ sweeps), over sqrt(1.5). The
  // three share the sweep's pitch, so neither a line's nor a sweep's pitch error enters (the
  // plane fit above spans lines and takes both); on a plane the three lie on one straight line
  // and the midpoint offset is zero without noise.
  Binned sweep;
  // Grazed returns (sensors::GrazedReturns, with the elevation map's 0.1 m cell) within the
  // mission's 10 m map range.
  double grazed = 0, within_map_range = 0;
};

struct PatchFit {
  bool ok = false;
  double incidence_rad = 0;
  Eigen::Vector3d normal;
};

PatchFit FitPatch(const RangeGrid& g, int l, int b, double* residual) {
  PatchFit fit;
  const std::size_t c = g.Index(l, b);
  const Eigen::Vector3d& pc = g.point[c];
  const double reach = kNeighbourBase_m + kNeighbourPerRange * g.range[c];
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
  int n = 0;
  for (int dl = -kHalfWindow; dl <= kHalfWindow; ++dl) {
    for (int db = -kHalfWindow; db <= kHalfWindow; ++db) {
      const int ll = l + dl, bb = b + db;
      if ((dl == 0 && db == 0) || ll < 0 || bb < 0 || ll >= g.lines || bb >= g.beams) continue;
      const std::size_t i = g.Index(ll, bb);
      if (g.cell[i] != Cell::kValid) continue;
      const Eigen::Vector3d q = g.point[i] - pc;  // relative to the centre: well conditioned
      if (q.norm() > reach) continue;
      sum += q;
      outer += q * q.transpose();
      ++n;
    }
  }
  if (n < kMinNeighbours) return fit;
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Matrix3d cov = outer / n - mean * mean.transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  fit.normal = eig.eigenvectors().col(0);
  // The centre is not in its own fit: its distance is the noise a plane cannot absorb.
  *residual = fit.normal.dot(-mean);
  const Eigen::Vector3d beam = (pc - g.origin[l]).normalized();
  fit.incidence_rad = std::acos(std::min(1.0, std::abs(fit.normal.dot(beam))));
  fit.ok = true;
  return fit;
}

void PlaneStats(const RangeGrid& g, Accumulator& acc, std::vector<PatchFit>& fits) {
  fits.assign(g.cell.size(), PatchFit{});
  for (int l = 0; l < g.lines; ++l) {
    for (int b = 0; b < g.beams; ++b) {
      const std::size_t i = g.Index(l, b);
      if (g.cell[i] != Cell::kValid) continue;
      double d = 0;
      fits[i] = FitPatch(g, l, b, &d);
      if (!fits[i].ok) continue;
      acc.plane.Add(g.range[i], fits[i].incidence_rad, d);
      acc.all.push_back(d);
    }
  }
}

// No-returns and the dropouts among them that neighbouring returns locate: at least two of the
// four grid neighbours returned and agree in range (within kEdgeMargin_m + 5 %), so the beam met a
// surface there; its range is their mean, its incidence the nearest fitted neighbour's.
void DropoutStats(const RangeGrid& g, const std::vector<PatchFit>& fits, Accumulator& acc) {
  for (int l = 0; l < g.lines; ++l) {
    for (int b = 0; b < g.beams; ++b) {
      const std::size_t i = g.Index(l, b);
      if (g.cell[i] == Cell::kExcluded) continue;
      acc.readings += 1;
      if (g.cell[i] == Cell::kValid) {
        acc.valid += 1;
        continue;
      }
      acc.no_returns += 1;
      double lo = 1e9, hi = -1e9, sum = 0;
      int n = 0;
      const PatchFit* nearest = nullptr;
      const int dl[4] = {0, 0, -1, 1}, db[4] = {-1, 1, 0, 0};
      for (int k = 0; k < 4; ++k) {
        const int ll = l + dl[k], bb = b + db[k];
        if (ll < 0 || bb < 0 || ll >= g.lines || bb >= g.beams) continue;
        const std::size_t j = g.Index(ll, bb);
        if (g.cell[j] != Cell::kValid) continue;
        lo = std::min(lo, double(g.range[j]));
        hi = std::max(hi, double(g.range[j]));
        sum += g.range[j];
        ++n;
        if (!nearest && fits[j].ok) nearest = &fits[j];
      }
      if (n < 2 || hi - lo > kEdgeMargin_m + 0.05 * lo) continue;
      acc.located_dropouts += 1;
      const int rb = Bin(kRangeBins_m, sum / n);
      if (rb >= 0) acc.dropouts_by_range[rb] += 1;
      if (nearest) {
        const int ib = Bin(kIncidenceBins_deg, nearest->incidence_rad * kRadToDeg);
        if (ib >= 0) acc.dropouts_by_incidence[ib] += 1;
      }
    }
  }
}

// Along each line: runs of readings that continue one surface (each within kEdgeMargin_m of the
// last, or of the line through the two before it); a depth edge separates two surface runs whose
// facing ends differ by more than 2 kEdgeMargin_m with at most two readings between them; a mixed
// pixel is a single reading there lying at least kEdgeMargin_m inside the step on both sides.
void MixedPixelStats(const RangeGrid& g, Accumulator& acc) {
  for (int l = 0; l < g.lines; ++l) {
    std::vector<int> run_id(g.beams, -1);
    std::vector<std::pair<int, int>> runs;  // [first, last] beams
    for (int b = 0; b < g.beams; ++b) {
      const std::size_t i = g.Index(l, b);
      if (g.cell[i] != Cell::kValid) continue;
      acc.line_checked += 1;
      bool joins = false;
      if (b > 0 && run_id[b - 1] >= 0) {
        const double r = g.range[i], prev = g.range[i - 1];
        joins = std::abs(r - prev) < kEdgeMargin_m;
        if (!joins && b > 1 && run_id[b - 2] == run_id[b - 1]) {
          joins = std::abs(r - (2 * prev - g.range[i - 2])) < kEdgeMargin_m;
        }
      }
      if (joins) {
        run_id[b] = run_id[b - 1];
        runs.back().second = b;
      } else {
        run_id[b] = static_cast<int>(runs.size());
        runs.emplace_back(b, b);
      }
    }
    auto length = [&](std::size_t k) { return runs[k].second - runs[k].first + 1; };
    for (std::size_t k = 0; k + 1 < runs.size(); ++k) {
      if (length(k) < kMinRun) continue;
      // The next surface run within three beams, with only short runs between.
      std::size_t m = k + 1;
      while (m < runs.size() && length(m) < kMinRun) ++m;
      if (m >= runs.size() || runs[m].first - runs[k].second > 3) continue;
      const double a = g.range[g.Index(l, runs[k].second)];
      const double z = g.range[g.Index(l, runs[m].first)];
      if (std::abs(z - a) <= 2 * kEdgeMargin_m) continue;
      acc.edges += 1;
      if (m == k + 2 && length(k + 1) == 1 && runs[k + 1].first == runs[k].second + 1 &&
          runs[m].first == runs[k + 1].first + 1) {
        const double r = g.range[g.Index(l, runs[k + 1].first)];
        if (r > std::min(a, z) + kEdgeMargin_m && r < std::max(a, z) - kEdgeMargin_m) {
          acc.mixed += 1;
        }
      }
    }
  }
}

// Every return within the band of the floor plane n.p + d0 = 0 whose two in-line neighbours are
// too (far floor returns included: they have too few neighbours for a patch fit).
void FloorInlineStats(const RangeGrid& g, const Eigen::Vector3d& n, double d0, Accumulator& acc) {
  const auto off = [&](int l, int b, double* d) {
    if (b < 0 || b >= g.beams) return false;
    const std::size_t i = g.Index(l, b);
    if (g.cell[i] != Cell::kValid) return false;
    *d = n.dot(g.point[i]) + d0;
    return std::abs(*d) <= kFloorBand_m;
  };
  for (int l = 0; l < g.lines; ++l) {
    for (int b = 0; b < g.beams; ++b) {
      double before, here, after;
      if (!off(l, b, &here) || !off(l, b - 1, &before) || !off(l, b + 1, &after)) continue;
      const int bin = Bin(kRangeBins_m, g.range[g.Index(l, b)]);
      if (bin < 0) continue;
      acc.floor_inline[static_cast<std::size_t>(bin)].push_back(
          (here - 0.5 * (before + after)) / std::sqrt(1.5));
    }
  }
}

void FloorStats(const RangeGrid& g, const std::vector<PatchFit>& fits, Accumulator& acc) {
  const double origin_z = g.origin.empty() ? 0.0 : g.origin[0].z();
  std::vector<Eigen::Vector3d> cand;
  for (std::size_t i = 0; i < g.cell.size(); ++i) {
    if (!fits[i].ok) continue;
    if (std::acos(std::min(1.0, std::abs(fits[i].normal.z()))) * kRadToDeg > kFloorNormalMax_deg)
      continue;
    if (g.point[i].z() > origin_z - kFloorBelow_m) continue;
    cand.push_back(g.point[i]);
  }
  if (cand.size() < 100) return;
  std::map<long, int> bins;
  for (const auto& p : cand) ++bins[std::lround(std::floor(p.z() / kFloorBin_m))];
  const auto mode = std::max_element(bins.begin(), bins.end(),
                                     [](auto& a, auto& b) { return a.second < b.second; });
  Eigen::Vector3d n = Eigen::Vector3d::UnitZ();
  double d0 = -(mode->first + 0.5) * kFloorBin_m;  // plane n.p + d0 = 0
  std::vector<double> resid;
  for (int iter = 0; iter < 4; ++iter) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int count = 0;
    // The band is wider on the first pass: the plane is still level there, the floor not.
    const double band = iter == 0 ? 2 * kFloorBand_m : kFloorBand_m;
    for (const auto& p : cand) {
      if (std::abs(n.dot(p) + d0) > band) continue;
      sum += p;
      outer += p * p.transpose();
      ++count;
    }
    if (count < 100) return;
    const Eigen::Vector3d mean = sum / count;
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(outer / count - mean * mean.transpose());
    n = eig.eigenvectors().col(0);
    if (n.z() < 0) n = -n;
    d0 = -n.dot(mean);
  }
  double ss = 0;
  for (const auto& p : cand) {
    const double d = n.dot(p) + d0;
    if (std::abs(d) > kFloorBand_m) continue;
    resid.push_back(d);
    ss += d * d;
  }
  acc.floor_tilt_deg.push_back(std::acos(n.z()) * kRadToDeg);
  acc.floor_pitch_deg.push_back(std::atan2(n.x(), n.z()) * kRadToDeg);
  acc.floor_roll_deg.push_back(std::atan2(-n.y(), n.z()) * kRadToDeg);
  acc.floor_sigma_m.push_back(RobustSigma(resid));
  acc.floor_rms_m.push_back(std::sqrt(ss / resid.size()));
  acc.floor_points.push_back(static_cast<double>(resid.size()));
  FloorInlineStats(g, n, d0, acc);
}

// What the mission would leave out of its elevation map as grazed: the grid as an organised scan
// with each line's laser at the origin (the points shifted by their line's origin).
void GrazedStats(const RangeGrid& g, Accumulator& acc) {
  constexpr double kMapRange_m = 10.0, kCell_m = 0.1;  // MissionConfig::map_range_m, cell_m
  sensors::Scan3D scan;
  scan.lines.resize(static_cast<std::size_t>(g.lines));
  for (int l = 0; l < g.lines; ++l) {
    for (int b = 0; b < g.beams; ++b) {
      const std::size_t i = g.Index(l, b);
      if (g.cell[i] != Cell::kValid) continue;
      const Eigen::Vector3d p = g.point[i] - g.origin[static_cast<std::size_t>(l)];
      sensors::ScanPoint sp;
      sp.x = static_cast<float>(p.x());
      sp.y = static_cast<float>(p.y());
      sp.z = static_cast<float>(p.z());
      sp.range_m = g.range[i];
      sp.line = static_cast<std::uint16_t>(l);
      sp.beam = static_cast<std::uint16_t>(b);
      scan.points.push_back(sp);
    }
  }
  sensors::MountConfig at_origin;
  at_origin.t_base_mount_m.setZero();
  at_origin.t_mount_laser_m.setZero();
  sensors::GrazingConfig config;
  config.max_spread_m = kCell_m;
  const std::vector<bool> grazed = sensors::GrazedReturns(scan, at_origin, config);
  for (std::size_t i = 0; i < scan.points.size(); ++i) {
    if (scan.points[i].range_m > kMapRange_m) continue;
    acc.within_map_range += 1;
    acc.grazed += grazed[i];
  }
}

// A nodding scanner's lines meet at its poles, where the beam runs along the pitch axis (y in both
// grids' frames): within 15 deg of it a line lies less than a quarter (sin 15 deg) of its spacing
// from the next, a +-2 line patch spans one dimension and its normal, hence the incidence, is
// arbitrary (the simulated corridor's walls 1 m to either side filled two thirds of the 75+ deg
// bin with such returns).
constexpr double kPoleCos = 0.966;  // cos 15 deg

void SweepStats(const RangeGrid& g, const std::vector<PatchFit>& fits, Accumulator& acc) {
  const int s = sensors::InterlacedSweeps(g.beam_step_rad);
  for (int l = 0; l < g.lines; ++l) {
    for (int b = s; b + s < g.beams; ++b) {
      const std::size_t i = g.Index(l, b), lo = g.Index(l, b - s), hi = g.Index(l, b + s);
      if (!fits[i].ok || g.cell[lo] != Cell::kValid || g.cell[hi] != Cell::kValid) continue;
      if (std::abs((g.point[i] - g.origin[l]).normalized().y()) > kPoleCos) continue;
      // The same surface: both neighbours within the patch's reach (a depth edge is not noise).
      const double reach = kNeighbourBase_m + kNeighbourPerRange * g.range[i];
      const Eigen::Vector3d& p = g.point[i];
      if ((g.point[lo] - p).norm() > reach || (g.point[hi] - p).norm() > reach) continue;
      const double d = fits[i].normal.dot(p - 0.5 * (g.point[lo] + g.point[hi])) / std::sqrt(1.5);
      acc.sweep.Add(g.range[i], fits[i].incidence_rad, d);
    }
  }
}

void Measure(const RangeGrid& g, Accumulator& acc) {
  GrazedStats(g, acc);
  std::vector<PatchFit> fits;
  PlaneStats(g, acc, fits);
  SweepStats(g, fits, acc);
  DropoutStats(g, fits, acc);
  MixedPixelStats(g, acc);
  FloorStats(g, fits, acc);
}

double Mean(const std::vector<double>& v) {
  if (v.empty()) return NAN;
  double s = 0;
  for (double x : v) s += x;
  return s / v.size();
}

// The flat statistics of one column: name -> value.
std::map<std::string, double> Summarize(const Accumulator& a) {
  std::map<std::string, double> s;
  for (std::size_t k = 0; k + 1 < kRangeBins_m.size(); ++k) {
    const std::string bin = BinName(kRangeBins_m, static_cast<int>(k), "m");
    s["plane_sigma_m.range_" + bin] = RobustSigma(a.plane.by_range[k]);
    s["plane_sigma_m.incidence_0-45deg.range_" + bin] =
        RobustSigma(a.plane.by_range_low_incidence[k]);
    // Dropout rates per bin: of the returns that located a bin (those with a plane fit).
    const double n = static_cast<double>(a.plane.by_range[k].size());
    s["dropout_rate.range_" + bin] = a.dropouts_by_range[k] / (n + a.dropouts_by_range[k]);
    s["floor_inline_sigma_m.range_" + bin] = RobustSigma(a.floor_inline[k]);
    s["sweep_inline_sigma_m.range_" + bin] = RobustSigma(a.sweep.by_range[k]);
    s["sweep_inline_sigma_m.incidence_0-45deg.range_" + bin] =
        RobustSigma(a.sweep.by_range_low_incidence[k]);
  }
  for (std::size_t k = 0; k + 1 < kIncidenceBins_deg.size(); ++k) {
    const std::string bin = BinName(kIncidenceBins_deg, static_cast<int>(k), "deg");
    s["plane_sigma_m.incidence_" + bin] = RobustSigma(a.plane.by_incidence[k]);
    s["sweep_inline_sigma_m.incidence_" + bin] = RobustSigma(a.sweep.by_incidence[k]);
    const double n = static_cast<double>(a.plane.by_incidence[k].size());
    s["dropout_rate.incidence_" + bin] =
        a.dropouts_by_incidence[k] / (n + a.dropouts_by_incidence[k]);
    s["share_of_points.incidence_" + bin] = n / static_cast<double>(a.all.size());
  }
  s["plane_sigma_m.all"] = RobustSigma(a.all);
  s["no_return_fraction"] = a.no_returns / a.readings;
  s["located_dropout_fraction"] = a.located_dropouts / (a.valid + a.located_dropouts);
  s["mixed_pixel_fraction_of_returns"] = a.mixed / a.line_checked;
  s["mixed_pixels_per_depth_edge"] = a.edges > 0 ? a.mixed / a.edges : NAN;
  s["depth_edges_per_1000_returns"] = 1000.0 * a.edges / a.line_checked;
  s["floor_tilt_deg"] = Mean(a.floor_tilt_deg);
  s["floor_sigma_m"] = Mean(a.floor_sigma_m);
  s["floor_rms_m"] = Mean(a.floor_rms_m);
  s["grazed_fraction_within_10m"] = a.grazed / a.within_map_range;
  return s;
}

json Details(const Accumulator& a, const std::vector<std::string>& names) {
  json d;
  d["scans"] = names;
  d["readings"] = a.readings;
  d["returns"] = a.valid;
  d["plane_fits"] = a.all.size();
  d["depth_edges"] = a.edges;
  d["mixed_pixels"] = a.mixed;
  d["located_dropouts"] = a.located_dropouts;
  d["floor_tilt_deg_per_scan"] = a.floor_tilt_deg;
  d["floor_roll_deg_per_scan"] = a.floor_roll_deg;
  d["floor_pitch_deg_per_scan"] = a.floor_pitch_deg;
  d["floor_points_per_scan"] = a.floor_points;
  json inline_counts = json::object();
  for (std::size_t k = 0; k + 1 < kRangeBins_m.size(); ++k) {
    inline_counts["range_" + BinName(kRangeBins_m, static_cast<int>(k), "m")] =
        a.floor_inline[k].size();
  }
  d["floor_inline_returns"] = inline_counts;
  return d;
}

// The real scan's returns with each line turned onto the floor (mapping::RectifyLinePitch about
// the scanner's own y axis, where 3DTK's frame has it); ranges are unchanged by the turn.
void SetLinesRight(RangeGrid& g) {
  std::vector<Eigen::Vector3f> returns;
  std::vector<std::size_t> at;
  for (std::size_t i = 0; i < g.point.size(); ++i) {
    if (g.cell[i] != Cell::kValid) continue;
    returns.push_back(g.point[i].cast<float>());
    at.push_back(i);
  }
  const mapping::LinePitch lp = mapping::RectifyLinePitch(returns, Eigen::Vector3f::Zero());
  for (std::size_t k = 0; k < at.size(); ++k) g.point[at[k]] = returns[k].cast<double>();
  std::fprintf(stderr, "%s: %zu of %zu lines set right, %.2f deg RMS%s%s\n", g.name.c_str(),
               lp.corrected, lp.lines, lp.rms_correction_rad * kRadToDeg,
               lp.note.empty() ? "" : ": ", lp.note.c_str());
}

struct Options {
  std::vector<std::string> real;
  std::string world = "corridor";
  std::string sensor_yaml;
  int sim_scans = 2;
  std::uint64_t seed = 1;
  bool legacy = false;
  bool lines_set_right = false;
};

[[noreturn]] void Usage(int code) {
  (code ? std::cerr : std::cout)
      << "sensor_realism --real FILE.3d [--real FILE.3d ...] [--world NAME] [--sim-scans N]\n"
         "               [--seed S] [--sensor FILE.yaml] [--legacy] [--lines-set-right]\n"
         "Prints JSON: the same statistics of the real scans (3DTK uos .3d, cm, left-handed)\n"
         "and of N simulated scans of the world (default corridor; scan k at the default start\n"
         "moved k x 4 m along +x or the next free spot, LMS200 seed S + k), with the ratio sim / "
         "real.\n"
         "The simulated LMS200 is Lms200Config::Measured() (the model fitted to real scans).\n"
         "--sensor: lms200/pitch_unit/scan/mount sections over the defaults instead.\n"
         "--legacy: the default (pre-issue-16) LMS200 model (constant noise, no mixed pixels,\n"
         "no dropouts, perfect mount).\n"
         "--lines-set-right: the real scans' lines set right by their floor first\n"
         "(mapping::RectifyLinePitch, as pitchlab's commands read them): the statistics without\n"
         "the nodding servo's line-to-line pitch error.\n";
  std::exit(code);
}

Options Parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) {
        std::cerr << "sensor_realism: " << a << " needs a value\n";
        Usage(2);
      }
      return argv[++i];
    };
    try {
      if (a == "--real")
        o.real.push_back(value());
      else if (a == "--world")
        o.world = value();
      else if (a == "--sensor")
        o.sensor_yaml = value();
      else if (a == "--sim-scans")
        o.sim_scans = std::stoi(value());
      else if (a == "--seed")
        o.seed = std::stoull(value());
      else if (a == "--legacy")
        o.legacy = true;
      else if (a == "--lines-set-right")
        o.lines_set_right = true;
      else if (a == "--help")
        Usage(0);
      else {
        std::cerr << "sensor_realism: unknown option " << a << "\n";
        Usage(2);
      }
    } catch (const std::logic_error&) {
      std::cerr << "sensor_realism: " << a << " wants a number\n";
      Usage(2);
    }
  }
  if (o.real.empty() || o.sim_scans < 1) {
    std::cerr << "sensor_realism: give at least one --real file and --sim-scans >= 1\n";
    Usage(2);
  }
  return o;
}

}  // namespace

int main(int argc, char** argv) {
  const Options o = Parse(argc, argv);
  try {
    Accumulator real, sim;
    for (const std::string& path : o.real) {
      RangeGrid g = ReadUos(path);
      std::fprintf(stderr, "%s: %d lines x %d beams\n", path.c_str(), g.lines, g.beams);
      if (o.lines_set_right) SetLinesRight(g);
      Measure(g, real);
    }
    sensors::SensorConfig sensor;
    if (!o.sensor_yaml.empty()) {
      std::ifstream in(o.sensor_yaml);
      if (!in) throw std::runtime_error(o.sensor_yaml + ": cannot be opened");
      std::stringstream text;
      text << in.rdbuf();
      sensor = sensors::ParseSensorConfig(text.str(), o.sensor_yaml);
    }
    if (o.sensor_yaml.empty()) {  // the measured model unless asked for the default (legacy) one
      sensor.lms200 = o.legacy ? sensors::Lms200Config::Legacy() : sensors::Lms200Config::Measured();
    }
    std::vector<std::string> sim_names;
    json drawn = json::array();
    for (int k = 0; k < o.sim_scans; ++k) {
      sim::SimRigConfig config;
      config.lms200 = sensor.lms200;
      config.lms200.seed = o.seed + k;
      config.pitch_unit = sensor.pitch_unit;
      config.pattern = sensor.scan;
      config.robot.mount = sensor.mount;
      sim::SimRig rig(std::string(PITCHLAB_WORLDS_DIR) + "/" + o.world + ".xml", config);
      const Eigen::Vector3d start =
          rig.sim().world().default_start.value_or(Eigen::Vector3d::Zero());
      // Scan k stands 4 k m along +x from the start, or the first free spot 0.5 m further on.
      Result<Eigen::Isometry3d> placed = Fail(Error::Code::kInvalidArgument, "not tried");
      for (int j = 0; j < 20 && !placed; ++j) {
        placed = rig.PlaceRobot(start.x() + 4.0 * k + 0.5 * j, start.y(), start.z());
      }
      if (!placed) {
        throw std::runtime_error(o.world + ": cannot place the robot: " + placed.error().message);
      }
      Result<sensors::Scan3D> scan = rig.Acquire();
      if (!scan) throw std::runtime_error(o.world + ": scan failed: " + scan.error().message);
      const std::string name = o.world + " seed " + std::to_string(config.lms200.seed);
      std::fprintf(stderr, "%s: %zu lines\n", name.c_str(), scan->lines.size());
      Measure(FromScan(*scan, config.robot.mount, name), sim);
      sim_names.push_back(name);
      const Eigen::Vector3d e = rig.mount_error_rpy_rad() * kRadToDeg;
      drawn.push_back({e.x(), e.y(), e.z()});
    }
    const auto r = Summarize(real), s = Summarize(sim);
    json stats = json::object();
    for (const auto& [name, rv] : r) {
      const double sv = s.at(name);
      json row = {{"real", std::isfinite(rv) ? json(rv) : json()},
                  {"sim", std::isfinite(sv) ? json(sv) : json()}};
      row["sim_over_real"] =
          (std::isfinite(rv) && std::isfinite(sv) && rv != 0) ? json(sv / rv) : json();
      stats[name] = row;
    }
    json out;
    out["statistics"] = stats;
    out["real"] = Details(real, o.real);
    out["sim"] = Details(sim, sim_names);
    out["sim"]["mount_error_rpy_deg_drawn"] = drawn;
    out["sim"]["lms200"] = sensors::SensorConfigToYaml(sensor);
    out["sim"]["legacy_model"] = o.legacy;
    std::cout << out.dump(2) << "\n";
  } catch (const std::exception& e) {
    std::cerr << "sensor_realism: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
