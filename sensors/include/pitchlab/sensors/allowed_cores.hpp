#pragma once
// How many cores this process may run on, for the code that spreads work over them (parallel
// loops, the simulated scanner's casting thread). Here, at the bottom of the module graph, beside
// the stopwatch, so that every module counts them alike.

namespace pitchlab::sensors {

/// The cores in this process's CPU affinity (taskset, a cluster job's cpuset), at least 1:
/// std::thread::hardware_concurrency counts the machine's, and a run given one core of 64 would
/// start threads for all of them.
unsigned AllowedCores();

}  // namespace pitchlab::sensors
