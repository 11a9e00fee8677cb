// Ground-truth evaluation of elevation maps and planning (issue 4), printed as JSON lines:
// - map quality on `terrain` and `urban` from simulated scans at true poses: RMSE, bias, max and
//   p95 error and coverage against the true surface (rays cast straight down, looking through
//   overhangs with the robot's headroom: mapping/elevation_truth.hpp) per cell size, over the
//   surface cells, with the cells at vertical faces (wall cells: see CompareConfig) apart and
//   all together, and the RMSE against the first surface from above (the former truth) beside it;
// - planning on the estimated map vs the true map, with unknown cells forbidden and penalised:
//   the estimated map's path costed on the true map, its ratio to the true optimum, and the truly
//   forbidden cells it crosses, split by whether the estimate had observed them.
//
//   benchmarks/elevation_truth_benchmark [--worlds terrain,urban] [--cells 0.05,0.1,0.2,0.4]

#include <cmath>
#include <cstdio>
#include <cstring>
#include <sstream>
#include <string>
#include <vector>

#include "pitchlab/mapping/elevation_layers.hpp"
#include "pitchlab/mapping/elevation_map.hpp"
#include "pitchlab/mapping/elevation_truth.hpp"
#include "pitchlab/planning/planner.hpp"
#include "pitchlab/planning/traversability.hpp"
#include "pitchlab/sim/sim_rig.hpp"
#include "pitchlab/worlds/world_catalog.hpp"

