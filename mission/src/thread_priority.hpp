#pragma once
// Private: work beside the mission yields the cores to it.

namespace pitchlab::mission {

/// Raises the calling thread's nice value by `by` (Linux: per thread, inherited by the threads
/// it starts; at most 19). Lowering one's own priority needs no privilege; where it is refused
/// the thread runs on as it was.
void LowerThisThreadsPriority(int by);

}  // namespace pitchlab::mission
