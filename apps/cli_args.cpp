#include "cli_args.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <limits>
#include <iostream>
#include <optional>
#include <set>
#include <sstream>

#include <CLI/CLI.hpp>

namespace pitchlab::apps {

namespace {

// --help laid out for long option descriptions: each option's names and value on one line, its
// description indented below (CLI11's default puts them in two columns, which long sentences
// overflow), then "(default: ...)" where pitchlab supplies one.
class HelpLayout : public CLI::Formatter {
 public:
  std::string make_help(const CLI::App* app, std::string, CLI::AppFormatMode) const override {
    std::ostringstream os;
    const std::vector<const CLI::Option*> options =
        app->get_options([](const CLI::Option*) { return true; });
    std::string positional;
    for (const CLI::Option* o : options) {
      if (o->get_positional()) positional = " " + o->get_type_name();
    }
    os << "usage: " << app->get_name() << positional << " [options]\n\n"
       << app->get_description() << "\n\n";
    const CLI::Option* help = app->get_help_ptr();
    for (const CLI::Option* o : options) {
      if (o == help) continue;  // last, below
      if (o->get_positional()) {
        os << "  " << o->get_type_name();
      } else {
        os << "  " << o->get_name(false, true);
        if (!o->get_type_name().empty()) os << " " << o->get_type_name();
      }
      os << "\n      " << o->get_description() << "\n";
    }
    os << "  " << help->get_name(false, true) << "\n      " << help->get_description() << "\n";
    return os.str();
  }
};

}  // namespace

struct CliArgs::Declared {
  std::string command;  ///< as in messages: "register", "hw emulate"
  CLI::App app;
  std::map<std::string, CLI::Option*> options;
  std::map<std::string, std::string> defaults;
  std::set<std::string> flags;
  std::string positional_name;
  int positional_min = 0, positional_max = 0;
};

CliArgs::CliArgs(std::string command, std::string summary)
    : declared_(std::make_unique<Declared>()) {
  declared_->command = command;
  CLI::App& app = declared_->app;
  app.name("pitchlab " + command);
  app.description(std::move(summary));
  app.formatter(std::make_shared<HelpLayout>());
  app.set_help_flag("-h,--help", "show this help");
  // Leftovers (unknown options, surplus positionals) are collected and worded in Parse.
  app.allow_extras();
}

CliArgs::CliArgs(CliArgs&&) noexcept = default;
CliArgs& CliArgs::operator=(CliArgs&&) noexcept = default;
CliArgs::~CliArgs() = default;

CliArgs& CliArgs::Option(const std::string& name, const std::string& metavar,
                         const std::string& help, std::optional<std::string> default_value) {
  std::string shown = help;
  if (default_value) {
    shown += " (default: " + *default_value + ")";
    declared_->defaults[name] = *default_value;
  }
  // Every occurrence is kept so Parse can name an option given twice.
  declared_->options[name] = declared_->app.add_option("--" + name)
                                 ->description(shown)
                                 ->type_name(metavar)
                                 ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  return *this;
}

CliArgs& CliArgs::Flag(const std::string& name, const std::string& help) {
  declared_->flags.insert(name);
  declared_->options[name] = declared_->app.add_flag("--" + name, help)
                                 ->multi_option_policy(CLI::MultiOptionPolicy::TakeAll);
  return *this;
}

CliArgs& CliArgs::Positionals(const std::string& name, const std::string& help, int min,
                              int max) {
  declared_->positional_name = name;
  declared_->positional_min = min;
  declared_->positional_max = max;
  // CLI11 names a positional with one word; the user sees `name` (e.g. "SOURCE TARGET").
  // It takes any number: Parse counts them and says what the command needs.
  declared_->app.add_option("positionals", positionals_, help)->type_name(name);
  return *this;
}

bool CliArgs::Parse(int argc, char** argv) {
  CLI::App& app = declared_->app;
  // CLI11 takes the arguments last first.
  std::vector<std::string> args(argv, argv + argc);
  const std::string& command = declared_->command;
  for (const std::string& arg : args) {
    if (arg == "--") break;
    // CLI11 reads `--flag=false` as "not given"; pitchlab's switches take no value at all.
    const auto eq = arg.find('=');
    if (arg.rfind("--", 0) == 0 && eq != std::string::npos &&
        declared_->flags.count(arg.substr(2, eq - 2)) > 0) {
      throw CliError(arg.substr(0, eq) + " takes no value");
    }
  }
  std::reverse(args.begin(), args.end());
  try {
    app.parse(args);
  } catch (const CLI::CallForHelp&) {
    std::cout << Usage();
    return false;
  } catch (const CLI::ParseError& e) {
    throw CliError(e.what());
  }
  for (const auto& [name, option] : declared_->options) {
    if (option->count() > 1) {
      throw CliError("--" + name + " given " + std::to_string(option->count()) +
                     " times: give it once");
    }
  }
  bool after_marker = false;  // after "--" everything is a positional
  int surplus = 0;            // positionals beyond what the command takes
  for (const std::string& extra : app.remaining()) {
    if (extra == "--" && !after_marker) {
      after_marker = true;
      continue;
    }
    ++surplus;
    if (!after_marker && extra.rfind("-", 0) == 0 && extra.size() > 1) {
      const std::string name = extra.substr(0, extra.find('='));
      throw CliError("unknown option '" + name + "' for '" + command + "' (see --help)");
    }
    if (declared_->positional_max == 0) throw CliError("unexpected argument '" + extra + "'");
  }
  const int n = static_cast<int>(positionals_.size()) + surplus;
  const int min = declared_->positional_min, max = declared_->positional_max;
  if (n < min || n > max) {
    throw CliError("'" + command + "' needs " +
                   (min == max ? std::to_string(min)
                               : std::to_string(min) + ".." + std::to_string(max)) +
                   " " + declared_->positional_name + " argument(s), got " + std::to_string(n));
  }
  return true;
}

std::string CliArgs::Usage() const { return declared_->app.help(); }

bool CliArgs::Has(const std::string& name) const {
  return Flagged(name) || declared_->defaults.count(name) > 0;
}

std::string CliArgs::Get(const std::string& name) const {
  const auto it = declared_->options.find(name);
  if (it != declared_->options.end() && it->second->count() > 0) {
    return it->second->results().front();
  }
  if (const auto d = declared_->defaults.find(name); d != declared_->defaults.end()) {
    return d->second;
  }
  throw CliError("'" + declared_->command + "' needs --" + name + " (see --help)");
}

bool CliArgs::Flagged(const std::string& name) const {
  const auto it = declared_->options.find(name);
  return it != declared_->options.end() && it->second->count() > 0;
}

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
                   " comma-separated numbers (" + declared_->options.at(name)->get_type_name() + ")");
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
