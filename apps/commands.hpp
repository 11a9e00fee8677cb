#pragma once
// The pitchlab subcommands. Each takes the arguments after its name and returns the exit code;
// errors a user can fix are thrown (CliError: exit 2; anything else: exit 1) and printed by main.

namespace pitchlab::apps {

/// `pitchlab scan`: one full 3D scan of a world written as PCD.
int RunScan(int argc, char** argv);
/// `pitchlab convert`: a point cloud (PCD, 3DTK, PLY, XYZ) written as pitchlab's PCD.
int RunConvert(int argc, char** argv);
/// `pitchlab register`: Algorithm 1 on two scans.
int RunRegister(int argc, char** argv);
/// `pitchlab merge`: scan-to-map merging of a scan sequence.
int RunMerge(int argc, char** argv);
/// `pitchlab map`: elevation map from clouds (lossless, ESRI grid, PNG).
int RunMap(int argc, char** argv);
/// `pitchlab plan`: traversability path on an elevation map.
int RunPlan(int argc, char** argv);
/// `pitchlab run`: the closed-loop mission, scored, with a run folder and report.
int RunRun(int argc, char** argv);
/// `pitchlab hw`: emulate devices on ptys driven by the simulator; read an LMS200.
int RunHw(int argc, char** argv);
/// `pitchlab bench`: a sweep of runs (worlds x seeds), each isolated, sharded, summarized.
int RunBench(int argc, char** argv);
/// `pitchlab worlds`: the built-in worlds and their metadata.
int RunWorlds(int argc, char** argv);

/// pitchlab's version (CMake's project version), for `pitchlab --version`.
const char* Version();
/// Turns off the libraries' own console output (PCL's), so pitchlab's message is the first line
/// a user reads; their failures still reach us as errors.
void SilenceLibraryConsoles();

}  // namespace pitchlab::apps
