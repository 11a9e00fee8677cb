// A full simulated stop-scan-go mission from a user's program: run_mission WORLD GOAL_X GOAL_Y OUT
// drives the P3-AT from the world's default start to (GOAL_X, GOAL_Y) [m] and writes the run
// folder OUT (scans, maps, paths, metrics.json, report.html). Exit 0: goal reached.
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <exception>
#include <string>

#include "pitchlab/mission/sim_mission.hpp"
#include "pitchlab/worlds/world_catalog.hpp"

int main(int argc, char** argv) {
  namespace mission = pitchlab::mission;
  char *end_x = nullptr, *end_y = nullptr;
  const double goal_x = argc == 5 ? std::strtod(argv[2], &end_x) : NAN;
  const double goal_y = argc == 5 ? std::strtod(argv[3], &end_y) : NAN;
  if (argc != 5 || end_x == argv[2] || end_y == argv[3] || *end_x != '\0' || *end_y != '\0' ||
      !std::isfinite(goal_x + goal_y)) {
    std::fprintf(stderr, "usage: %s WORLD GOAL_X GOAL_Y OUT (the goal in metres)\n", argv[0]);
    return 2;
  }
  try {
    mission::SimMissionSpec spec = mission::LoadSimMissionSpec(std::nullopt);  // the defaults
    spec.world_file = pitchlab::worlds::ResolveWorld(argv[1], PITCHLAB_WORLDS_DIR);
    spec.goal_m = Eigen::Vector2d(goal_x, goal_y);
    std::printf("world %s, goal (%.2f, %.2f) m\n", spec.world_file.c_str(), goal_x, goal_y);
    mission::SimMissionObserver observer;
    observer.on_progress = [](const std::string& text, double sim_s) {
      std::printf("[sim %5.0f s] %s\n", sim_s, text.c_str());
    };
    const mission::SimMissionOutcome run = mission::RunSimMission(spec, argv[4], observer);
    std::printf("%s: %s after %zu stops, final error %.3f m; run folder %s\n",
                run.result.success ? "success" : "FAILED", run.result.reason.c_str(),
                run.result.stops.size(), run.score.final_translation_error_m,
                run.folder.string().c_str());
    return run.result.success ? 0 : 1;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "run_mission: %s\n", e.what());
    return 1;
  }
}
