// pitchlab: the command-line entry point. Dispatches to subcommands; the only place that catches
// and prints errors and picks the exit code (STYLE.md "Errors").

#include <cstring>
#include <exception>
#include <new>
#include <stdexcept>
#include <iostream>
#include <string>

#include "cli_args.hpp"
#include "commands.hpp"
#include "huge_pages.hpp"
#include "pitchlab/mission/cleanup_registry.hpp"
#include "pitchlab/mission/run_folder.hpp"

namespace {

struct Command {
  const char* name;
  int (*run)(int, char**);
  const char* summary;
};

constexpr Command kCommands[] = {
    {"run", pitchlab::apps::RunRun, "closed-loop stop-scan-go mission, scored, with a report"},
    {"bench", pitchlab::apps::RunBench, "sweep of runs over worlds x seeds: isolated, sharded, summarized"},
    {"scan", pitchlab::apps::RunScan, "one full 3D scan of a world, written as PCD"},
    {"convert", pitchlab::apps::RunConvert, "a point cloud (PCD, 3DTK .3d, PLY, XYZ) as pitchlab's PCD"},
    {"register", pitchlab::apps::RunRegister, "align two scans (Algorithm 1), result as JSON"},
    {"merge", pitchlab::apps::RunMerge, "merge a scan sequence into one map cloud + trajectory"},
    {"map", pitchlab::apps::RunMap, "elevation map from point clouds (Eq. 2-3)"},
    {"plan", pitchlab::apps::RunPlan, "traversability path on an elevation map (Eq. 4-5)"},
    {"hw", pitchlab::apps::RunHw, "hardware: emulate the devices on ptys, read an LMS200"},
    {"worlds", pitchlab::apps::RunWorlds, "list the built-in worlds"},
};

void PrintUsage(std::ostream& os) {
  os << "usage: pitchlab <command> [options]   (pitchlab <command> --help for its options)\n"
        "       pitchlab --version\n\n"
        "pitchlab: pitching-LMS200 3D mapping and elevation-map planning testbed\n\ncommands:\n";
  for (const Command& c : kCommands) os << "  " << c.name << "\t" << c.summary << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  if (argc >= 2 && !std::strcmp(argv[1], "--version")) {
    std::cout << "pitchlab " << pitchlab::apps::Version() << "\n";
    return 0;
  }
  // The long commands' buffers on huge pages (huge_pages.hpp): before anything else, as it may
  // start the program again.
  if (argc >= 2 && (!std::strcmp(argv[1], "run") || !std::strcmp(argv[1], "bench"))) {
    pitchlab::apps::UseHugePagesForLargeAllocations(argv);
  }
  // PCL prints its own diagnostics to stderr before ours reach the user; every PCL failure that
  // matters comes back to us as an error we word ourselves.
  pitchlab::apps::SilenceLibraryConsoles();
  if (argc < 2 || !std::strcmp(argv[1], "--help") || !std::strcmp(argv[1], "-h")) {
    PrintUsage(argc < 2 ? std::cerr : std::cout);
    return argc < 2 ? 2 : 0;
  }
  for (const Command& c : kCommands) {
    if (std::string(argv[1]) != c.name) continue;
    // An interruption's cleanup may make the command fail (its folder removed under it): the
    // watcher's exit status (130, 143) is the one that counts, so wait for it.
    try {
      const int code = c.run(argc - 2, argv + 2);
      pitchlab::mission::WaitIfInterrupted();
      return code;
    } catch (const pitchlab::apps::CliError& e) {
      pitchlab::mission::WaitIfInterrupted();
      std::cerr << "pitchlab " << c.name << ": " << e.what() << "\n";
      return 2;
    } catch (const std::bad_alloc&) {
      std::cerr << "pitchlab " << c.name << ": error: out of memory: an input or option asks "
                << "for more than this machine has (a size in a file header, a cell too small "
                << "for the area)\n";
      return 1;
    } catch (const std::length_error&) {  // std::vector's "vector::_M_default_append"
      std::cerr << "pitchlab " << c.name << ": error: an input or option asks for a size no "
                << "container can hold (a count in a file header, a cell too small for the area)\n";
      return 1;
    } catch (const std::exception& e) {
      pitchlab::mission::WaitIfInterrupted();
      std::cerr << "pitchlab " << c.name
                << ": error: " << pitchlab::mission::WithFinalPaths(e.what()) << "\n";
      return 1;
    }
  }
  std::cerr << "pitchlab: unknown command '" << argv[1] << "'\n\n";
  PrintUsage(std::cerr);
  return 2;
}
