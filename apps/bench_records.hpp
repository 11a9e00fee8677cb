#pragma once
// A bench folder's run records (runs.jsonl, one JSON object per run) and the per-run numbers its
// summary and `bench --compare` read from them.

#include <cstddef>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

namespace pitchlab::apps {

using BenchRecord = nlohmann::ordered_json;  // records keep their field order

/// Every parseable record of `path` (none when it is missing); a torn last line, or any line
/// that is not a run record, is skipped with a line on stderr naming it.
std::vector<BenchRecord> ReadRecords(const std::filesystem::path& path);

/// "<world>-s<seed>": one run of a sweep.
std::string RecordKey(const BenchRecord& record);

/// The runs of `records` by world (worlds and, within one, runs in key order), each run once: the
/// first of its records (a resumed or merged sweep may hold a run twice). `duplicates`, when
/// given, gets how many records were left out.
using RunsByWorld = std::map<std::string, std::vector<const BenchRecord*>>;
RunsByWorld UniqueRunsByWorld(const std::vector<BenchRecord>& records,
                              std::size_t* duplicates = nullptr);

/// runs.jsonl of a bench folder, or `item` itself when it names a file. Throws CliError (a
/// command-line mistake) when there is no such file.
std::filesystem::path RecordsFile(const std::string& item, const char* option);

/// The number at `key` of each record that has one (failed runs often have none).
std::vector<double> Numbers(const std::vector<const BenchRecord*>& records, const char* key);

/// Each run's false hazard cells per cell compared [%], where the run reported them.
std::vector<double> FalseHazardPercent(const std::vector<const BenchRecord*>& records);

}  // namespace pitchlab::apps
