// The simulated P3-AT driving, as a mission drives it: from each world's default start, 1 s
// straight at 0.4 m/s, a 90 deg turn on the spot at 60 deg/s, 1 s back the other way, a 90 deg
// turn back. One iteration = that 5.0 s of simulated driving; the counters split MuJoCo's time by
// its own stage timers (mjcb_time): collision and the constraint solve (noslip included); the
// contacts and the solver's iterations are sampled every 0.5 s.
// Worlds: PITCHLAB_WORLDS_DIR/{office,terrain}.xml (office: cylinders on a plane, analytic
// contacts; terrain: cylinders on a heightfield, convex-convex contacts through libccd).

#include <benchmark/benchmark.h>
#include <mujoco/mujoco.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <memory>
#include <stdexcept>
#include <string>

#include "pitchlab/sim/sim_rig.hpp"

namespace {

namespace fs = std::filesystem;
using pitchlab::sim::SimRig;

mjtNum NowMs() {
  using clock = std::chrono::steady_clock;
  return std::chrono::duration<mjtNum, std::milli>(clock::now().time_since_epoch()).count();
}

std::unique_ptr<SimRig> PlacedRig(const std::string& world) {
  const fs::path path = fs::path(PITCHLAB_WORLDS_DIR) / (world + ".xml");
  if (!fs::exists(path)) throw std::runtime_error("no world file " + path.string());
  auto rig = std::make_unique<SimRig>(path.string(), pitchlab::sim::SimRigConfig{});
  if (auto placed = rig->PlaceAtDefaultStart(); !placed) {
    throw std::runtime_error(world + ": " + placed.error().message);
  }
  return rig;
}

// Contacts and solver iterations summed over the steps (read after each Drive's last step).
struct Load {
  double contacts = 0, iterations = 0, samples = 0;
};

void DriveOneLeg(SimRig& rig, benchmark::State& state, Load& load) {
  constexpr double kTurn_rps = 60.0 * 3.14159265358979323846 / 180.0;
  for (const auto& [v, w, t] : {std::tuple{0.4, 0.0, 1.0}, std::tuple{0.0, kTurn_rps, 1.5},
                                std::tuple{0.4, 0.0, 1.0}, std::tuple{0.0, -kTurn_rps, 1.5}}) {
    for (double done = 0; done < t - 1e-9; done += 0.5) {
      if (auto odo = rig.base().Drive(v, w, std::min(0.5, t - done)); !odo) {
        state.SkipWithError(odo.error().message.c_str());
        return;
      }
      load.contacts += rig.sim().data()->ncon;
      load.iterations += rig.sim().data()->solver_iter;
      load.samples += 1;
    }
  }
}

void BM_Drive(benchmark::State& state, const std::string& world) {
  std::unique_ptr<SimRig> rig;
  try {
    rig = PlacedRig(world);
  } catch (const std::exception& e) {
    state.SkipWithError(e.what());
    return;
  }
  mjcb_time = NowMs;
  const mjData* d = rig->sim().data();
  const double step0 = d->timer[mjTIMER_STEP].duration;
  const double coll0 = d->timer[mjTIMER_POS_COLLISION].duration;
  const double cons0 = d->timer[mjTIMER_CONSTRAINT].duration;
  const int steps0 = d->timer[mjTIMER_STEP].number;
  Load load;
  for (auto _ : state) DriveOneLeg(*rig, state, load);
  mjcb_time = nullptr;
  const double steps = d->timer[mjTIMER_STEP].number - steps0;
  const double per_step_us = 1e3 / std::max(1.0, steps);
  const double coll = d->timer[mjTIMER_POS_COLLISION].duration - coll0;
  const double cons = d->timer[mjTIMER_CONSTRAINT].duration - cons0;
  state.counters["steps"] = steps;
  state.counters["contacts"] = load.contacts / std::max(1.0, load.samples);
  state.counters["solver_iterations"] = load.iterations / std::max(1.0, load.samples);
  state.counters["collision_us_per_step"] = coll * per_step_us;
  state.counters["constraint_us_per_step"] = cons * per_step_us;
  state.counters["mujoco_us_per_step"] = (d->timer[mjTIMER_STEP].duration - step0) * per_step_us;
  state.counters["sim_s_per_wall_s"] = benchmark::Counter(
      5.0 * static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}

BENCHMARK_CAPTURE(BM_Drive, office, std::string("office"))->Unit(benchmark::kMillisecond);
BENCHMARK_CAPTURE(BM_Drive, terrain, std::string("terrain"))->Unit(benchmark::kMillisecond);

}  // namespace

BENCHMARK_MAIN();
