// The hardware swap-in end to end: `pitchlab hw emulate` puts an emulated LMS200, pitch unit and
// P3 on pseudo-terminals, driven by the simulator in the yard world; `pitchlab run --backend hw`
// drives the same mission through the serial drivers; its elevation map must agree with a
// simulated run's within noise.

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>
#include <nlohmann/json.hpp>

#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"
#include "pitchlab/hw/pitch_unit_emulator.hpp"
#include "pitchlab/hw/serial_port.hpp"
#include "pitchlab/mapping/elevation_io.hpp"

#include "cli_support.hpp"
#include "scoped_temp_dir.hpp"

namespace pitchlab {
namespace {

namespace fs = std::filesystem;
using cli_test::CliResult;
using cli_test::Slurp;

const fs::path kYard = fs::path(PITCHLAB_SOURCE_DIR) / "tests/data/worlds/yard.xml";
// Both runs: a reduced scan (50 lines over 50 deg at 1 deg: a 38400-baud line still takes
// ~0.1 s of wall time) and the same short mission, 2.5 m on from the yard's default start (in
// simulation it arrives in 4 stops for each of seeds 1..16).
constexpr char kSharedConfig[] =
    "seed: 3\n"
    "scan: {lines: 50, pitch_start_deg: -15, pitch_end_deg: 35}\n"
    "lms200: {resolution_deg: 1}\n";
constexpr char kMission[] = " --goal=-3,0 --quiet";
constexpr int kEmulatorStartTimeout_ms = 30000;

// `pitchlab hw emulate` as a child process; its device paths parsed from the JSON it prints.
// `baud` empty: the devices' power-on rates (no --baud).
class Emulators {
 public:
  Emulators(const fs::path& config, const fs::path& log, const std::string& baud = "38400") {
    int out[2];
    if (::pipe(out) != 0) return;
    pid_ = ::fork();
    if (pid_ == 0) {
      ::dup2(out[1], STDOUT_FILENO);
      const int err = ::open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      ::dup2(err, STDERR_FILENO);
      ::close(out[0]);
      ::close(out[1]);
      if (baud.empty()) {
        ::execl(PITCHLAB_CLI, PITCHLAB_CLI, "hw", "emulate", "--world", kYard.c_str(), "--config",
                config.c_str(), "--json", static_cast<char*>(nullptr));
      } else {
        ::execl(PITCHLAB_CLI, PITCHLAB_CLI, "hw", "emulate", "--world", kYard.c_str(), "--config",
                config.c_str(), "--baud", baud.c_str(), "--json", static_cast<char*>(nullptr));
      }
      ::_exit(127);
    }
    ::close(out[1]);
    stdout_ = out[0];
    ReadPaths();
  }
  ~Emulators() {
    if (pid_ > 0) {
      ::kill(pid_, SIGTERM);
      int status = 0;
      ::waitpid(pid_, &status, 0);
    }
    if (stdout_ >= 0) ::close(stdout_);
  }
  const nlohmann::json& paths() const { return paths_; }

 private:
  void ReadPaths() {
    std::string text;
    const auto deadline =
        std::chrono::steady_clock::now() + std::chrono::milliseconds(kEmulatorStartTimeout_ms);
    while (std::chrono::steady_clock::now() < deadline) {
      pollfd p{stdout_, POLLIN, 0};
      if (::poll(&p, 1, 200) <= 0) continue;
      char buffer[512];
      const ssize_t n = ::read(stdout_, buffer, sizeof(buffer));
      if (n <= 0) return;  // the emulator died: paths_ stays empty
      text.append(buffer, static_cast<std::size_t>(n));
      paths_ = nlohmann::json::parse(text, nullptr, /*allow_exceptions=*/false);
      if (!paths_.is_discarded()) return;
    }
    paths_ = nlohmann::json();
  }

