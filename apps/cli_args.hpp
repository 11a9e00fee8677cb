#pragma once
// pitchlab's subcommand options: `--name value` / `--name=value`, `--flag`, positionals, `--` before
// positionals that look like options, and a generated --help, parsed by CLI11 (cli_args.cpp keeps
// its header out of every other file). Errors throw CliError with a message for the user; the typed
// getters check numbers (finite, in range, whole) and name the option and the value.

#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

namespace pitchlab::apps {

/// A user mistake on the command line; main prints it with the subcommand's usage, exits 2.
struct CliError : std::runtime_error {
  using std::runtime_error::runtime_error;
};

/// Declares the options of one subcommand, then parses argv against them.
class CliArgs {
 public:
  CliArgs(std::string command, std::string summary);
  CliArgs(CliArgs&&) noexcept;
  CliArgs& operator=(CliArgs&&) noexcept;
  ~CliArgs();

  /// An option taking a value; `metavar` is shown in --help (e.g. "x,y,yaw").
  CliArgs& Option(const std::string& name, const std::string& metavar, const std::string& help,
                  std::optional<std::string> default_value = std::nullopt);
  /// A boolean switch.
  CliArgs& Flag(const std::string& name, const std::string& help);
  /// Positional arguments: `name` shown in --help; min..max of them accepted.
  CliArgs& Positionals(const std::string& name, const std::string& help, int min, int max);

  /// Parses argv (after the subcommand). Returns false when --help was asked (usage printed).
  /// An option given twice, an unknown option, a missing value or a value given to a flag is a
  /// CliError.
  bool Parse(int argc, char** argv);

  std::string Usage() const;
  bool Has(const std::string& name) const;               ///< given or defaulted
  std::string Get(const std::string& name) const;        ///< throws CliError when missing
  bool Flagged(const std::string& name) const;
  const std::vector<std::string>& positionals() const { return positionals_; }

  /// "1.5,-2,90" -> {1.5, -2, 90}; exactly `count` finite numbers or CliError naming the option.
  std::vector<double> GetNumbers(const std::string& name, std::size_t count) const;
  /// "1,2;3.5,-1" -> {{1, 2}, {3.5, -1}}: one or more points of two finite numbers each,
  /// ';'-separated, else CliError naming the option, the point and what is wrong with it.
  std::vector<std::pair<double, double>> GetPoints(const std::string& name) const;
  /// One number within [min, max] (max may be infinite: then "inf" is accepted too), else
  /// CliError naming the option, the value and the range.
  double GetNumber(const std::string& name, double min, double max) const;
  /// A whole number 0 .. 2^64-1 (a seed, a count), else CliError naming the option and the value.
  std::uint64_t GetWholeNumber(const std::string& name) const;

 private:
  struct Declared;  // the CLI11 app and what was declared on it (cli_args.cpp)
  std::unique_ptr<Declared> declared_;
  std::vector<std::string> positionals_;
};

/// "42" -> 42 (0 .. 2^64-1, digits only), else CliError "<what> '<text>' is not a whole number".
std::uint64_t ParseWholeNumber(const std::string& text, const std::string& what);

}  // namespace pitchlab::apps