namespace {

using namespace pitchlab;

struct WorldScans {
  std::vector<std::vector<Eigen::Vector3f>> clouds;  // world frame
  std::vector<Eigen::Vector3f> origins;              // laser at scan start, world frame
  Eigen::Vector2d start = Eigen::Vector2d::Zero();
};

std::vector<std::string> Split(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream ss(s);
  for (std::string item; std::getline(ss, item, ',');) out.push_back(item);
  return out;
}

// Scans from the default start facing 0, 120 and 240 deg, and from 8 m ahead facing 0 and 180.
WorldScans Scan(sim::SimRig& rig) {
  WorldScans w;
  const auto start = rig.PlaceAtDefaultStart();
  if (!start) throw std::runtime_error("cannot place the robot: " + start.error().message);
  w.start = start->translation().head<2>();
  const double x0 = w.start.x(), y0 = w.start.y();
  const double poses[][3] = {
      {x0, y0, 0}, {x0, y0, 2.0944}, {x0, y0, 4.1888}, {x0 + 8, y0, 0}, {x0 + 8, y0, M_PI}};
  for (const auto& p : poses) {
    if (!rig.PlaceRobot(p[0], p[1], p[2])) continue;  // a rock there: skip that pose
    const auto scan = rig.Acquire();
    if (!scan) continue;
    const Eigen::Isometry3f T = scan->T_world_base.cast<float>();
    std::vector<Eigen::Vector3f> cloud;
    for (const auto& q : scan->points) cloud.push_back(T * Eigen::Vector3f(q.x, q.y, q.z));
    w.clouds.push_back(std::move(cloud));
    w.origins.push_back(rig.sim().T_world_laser().translation().cast<float>());
  }
  return w;
}

// The estimated map's path from start to start + offset costed on the true map, under one
// unknown-cell policy. Truly forbidden cells it crosses are split by what the estimate knew of
// them: a crossing through a cell the estimate observed is a map error; one through a cell it
// had not seen (only possible when unknown cells are penalised) is the price of exploring, which
// the closed loop pays by scanning again before it drives there.
void PlanningVsTruth(const std::string& world, const mapping::ElevationLayers& est,
                     const mapping::ElevationLayers& truth, const Eigen::Vector2d& start,
                     planning::UnknownPolicy policy) {
  planning::PlannerConfig cfg;
  cfg.unknown = policy;
  const char* policy_name = policy == planning::UnknownPolicy::kForbid ? "forbid" : "penalise";
  const planning::TraversabilityGrid E = planning::BuildTraversability(est, cfg);
  const planning::TraversabilityGrid T = planning::BuildTraversability(truth, cfg);
  for (const Eigen::Vector2d offset :
       {Eigen::Vector2d(12, 0), Eigen::Vector2d(10, 6), Eigen::Vector2d(6, -8)}) {
    const Eigen::Vector2d goal = start + offset;
    const auto pe = planning::PlanPath(E, start, goal, planning::Algorithm::kAStar);
    const auto pt = planning::PlanPath(T, start, goal, planning::Algorithm::kAStar);
    std::printf(
        "{\"world\": \"%s\", \"planning\": true, \"unknown\": \"%s\", \"start\": [%.2f, %.2f], "
        "\"goal\": [%.2f, %.2f], \"estimated\": \"%s\", \"true\": \"%s\"",
        world.c_str(), policy_name, start.x(), start.y(), goal.x(), goal.y(),
        pe ? "found" : planning::ToString(pe.error().reason),
        pt ? "found" : planning::ToString(pt.error().reason));
    if (pe) {
      const planning::PathOnMap on_truth = planning::EvaluatePath(T, *pe);
      std::size_t where_known = 0, where_unseen = 0;
      for (std::size_t n = 1; n < pe->cells.size(); ++n) {
        const std::size_t k = T.geometry.Linear(pe->cells[n]);
        if (T.Free(k)) continue;
        (est.state[k] == mapping::CellState::kObserved ? where_known : where_unseen) += 1;
      }
      std::printf(
          ", \"estimated_cost\": %.4f, \"estimated_cost_on_truth\": %.4f, "
          "\"truly_forbidden_cells_crossed\": %zu, \"of_which_observed_in_estimate\": %zu, "
          "\"of_which_unseen_in_estimate\": %zu, \"truly_unknown_cells\": %zu",
          pe->cost, on_truth.cost, on_truth.forbidden_cells, where_known, where_unseen,
          on_truth.unknown_cells);
      if (pt) {
        std::printf(", \"true_optimum\": %.4f, \"ratio\": %.4f", pt->cost,
                    on_truth.cost / pt->cost);
      }
    }
    std::printf("}\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> worlds = {"terrain", "urban"};
  std::vector<double> cells = {0.05, 0.1, 0.2, 0.4};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--worlds")) worlds = Split(argv[i + 1]);
    if (!std::strcmp(argv[i], "--cells")) {
      cells.clear();
      for (const auto& c : Split(argv[i + 1])) cells.push_back(std::stod(c));
    }
  }
  for (const std::string& world : worlds) {
    sim::SimRig rig(worlds::ResolveWorld(world, PITCHLAB_WORLDS_DIR).string(), sim::SimRigConfig{});
    const WorldScans scans = Scan(rig);
    std::size_t points = 0;
    for (const auto& c : scans.clouds) points += c.size();
    (void)rig.PlaceRobot(scans.start.x() + 200, scans.start.y() + 200,
                         0);  // out of the way (fails off-world: fine)
    for (double cell : cells) {
      const mapping::GridGeometry g = mapping::GridGeometry::Covering(
          scans.start - Eigen::Vector2d(16, 16), scans.start + Eigen::Vector2d(24, 16), cell);
      mapping::ElevationMap map(g);
      for (std::size_t s = 0; s < scans.clouds.size(); ++s)
        (void)map.InsertScan(scans.clouds[s].data(), scans.clouds[s].size(), scans.origins[s]);
      const mapping::ElevationLayers est = mapping::ComputeLayers(map);
      const mapping::ElevationLayers truth =
          mapping::ComputeTruthLayers(mapping::ComputeTrueElevationMap(rig.caster(), g));
      const mapping::MapErrorReport r = mapping::CompareToTruth(est, truth);
      // The former truth, the first surface from above (canopies count), for comparison.
      mapping::TruthConfig first_hit;
      first_hit.min_headroom_m = 0;
      const mapping::MapErrorReport r0 = mapping::CompareToTruth(
          est,
          mapping::ComputeTruthLayers(mapping::ComputeTrueElevationMap(rig.caster(), g, first_hit)));
      std::printf(
          "{\"world\": \"%s\", \"scans\": %zu, \"points\": %zu, \"cell_m\": %.3f, "
          "\"cells\": %zu, \"coverage\": %.4f, \"surface_cells\": %zu, \"rmse_m\": %.4f, "
          "\"mean_error_m\": %.4f, \"max_abs_error_m\": %.4f, \"p95_abs_error_m\": %.4f, "
          "\"wall_cells\": %zu, \"wall_rmse_m\": %.4f, \"all_rmse_m\": %.4f, "
          "\"all_max_abs_error_m\": %.4f, \"drop_cells\": %zu, "
          "\"first_hit_truth\": {\"rmse_m\": %.4f, \"all_rmse_m\": %.4f, \"coverage\": %.4f}}\n",
          world.c_str(), scans.clouds.size(), points, cell, g.cell_count(), r.coverage,
          r.surface_cells, r.rmse_m, r.mean_error_m, r.max_abs_error_m, r.p95_abs_error_m,
          r.wall_cells, r.wall_rmse_m, r.all_rmse_m, r.all_max_abs_error_m, r.drop_cells, r0.rmse_m,
          r0.all_rmse_m, r0.coverage);
      std::fflush(stdout);
      if (std::abs(cell - 0.2) < 1e-9) {
        for (const auto policy :
             {planning::UnknownPolicy::kForbid, planning::UnknownPolicy::kPenalise})
          PlanningVsTruth(world, est, truth, scans.start, policy);
      }
    }
  }
  return 0;
}
