#pragma once
// A bench folder's run records (runs.jsonl, one JSON object per run) and the per-run numbers its
// summary and `bench --compare` read from them.

#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pitchlab::apps {

using BenchRecord = nlohmann::ordered_json;  // records keep their field order

/// Every parseable record of `path` (none when it is missing); a torn last line, or any line
/// that is not a run record, is skipped with a line on stderr naming it.
std::vector<BenchRecord> ReadRecords(const std::filesystem::path& path);

/// runs.jsonl of a bench folder, or `item` itself when it names a file. Throws CliError (a
/// command-line mistake) when there is no such file.
std::filesystem::path RecordsFile(const std::string& item, const char* option);

/// The number at `key` of each record that has one (failed runs often have none).
std::vector<double> Numbers(const std::vector<const BenchRecord*>& records, const char* key);

/// Each run's false hazard cells per cell compared [%], where the run reported them.
std::vector<double> FalseHazardPercent(const std::vector<const BenchRecord*>& records);

}  // namespace pitchlab::apps