  pid_t pid_ = -1;
  int stdout_ = -1;
  nlohmann::json paths_;
};

// `pitchlab <args>` in the background (stderr to `err`), for a test that signals it.
class Background {
 public:
  Background(const std::vector<std::string>& args, const fs::path& err) {
    std::vector<char*> argv = {const_cast<char*>(PITCHLAB_CLI)};
    for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
    argv.push_back(nullptr);
    const std::string err_path = err.string();
    pid_ = ::fork();  // after it only async-signal-safe calls: argv is built above
    if (pid_ == 0) {
      const int fd = ::open(err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
      const int null = ::open("/dev/null", O_WRONLY);
      ::dup2(fd, STDERR_FILENO);
      ::dup2(null, STDOUT_FILENO);
      ::execv(PITCHLAB_CLI, argv.data());
      ::_exit(127);
    }
  }
  ~Background() {
    if (pid_ > 0 && !exited_) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  // Waits until `pred` holds; false if the process ended first or 60 s passed.
  template <typename Pred>
  bool Until(Pred pred) {
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(60);
    while (!pred()) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        return false;
      }
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    return true;
  }
  // Sends `signal` and returns the exit code (-1 when killed by a signal).
  int Signal(int signal) {
    ::kill(pid_, signal);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    exited_ = true;
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  }

 private:
  pid_t pid_ = -1;
  bool exited_ = false;
};

// Within a second (the emulated P3's watchdog takes 2 s, so a stop seen sooner was sent).
template <typename Pred>
bool Soon(Pred pred) {
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(1);
  while (!pred()) {
    if (std::chrono::steady_clock::now() > deadline) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return true;
}

class HwRunCli : public ::testing::Test {
 protected:
  CliResult Exec(const std::string& args) const { return cli_test::RunPitchlab(args, dir_.path()); }
  fs::path Write(const std::string& name, const std::string& text) const {
    std::ofstream(dir_ / name) << text;
    return dir_ / name;
  }
  const test_support::ScopedTempDir dir_{"hw_run_cli"};
};

// Mean heights of the cells both maps observed (at least `min_points` each, with a vertical
// spread below `max_spread_m` in both): RMSE and count. A cell on a wall face has no one height:
// its mean is wherever the laser happened to hit the face, so it differs between any two runs.
struct Agreement {
  double rmse_m = 0;
  std::size_t cells = 0;
};
Agreement CompareMaps(const mapping::ElevationMap& a, const mapping::ElevationMap& b,
                      std::uint32_t min_points, double max_spread_m) {
  double sum = 0;
  Agreement r;
  for (std::size_t k = 0; k < a.cells().size(); ++k) {
    const mapping::CellStats &p = a.at(k), &q = b.at(k);
    if (p.count < min_points || q.count < min_points) continue;
    if (p.max_z - p.min_z >= max_spread_m || q.max_z - q.min_z >= max_spread_m) continue;
    sum += (p.mean_z - q.mean_z) * (p.mean_z - q.mean_z);
    ++r.cells;
  }
  r.rmse_m = r.cells ? std::sqrt(sum / r.cells) : 0;
  return r;
}

// Intersection over union of the cells holding a point above `height_m`: where two maps put
// the walls and obstacles. A misplaced map shifts them into other cells.
double ObstacleOverlap(const mapping::ElevationMap& a, const mapping::ElevationMap& b,
                       double height_m) {
  std::size_t both = 0, either = 0;
  for (std::size_t k = 0; k < a.cells().size(); ++k) {
    const bool in_a = a.at(k).known() && a.at(k).max_z > height_m;
    const bool in_b = b.at(k).known() && b.at(k).max_z > height_m;
    both += in_a && in_b;
    either += in_a || in_b;
  }
  return either ? double(both) / double(either) : 0.0;
}

TEST_F(HwRunCli, AMissionOverTheEmulatedDevicesMapsTheYardLikeTheSimulator) {
  const fs::path emulator_config = Write("emulator.yaml", kSharedConfig);
  Emulators emulators(emulator_config, dir_ / "emulator.log");
  ASSERT_TRUE(emulators.paths().contains("lms200")) << Slurp(dir_ / "emulator.log");
  const nlohmann::json& p = emulators.paths();
  const fs::path hw_config = Write(
      "hw.yaml", std::string(kSharedConfig) + "backend: hw\nhw:\n" +
                     "  lms200: {device: " + p["lms200"].get<std::string>() + ", baud: 38400}\n" +
                     "  pitch_unit: {device: " + p["pitch_unit"].get<std::string>() +
                     ", baud: 38400}\n" + "  base: {device: " + p["base"].get<std::string>() +
                     ", baud: 38400}\n");

  // The emulated robot stands at the yard's default start: tell the run where that is.
  const CliResult hw = Exec("run --config " + hw_config.string() + " --world " + kYard.string() +
                            " --start -5.5,0,0 --json --out " + (dir_ / "hw").string() + kMission);
  ASSERT_EQ(hw.exit_code, 0) << hw.err << hw.out << Slurp(dir_ / "emulator.log");
  const nlohmann::json metrics = nlohmann::json::parse(hw.out);
  EXPECT_TRUE(metrics["success"].get<bool>()) << metrics["reason"];
  EXPECT_FALSE(metrics.contains("cost_ratio"));  // no truth on hardware: no scoring
  EXPECT_FALSE(metrics.contains("final_pose_error"));
  EXPECT_FALSE(fs::exists(dir_ / "hw/truth_elevation.png"));
  EXPECT_TRUE(fs::exists(dir_ / "hw/stops/000/scan.pcd"));
  const YAML::Node used = YAML::LoadFile((dir_ / "hw/config.yaml").string());
  EXPECT_EQ(used["backend"].as<std::string>(), "hw");
  EXPECT_EQ(used["hw"]["lms200"]["baud"].as<int>(), 38400);

  // The simulated run of the same mission, and one with another seed: the noise floor.
  const fs::path sim_config = Write("sim.yaml", kSharedConfig);
  for (const char* seed : {"3", "4"}) {
    const CliResult sim =
        Exec("run --config " + sim_config.string() + " --world " + kYard.string() + " --seed " +
             seed + " --out " + (dir_ / ("sim" + std::string(seed))).string() + kMission);
    ASSERT_EQ(sim.exit_code, 0) << sim.err;
  }
  const auto hw_map = mapping::LoadElevationMap((dir_ / "hw/elevation.plem").string());
  const auto sim_map = mapping::LoadElevationMap((dir_ / "sim3/elevation.plem").string());
  const auto other_map = mapping::LoadElevationMap((dir_ / "sim4/elevation.plem").string());
  ASSERT_TRUE(hw_map && sim_map && other_map);
  ASSERT_TRUE(hw_map->geometry().SameAs(sim_map->geometry()));

  // Where the map has a height (the floor, tops of things): within range noise and quantization.
  constexpr double kSurfaceRmse_m = 0.02;
  constexpr double kSurfaceSpread_m = 0.1;  // vertical spread of a cell that is a surface
  constexpr std::uint32_t kMinPoints = 3;
  constexpr std::size_t kMinSurfaceCells = 400;  // of the floor around the drive
  const Agreement surface = CompareMaps(*hw_map, *sim_map, kMinPoints, kSurfaceSpread_m);
  EXPECT_GT(surface.cells, kMinSurfaceCells);
  EXPECT_LT(surface.rmse_m, kSurfaceRmse_m) << surface.cells << " surface cells in common";
  // Where things stand (walls, crates): the same cells, as between two simulated runs that differ
  // only in their seed (seen with a 60-line scan: 0.93 both; a start given 0.3 m off: 0.002).
  constexpr double kObstacleHeight_m = 0.2;
  constexpr double kNoiseFactor = 0.85;
  const double hw_iou = ObstacleOverlap(*hw_map, *sim_map, kObstacleHeight_m);
  const double noise_iou = ObstacleOverlap(*other_map, *sim_map, kObstacleHeight_m);
  EXPECT_GT(hw_iou, kNoiseFactor * noise_iou) << "seed 3 vs 4: " << noise_iou;
}

TEST_F(HwRunCli, AHardwareRunWithoutDevicesSaysWhichSettingIsMissing) {
  const fs::path config = Write("no_devices.yaml", "backend: hw\nhw: {lms200: {baud: 38400}}\n");
  const CliResult r = Exec("run --quiet --goal 1,0 --config " + config.string() + " --out " +
                           (dir_ / "none").string());
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("hw.lms200.device is required"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "none"));

  const CliResult bad = Exec("run --quiet --backend robot");
  EXPECT_EQ(bad.exit_code, 2);
  EXPECT_NE(bad.err.find("--backend 'robot' is not a backend"), std::string::npos) << bad.err;

  const CliResult absent = Exec("run --quiet --backend hw --goal 1,0 --config " +
                                Write("gone.yaml",
                                      "hw:\n  lms200: {device: /nonexistent/tty}\n"
                                      "  pitch_unit: {device: /nonexistent/tty1}\n"
                                      "  base: {device: /nonexistent/tty2}\n")
                                    .string() +
                                " --out " + (dir_ / "gone").string());
  EXPECT_EQ(absent.exit_code, 1);
  EXPECT_NE(absent.err.find("/nonexistent/tty"), std::string::npos) << absent.err;
  EXPECT_FALSE(fs::exists(dir_ / "gone"));
}

// Ctrl-C in a hardware run: the base is stopped with its motors disabled, the LMS200 stops
// streaming, no run folder (nor its hidden staging folder) is left, and the exit code is 130
// with a message saying so. The devices are emulated in this process, so their state is read
// directly the moment the run has exited.
TEST_F(HwRunCli, CtrlCWhileTheBaseTurnsStopsItAndLeavesNoRunFolder) {
  hw::Lms200Emulator lms{hw::Lms200EmulatorConfig{}};
  hw::PitchUnitEmulator pitch{sensors::PitchUnitConfig{}};
  hw::P2osEmulator base{hw::P2osEmulatorConfig{38400}};
  const fs::path config =
      Write("ctrl_c.yaml",
            std::string(kSharedConfig) + "backend: hw\nhw:\n" + "  lms200: {device: " + lms.path() +
                ", baud: 38400, continuous: true}\n" + "  pitch_unit: {device: " + pitch.path() +
                ", baud: 38400}\n" + "  base: {device: " + base.path() + ", baud: 38400}\n");
  const fs::path out = dir_ / "interrupted", err = dir_ / "interrupted.err";
  // The goal is behind the robot: the mission begins by turning in place to face it.
  Background run(
      {"run", "--config", config.string(), "--goal=-6,0", "--out", out.string(), "--quiet"}, err);
  ASSERT_TRUE(run.Until([&] { return base.command().second != 0.0; })) << Slurp(err);
  ASSERT_TRUE(base.motors_enabled());
  ASSERT_TRUE(lms.streaming());
  EXPECT_EQ(run.Signal(SIGINT), 130) << Slurp(err);
  const std::string message = Slurp(err);
  EXPECT_NE(message.find("interrupted by SIGINT"), std::string::npos) << message;
  EXPECT_NE(message.find("no run folder written"), std::string::npos) << message;
  EXPECT_TRUE(Soon([&] { return !base.motors_enabled(); })) << "motors left enabled";
  EXPECT_EQ(base.command(), std::make_pair(0.0, 0.0));
  EXPECT_TRUE(Soon([&] { return !lms.streaming(); })) << "LMS200 left streaming";
  EXPECT_FALSE(fs::exists(out));
  for (const auto& entry : fs::directory_iterator(dir_.path())) {
    EXPECT_EQ(entry.path().filename().string().rfind(".interrupted", 0), std::string::npos)
        << "staging folder left: " << entry.path();
  }
}

TEST_F(HwRunCli, SigtermWhileHwLms200WaitsForASilentDeviceEndsWithTheSignalsCode) {
  hw::Lms200Emulator lms{hw::Lms200EmulatorConfig{}};
  hw::FaultPlan silent;
  silent.kind = hw::FaultPlan::Kind::kSilent;
  lms.SetFaults(silent);  // the driver keeps probing baud rates: a long wait to interrupt
  const fs::path err = dir_ / "lms200.err";
  Background scan({"hw", "lms200", "--device", lms.path(), "--baud", "38400", "--once", "--json"},
                  err);
  ASSERT_TRUE(scan.Until([&] { return lms.stats().requests > 0; })) << Slurp(err);
  EXPECT_EQ(scan.Signal(SIGTERM), 128 + SIGTERM) << Slurp(err);
  const std::string message = Slurp(err);
  EXPECT_NE(message.find("hw lms200: interrupted by SIGTERM"), std::string::npos) << message;
  EXPECT_FALSE(lms.streaming());
}

// ---------------------------------------------------------------------------------------------
// `hw emulate` as a Pioneer client meets it (issue 17, items 6, 7, 8, 11): literal packets to
// the base wired to the simulated P3-AT, at the rate a P3 opens at.

using Bytes = std::vector<std::uint8_t>;
using Clock = std::chrono::steady_clock;
using std::chrono::milliseconds;

// The client end of a serial line, with pitchlab's P2OS framing for the replies.
class Line {
 public:
  Line(const std::string& device, int baud) : port_(device, baud) {}
  void Write(const Bytes& bytes) { ASSERT_TRUE(port_.Write(bytes)); }
  void Flush() {
    port_.DiscardInput();
    reader_.Clear();
  }
  std::optional<Bytes> Packet(milliseconds timeout = milliseconds(1000)) {
    const auto deadline = Clock::now() + timeout;
    std::uint8_t buffer[256];
    for (;;) {
      if (auto payload = reader_.Next()) return *payload;
      const auto left = std::chrono::duration_cast<milliseconds>(deadline - Clock::now());
      if (left.count() <= 0) return std::nullopt;
      Result<std::size_t> n = port_.Read(buffer, sizeof(buffer), left);
      if (n) reader_.Feed(buffer, *n);
    }
  }
  std::optional<Bytes> Sip() {
    while (auto p = Packet()) {
      if ((*p)[0] == 0x32 || (*p)[0] == 0x33) return p;
    }
    return std::nullopt;
  }
  hw::SerialPort& port() { return port_; }

