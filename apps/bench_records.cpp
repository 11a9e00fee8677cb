#include "bench_records.hpp"

#include <cstdint>
#include <cstdio>
#include <fstream>

#include "cli_args.hpp"

namespace pitchlab::apps {

namespace fs = std::filesystem;

std::vector<BenchRecord> ReadRecords(const fs::path& path) {
  std::vector<BenchRecord> records;
  std::ifstream in(path);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (line.empty()) continue;
    BenchRecord record = BenchRecord::parse(line, nullptr, /*allow_exceptions=*/false);
    if (record.is_object() && record.contains("world") && record.contains("seed")) {
      records.push_back(std::move(record));
    } else {
      std::fprintf(stderr, "bench: %s line %d is not a run record; ignored\n",
                   path.string().c_str(), number);
    }
  }
  return records;
}

std::string RecordKey(const BenchRecord& record) {
  return record.value("world", std::string()) + "-s" +
         std::to_string(record.value("seed", std::uint64_t{0}));
}

RunsByWorld UniqueRunsByWorld(const std::vector<BenchRecord>& records, std::size_t* duplicates) {
  std::map<std::string, const BenchRecord*> unique;  // key -> first record
  std::size_t repeated = 0;
  for (const BenchRecord& r : records) repeated += !unique.emplace(RecordKey(r), &r).second;
  if (duplicates) *duplicates = repeated;
  RunsByWorld by_world;
  for (const auto& [key, r] : unique) {
    by_world[r->value("world", std::string())].push_back(r);
  }
  return by_world;
}

fs::path RecordsFile(const std::string& item, const char* option) {
  const fs::path file = fs::is_directory(item) ? fs::path(item) / "runs.jsonl" : fs::path(item);
  if (!fs::is_regular_file(file)) {
    throw CliError(std::string(option) + ": no runs.jsonl at '" + file.string() + "'");
  }
  return file;
}

std::vector<double> Numbers(const std::vector<const BenchRecord*>& records, const char* key) {
  std::vector<double> v;
  for (const BenchRecord* r : records) {
    if (r->contains(key) && (*r)[key].is_number()) v.push_back((*r)[key].get<double>());
  }
  return v;
}

std::vector<double> FalseHazardPercent(const std::vector<const BenchRecord*>& records) {
  std::vector<double> v;
  for (const BenchRecord* r : records) {
    const BenchRecord& f = r->value("false_hazard_cells", BenchRecord());
    const BenchRecord& n = r->value("map_cells_compared", BenchRecord());
    if (f.is_number() && n.is_number() && n.get<double>() > 0) {
      v.push_back(100.0 * f.get<double>() / n.get<double>());
    }
  }
  return v;
}

}  // namespace pitchlab::apps
