#include "cli_args.hpp"

#include <charconv>
#include <cmath>
#include <limits>
#include <iostream>
#include <optional>
#include <sstream>

namespace pitchlab::apps {

CliArgs::CliArgs(std::string command, std::string summary)
    : command_(std::move(command)), summary_(std::move(summary)) {}

CliArgs& CliArgs::Option(const std::string& name, const std::string& metavar,
                         const std::string& help, std::optional<std::string> default_value) {
  order_.push_back(name);
  specs_[name] = Spec{metavar, help, std::move(default_value), false};
  return *this;
}

CliArgs& CliArgs::Flag(const std::string& name, const std::string& help) {
  order_.push_back(name);
  specs_[name] = Spec{"", help, std::nullopt, true};
  return *this;
}

CliArgs& CliArgs::Positionals(const std::string& name, const std::string& help, int min,
                              int max) {
  positional_name_ = name;
  positional_help_ = help;
  positional_min_ = min;
  positional_max_ = max;
  return *this;
}

bool CliArgs::Parse(int argc, char** argv) {
  for (int i = 0; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--help" || arg == "-h") {
      std::cout << Usage();
      return false;
    }
    if (arg.rfind("--", 0) == 0) {
      std::string name = arg.substr(2), value;
      const auto eq = name.find('=');
      const bool inline_value = eq != std::string::npos;
      if (inline_value) {
        value = name.substr(eq + 1);
        name = name.substr(0, eq);
      }
      auto it = specs_.find(name);
      if (it == specs_.end()) {
        throw CliError("unknown option '--" + name + "' for '" + command_ + "' (see --help)");
      }
      if (it->second.is_flag) {
        if (inline_value) throw CliError("--" + name + " takes no value");
        values_[name] = "true";
        continue;
      }
      if (!inline_value) {
        if (i + 1 >= argc) throw CliError("--" + name + " needs a value (" +
                                          it->second.metavar + ")");
        value = argv[++i];
      }
      values_[name] = value;
      continue;
    }
    positionals_.push_back(arg);
  }
  const int n = static_cast<int>(positionals_.size());
  if (n < positional_min_ || n > positional_max_) {
    if (positional_max_ == 0) throw CliError("unexpected argument '" + positionals_.front() + "'");
    throw CliError("'" + command_ + "' needs " +
                   (positional_min_ == positional_max_ ? std::to_string(positional_min_)
                                                       : std::to_string(positional_min_) + ".." +
                                                             std::to_string(positional_max_)) +
                   " " + positional_name_ + " argument(s), got " + std::to_string(n));
  }
  return true;
}

std::string CliArgs::Usage() const {
  std::ostringstream os;
  os << "usage: pitchlab " << command_;
  if (!positional_name_.empty()) os << " " << positional_name_;
  os << " [options]\n\n" << summary_ << "\n\n";
  if (!positional_name_.empty()) os << "  " << positional_name_ << "\n      " << positional_help_
                                    << "\n";
  for (const std::string& name : order_) {
    const Spec& s = specs_.at(name);
    os << "  --" << name;
    if (!s.is_flag) os << " " << s.metavar;
    os << "\n      " << s.help;
    if (s.default_value) os << " (default: " << *s.default_value << ")";
    os << "\n";
  }
  os << "  --help\n      show this help\n";
  return os.str();
}

bool CliArgs::Has(const std::string& name) const {
  return values_.count(name) > 0 || (specs_.count(name) && specs_.at(name).default_value);
}

std::string CliArgs::Get(const std::string& name) const {
  if (auto it = values_.find(name); it != values_.end()) return it->second;
  if (auto it = specs_.find(name); it != specs_.end() && it->second.default_value) {
    return *it->second.default_value;
  }
  throw CliError("'" + command_ + "' needs --" + name + " (see --help)");
}

bool CliArgs::Flagged(const std::string& name) const { return values_.count(name) > 0; }

namespace {

// `item` whole as a finite number, else nothing ("1.5x", "", "nan", "inf" are not).
std::optional<double> FiniteNumber(const std::string& item) {
  std::size_t used = 0;
  double v = 0;
  try {
    v = std::stod(item, &used);
  } catch (const std::exception&) {
    return std::nullopt;
  }
  if (used == 0 || used != item.size() || !std::isfinite(v)) return std::nullopt;
  return v;
}

}  // namespace

std::vector<double> CliArgs::GetNumbers(const std::string& name, std::size_t count) const {
  const std::string text = Get(name);
  std::vector<double> numbers;
  std::stringstream ss(text);
  std::string item;
  while (std::getline(ss, item, ',')) {
    const std::optional<double> v = FiniteNumber(item);
    if (!v) throw CliError("--" + name + " '" + text + "': '" + item + "' is not a number");
    numbers.push_back(*v);
  }
  if (numbers.size() != count) {
    throw CliError("--" + name + " '" + text + "' needs " + std::to_string(count) +
                   " comma-separated numbers (" + specs_.at(name).metavar + ")");
  }
  return numbers;
}

std::vector<std::pair<double, double>> CliArgs::GetPoints(const std::string& name) const {
  const std::string text = Get(name);
  std::vector<std::pair<double, double>> points;
  std::stringstream ss(text);
  std::string point;
  int k = 0;
  while (std::getline(ss, point, ';')) {
    ++k;
    const std::string where = "--" + name + " '" + text + "': point " + std::to_string(k) + " '" +
                              point + "' ";
    std::vector<double> xy;
    std::stringstream ps(point);
    std::string item;
    while (std::getline(ps, item, ',')) {
      const std::optional<double> v = FiniteNumber(item);
      if (!v) throw CliError(where + "has '" + item + "', not a number");
      xy.push_back(*v);
    }
    if (xy.size() != 2) throw CliError(where + "needs 2 comma-separated numbers (x,y)");
    points.emplace_back(xy[0], xy[1]);
  }
  // getline drops one trailing empty item: "1,2;" would pass as one point without this.
  if (points.empty() || text.back() == ';') {
    throw CliError("--" + name + " '" + text + "' needs x,y[;x,y...] (a point after each ';')");
  }
  return points;
}

double CliArgs::GetNumber(const std::string& name, double min, double max) const {
  const std::string text = Get(name);
  double v = 0;
  if (std::isinf(max) && (text == "inf" || text == "Inf")) {
    v = max;
  } else {
    v = GetNumbers(name, 1)[0];
  }
  if (!(v >= min && v <= max)) {
    std::ostringstream range;
    range << min << " .. " << max;
    throw CliError("--" + name + " '" + text + "' is out of range (" + range.str() + ")");
  }
  return v;
}

std::uint64_t CliArgs::GetWholeNumber(const std::string& name) const {
  return ParseWholeNumber(Get(name), "--" + name);
}

std::uint64_t ParseWholeNumber(const std::string& text, const std::string& what) {
  std::uint64_t value = 0;
  const char* end = text.data() + text.size();
  const auto [stop, error] = std::from_chars(text.data(), end, value);
  if (text.empty() || text.front() == '-' || error != std::errc() || stop != end) {
    throw CliError(what + " '" + text + "' is not a whole number 0 .. " +
                   std::to_string(std::numeric_limits<std::uint64_t>::max()));
  }
  return value;
}

}  // namespace pitchlab::apps
