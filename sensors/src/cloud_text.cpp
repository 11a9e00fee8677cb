#include "cloud_text.hpp"

#include <cctype>
#include <charconv>
#include <filesystem>

namespace pitchlab::sensors::detail {

std::vector<std::string_view> SplitFields(std::string_view line) {
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  std::vector<std::string_view> fields;
  constexpr std::string_view kSeparators = " \t,";
  std::size_t start = line.find_first_not_of(kSeparators);
  while (start != std::string_view::npos) {
    const std::size_t end = line.find_first_of(kSeparators, start);
    fields.push_back(line.substr(start, end == std::string_view::npos ? end : end - start));
    start = end == std::string_view::npos ? end : line.find_first_not_of(kSeparators, end);
  }
  return fields;
}

std::optional<double> ParseNumber(std::string_view token) {
  if (!token.empty() && token.front() == '+') {  // from_chars refuses a '+' sign: drop one
    token.remove_prefix(1);
    if (!token.empty() && (token.front() == '+' || token.front() == '-')) return std::nullopt;
  }
  double value = 0.0;
  const auto [end, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
  if (ec != std::errc() || end != token.data() + token.size()) return std::nullopt;
  return value;
}

bool IsBlankOrComment(std::string_view line) {
  const std::size_t first = line.find_first_not_of(" \t\r");
  return first == std::string_view::npos || line[first] == '#';
}

ScanPoint MakePoint(const Eigen::Vector3d& p_m, const Eigen::Vector3d& sensor_m) {
  ScanPoint p;
  p.x = static_cast<float>(p_m.x());
  p.y = static_cast<float>(p_m.y());
  p.z = static_cast<float>(p_m.z());
  p.range_m = static_cast<float>((p_m - sensor_m).norm());
  return p;
}

std::string LowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

}  // namespace pitchlab::sensors::detail
