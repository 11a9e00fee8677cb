#pragma once
// The output folder and file helpers of `map` and `plan`, which stage their output as runs do:
// the mission library's, under the names those commands use.

#include "pitchlab/mission/run_folder.hpp"

namespace pitchlab::apps {

using mission::RunFolder;
using mission::WriteTextFile;

}  // namespace pitchlab::apps