 private:
  hw::SerialPort port_;
  hw::p2os::PacketReader reader_;
};

const Bytes kSync0 = {0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00};
const Bytes kSync1 = {0xFA, 0xFB, 0x03, 0x01, 0x00, 0x01};  // also OPEN once synced
const Bytes kSync2 = {0xFA, 0xFB, 0x03, 0x02, 0x00, 0x02};
const Bytes kEnable1 = {0xFA, 0xFB, 0x06, 0x04, 0x3B, 0x01, 0x00, 0x05, 0x3B};
const Bytes kClose = {0xFA, 0xFB, 0x03, 0x02, 0x00, 0x02};  // CLOSE once open
const Bytes kPulse = {0xFA, 0xFB, 0x03, 0x00, 0x00, 0x00};  // PULSE once open

int Le16s(const Bytes& p, std::size_t at) { return std::int16_t(p[at] | (p[at + 1] << 8)); }

class HwEmulate : public HwRunCli {
 protected:
  void SetUp() override {
    emulators_ = std::make_unique<Emulators>(Write("emulator.yaml", kSharedConfig),
                                             dir_ / "emulator.log", "");
    ASSERT_TRUE(emulators_->paths().contains("base")) << Slurp(dir_ / "emulator.log");
  }
  std::string Path(const char* device) const { return emulators_->paths()[device]; }
  // ROS p2os's Setup at 9600: SYNC0/1/2 echoed, OPEN, ENABLE 1.
  void Connect(Line& base) {
    for (const Bytes* step : {&kSync0, &kSync1, &kSync2}) {
      base.Write(*step);
      const auto echo = base.Packet();
      ASSERT_TRUE(echo) << "no echo at 9600";
      ASSERT_EQ((*echo)[0], (*step)[3]);
    }
    base.Write(kSync1);
    base.Write(kEnable1);
  }
  std::unique_ptr<Emulators> emulators_;
};

// Beside the paths (stdout, for scripts) it says on stderr what each one is, at which rate, and
// how to stop it (issue 18: three bare pty paths said neither).
TEST_F(HwEmulate, SaysWhatEachDeviceIsAndHowToStop) {
  const std::string said = Slurp(dir_ / "emulator.log");
  for (const char* what : {"SICK LMS200", "pitching servo", "Pioneer P3", "9600 baud",
                           "--backend hw", "Ctrl-C"}) {
    EXPECT_NE(said.find(what), std::string::npos) << "no '" << what << "' in:\n" << said;
  }
}

TEST_F(HwEmulate, TheBaseAnswersAt9600WhereAP3OpensItsHostPort) {
  Line base(Path("base"), 9600);
  base.Write(kSync0);
  const auto echo = base.Packet();
  ASSERT_TRUE(echo) << "no SYNC0 echo at 9600";
  EXPECT_EQ(*echo, Bytes{0x00});
}

TEST_F(HwEmulate, Vel2TurnsTheSimulatedWheelsAtTheCommandedSpeeds) {
  Line base(Path("base"), 9600);
  Connect(base);
  // VEL2 left 200, right 300 mm/s.
  base.Write({0xFA, 0xFB, 0x06, 0x20, 0x3B, 0x0F, 0x0A, 0x2F, 0x45});
  // The P3's acceleration ramp (0.5 m/s^2), then steady; a PULSE every 0.5 s as ROS p2os's
  // loop sends one, or the 2 s watchdog stops the robot.
  for (int i = 0; i < 3; ++i) {
    std::this_thread::sleep_for(milliseconds(500));
    base.Write(kPulse);
  }
  base.Flush();
  double left = 0, right = 0;
  constexpr int kSips = 5;
  for (int i = 0; i < kSips; ++i) {
    const auto sip = base.Sip();
    ASSERT_TRUE(sip);
    left += Le16s(*sip, 7) / double(kSips);
    right += Le16s(*sip, 9) / double(kSips);
  }
  // The simulated encoders' speeds are ticks (1.4 mm) over a 0.1 s window: 14 mm/s steps.
  constexpr double kWheelSpeedTolerance_mmps = 20.0;
  EXPECT_NEAR(left, 200.0, kWheelSpeedTolerance_mmps);
  EXPECT_NEAR(right, 300.0, kWheelSpeedTolerance_mmps);
  base.Write(kClose);
}

TEST_F(HwEmulate, AParkedBaseReportsAConstantPoseAndZeroSpeeds) {
  Line base(Path("base"), 9600);
  Connect(base);
  std::this_thread::sleep_for(milliseconds(500));
  base.Flush();
  const auto first = base.Sip();
  ASSERT_TRUE(first);
  // 12 s: the simulated gyro's drift (0.8 deg/min) would move THPOS by 2 units (0.088 deg).
  const auto until = Clock::now() + std::chrono::seconds(12);
  int sips = 0;
  while (Clock::now() < until) {
    const auto sip = base.Sip();
    ASSERT_TRUE(sip);
    ++sips;
    ASSERT_EQ((*sip)[0], 0x32) << "SIP " << sips << " says moving";
    ASSERT_EQ(Bytes(sip->begin() + 1, sip->begin() + 11),
              Bytes(first->begin() + 1, first->begin() + 11))
        << "SIP " << sips << ": pose or wheel speeds changed (x, y, th, l, r at 1..10)";
  }
  EXPECT_GT(sips, 100);
  base.Write(kClose);
}

TEST_F(HwEmulate, PowerCyclingTheLaserThroughTheBaseRestartsItAt9600) {
  Line laser(Path("lms200"), 9600);
  // The laser to 38400 (20 40), as a client leaves it.
  laser.Write({0x02, 0x00, 0x02, 0x00, 0x20, 0x40, 0x50, 0x08});
  std::this_thread::sleep_for(milliseconds(300));
  ASSERT_TRUE(laser.port().SetBaud(9600));
  laser.port().DiscardInput();
  Line base(Path("base"), 9600);
  Connect(base);
  // ARIA: com2Bytes(31, 11, 0), a second, com2Bytes(31, 11, 1).
  base.Write({0xFA, 0xFB, 0x06, 0x1F, 0x3B, 0x00, 0x0B, 0x1F, 0x46});
  std::this_thread::sleep_for(milliseconds(1000));
  base.Write({0xFA, 0xFB, 0x06, 0x1F, 0x3B, 0x01, 0x0B, 0x20, 0x46});
  // The power-on telegram at 9600: 02 80 LEN 90 "LMS200;30106..."
  hw::lms200::TelegramReader reader;
  std::uint8_t buffer[256];
  const auto deadline = Clock::now() + milliseconds(3000);
  std::optional<hw::lms200::Telegram> power_on;
  while (!power_on && Clock::now() < deadline) {
    Result<std::size_t> n = laser.port().Read(buffer, sizeof(buffer), milliseconds(100));
    if (n) reader.Feed(buffer, *n);
    while (auto e = reader.Next()) {
      if (e->kind == hw::lms200::ReaderEvent::Kind::kTelegram && e->telegram.command == 0x90) {
        power_on = e->telegram;
      }
    }
  }
  ASSERT_TRUE(power_on) << "no power-on telegram at 9600 after the power cycle";
  EXPECT_EQ(std::string(power_on->data.begin(), power_on->data.begin() + 12), "LMS200;30106");
  base.Write(kClose);
}

}  // namespace
}  // namespace pitchlab
