// `pitchlab hw`: the hardware layer from the command line.
//   hw emulate --world NAME   emulated LMS200, pitch unit and P3 driven by the simulator
//   hw lms200 --device PATH   one scan from a (real or emulated) LMS200, as JSON

#include <atomic>
#include <csignal>
#include <cstdio>
#include <iostream>
#include <map>
#include <memory>
#include <mutex>
#include <thread>

#include <nlohmann/json.hpp>

#include "pitchlab/mission/app_config.hpp"
#include "cli_args.hpp"
#include "commands.hpp"
#include "pitchlab/hw/lms200_driver.hpp"
#include "pitchlab/hw/lms200_emulator.hpp"
#include "pitchlab/hw/p2os_emulator.hpp"
#include "pitchlab/hw/pitch_unit_emulator.hpp"
#include "pitchlab/hw/stop_request.hpp"
#include "pitchlab/sim/sim_rig.hpp"
#include "pitchlab/worlds/world_catalog.hpp"
#include "world_paths.hpp"

namespace pitchlab::apps {

namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr double kRadToDeg = 180.0 / kPi;
// Power-on rates: a P3 opens its host port at 9600 (ARIA and ROS p2os connect there); the pitch
// unit's protocol defaults to 38400 (docs/pitch_unit_protocol.md).
constexpr int kBasePowerOnBaud = 9600;
constexpr int kPitchUnitPowerOnBaud = 38400;
std::atomic<bool> g_interrupted{false};

int ParseBaud(const std::string& text) {
  try {
    const int baud = std::stoi(text);
    if (hw::IsSupportedBaud(baud)) return baud;
  } catch (const std::exception&) {
  }
  throw CliError("--baud '" + text + "' is not a rate (9600, 19200, 38400, 500000)");
}

const char* StatusName(sensors::ReadingStatus s) {
  switch (s) {
    case sensors::ReadingStatus::kValid:
      return "valid";
    case sensors::ReadingStatus::kNoReturn:
      return "no_return";
    case sensors::ReadingStatus::kOverRange:
      return "over_range";
    case sensors::ReadingStatus::kDazzled:
      return "dazzled";
  }
  return "unknown";
}

// The simulator behind the three emulators. One mutex: physics is stepped by one caller at a time.
class SimulatedDevices {
 public:
  SimulatedDevices(const std::string& world_path, const mission::AppConfig& config, int pitch_baud,
                   int base_baud)
      : rig_(world_path, config.rig) {
    if (Result<Eigen::Isometry3d> placed = rig_.PlaceAtDefaultStart(); !placed) {
      throw std::runtime_error("cannot place the robot: " + placed.error().message);
    }
    hw::Lms200EmulatorConfig lms;
    lms.lms = config.rig.lms200;
    lms_ = std::make_unique<hw::Lms200Emulator>(
        lms, [this](const sensors::Lms200Config& c) { return Line(c); });
    hw::PitchPhysics pitch;
    pitch.command = [this](double target_rad) {
      std::lock_guard<std::mutex> lock(mutex_);
      (void)rig_.pitch_axis().MoveTo(target_rad, std::chrono::milliseconds(10000));
    };
    pitch.state = [this] {
      std::lock_guard<std::mutex> lock(mutex_);
      return std::make_pair(rig_.pitch_axis().ReadEncoder().value_or(0.0), false);
    };
    pitch_ = std::make_unique<hw::PitchUnitEmulator>(config.rig.pitch_unit, pitch_baud, pitch);
    hw::P2osEmulatorConfig p3;
    p3.baud = base_baud;
    p3_ = std::make_unique<hw::P2osEmulator>(p3, BaseOf(config));
    stepper_ = std::thread([this] { StepPhysics(); });
  }
  ~SimulatedDevices() {
    running_ = false;
    if (stepper_.joinable()) stepper_.join();
  }
  nlohmann::json Paths() const {
    return {{"lms200", lms_->path()}, {"pitch_unit", pitch_->path()}, {"base", p3_->path()}};
  }

 private:
  // The simulated base as the P3's microcontroller sees it.
  hw::BasePhysics BaseOf(const mission::AppConfig& config) {
    hw::BasePhysics base;
    base.command = [this](double v, double w) {
      v_mps_ = v;
      omega_rps_ = w;
    };
    base.state = [this] {
      std::lock_guard<std::mutex> lock(mutex_);
      hw::BaseState s;
      if (Result<sensors::Odometry> o = rig_.base().ReadOdometry(); o) {
        const double half_track = 0.5 * rig_.base().effective_track_m();
        const Eigen::Vector2d travel = rig_.sim().WheelAngles() * rig_.sim().params().wheel_radius_m;
        s = {o->x_m,       o->y_m,     o->yaw_rad,   o->v_mps - half_track * o->omega_rps,
             o->v_mps + half_track * o->omega_rps, o->omega_rps, o->stalled, o->stalled,
             12.8,         travel[0],  travel[1]};
      }
      return s;
    };
    // VEL2's wheel speeds through the track the simulated base turns with (a skid-steer P3-AT's
    // effective track, ~0.96 m, not its 0.33 m axle), so the wheels run as commanded.
    base.track_m = rig_.base().effective_track_m();
    // The simulated encoders' tick (OdometryConfig::ticks_per_rev on the wheel).
    base.encoder_tick_m =
        2.0 * kPi * rig_.sim().params().wheel_radius_m / config.rig.odometry.ticks_per_rev;
    base.emergency_stop = [this] {
      std::lock_guard<std::mutex> lock(mutex_);
      v_mps_ = omega_rps_ = 0.0;
      rig_.base().EmergencyStop();
    };
    // Auxiliary power output 11 feeds the laser (ARIA switches it to reset an LMS).
    base.aux_power = [this](int output, bool on) {
      if (output == hw::p2os::kLaserPowerOutput) lms_->SetPowered(on);
    };
    return base;
  }

  // The base keeps moving between requests: step physics in real time with its last command.
  void StepPhysics() {
    constexpr double kStep_s = 0.02;
    while (running_) {
      {
        std::lock_guard<std::mutex> lock(mutex_);
        (void)rig_.base().Drive(v_mps_, omega_rps_, kStep_s);
      }
      std::this_thread::sleep_for(std::chrono::duration<double>(kStep_s));
    }
  }
  sensors::LaserLine Line(const sensors::Lms200Config& wanted) {
    std::lock_guard<std::mutex> lock(mutex_);
    // The driver may pick another variant or range mode than the config's: a scanner per mode.
    const auto key = std::make_tuple(wanted.fov_deg, wanted.resolution_deg, int(wanted.range_mode));
    auto it = scanners_.find(key);
    if (it == scanners_.end()) {
      sensors::Lms200Config c = rig_.config().lms200;
      c.fov_deg = wanted.fov_deg;
      c.resolution_deg = wanted.resolution_deg;
      c.range_mode = wanted.range_mode;
      it = scanners_
               .emplace(key, std::make_unique<sim::SimLineScanner>(rig_.sim(), rig_.caster(), c))
               .first;
    }
    Result<sensors::LaserLine> line = it->second->NextLine(std::chrono::milliseconds(10000));
    return line ? *line : sensors::LaserLine{};  // a wrong-sized line goes out as "no return"
  }

  sim::SimRig rig_;
  std::mutex mutex_;
  std::atomic<double> v_mps_{0.0}, omega_rps_{0.0};
  std::atomic<bool> running_{true};
  std::map<std::tuple<double, double, int>, std::unique_ptr<sim::SimLineScanner>> scanners_;
  std::unique_ptr<hw::Lms200Emulator> lms_;
  std::unique_ptr<hw::PitchUnitEmulator> pitch_;
  std::unique_ptr<hw::P2osEmulator> p3_;
  std::thread stepper_;
};

int RunEmulate(int argc, char** argv) {
  CliArgs args("hw emulate",
               "Starts an emulated LMS200, pitch unit and P3 base on pseudo-terminals, driven by\n"
               "the simulator in a world; prints their device paths and runs until interrupted.");
  args.Option("world", "NAME|FILE.xml", "built-in world (" + BuiltinWorldNames() + ") or MJCF",
              "terrain")
      .Option("config", "FILE.yaml", "rig configuration (see README)")
      .Option("baud", "B",
              "pitch unit and base rate (default: their power-on rates, pitch unit 38400, base "
              "9600; the LMS200 starts at 9600)")
      .Flag("json", "print the device paths as JSON");
  if (!args.Parse(argc, argv)) return 0;
  const bool baud_given = args.Has("baud");
  const int pitch_baud = baud_given ? ParseBaud(args.Get("baud")) : kPitchUnitPowerOnBaud;
  const int base_baud = baud_given ? ParseBaud(args.Get("baud")) : kBasePowerOnBaud;
  mission::AppConfig config =
      mission::LoadAppConfig(args.Has("config") ? std::optional(args.Get("config")) : std::nullopt);
  const auto world_path = worlds::ResolveWorld(args.Get("world"), WorldsDir());
  // Before the devices exist: a signal while they are made (the world loads for a second or two)
  // then ends the wait below at once, and their destructors remove the pseudo-terminals' links
  // and folders; the default action would kill the process and leave them (/tmp/pitchlab-hw-*).
  std::signal(SIGINT, [](int) { g_interrupted = true; });
  std::signal(SIGTERM, [](int) { g_interrupted = true; });
  SimulatedDevices devices(world_path.string(), config, pitch_baud, base_baud);
  const nlohmann::json paths = devices.Paths();
  // What the paths are, on stderr, before the paths: stdout stays the three paths (or the JSON)
  // for scripts, and a script that has read them has the explanation in its log too.
  std::fprintf(stderr,
               "hw emulate: %s simulated behind three pseudo-terminals, opened like serial "
               "ports:\n"
               "  lms200      SICK LMS200 telegrams, 9600 baud after power-on (switches on "
               "request)\n"
               "  pitch_unit  the pitching servo's board, %d baud\n"
               "  base        Pioneer P3 (P2OS/ARCOS packets), %d baud\n"
               "Name them in a config's hw section and run `pitchlab run --backend hw --config "
               "FILE --world %s` (hw/README.md). Ctrl-C or SIGTERM stops the emulators.\n",
               world_path.stem().c_str(), pitch_baud, base_baud, world_path.stem().c_str());
  if (args.Flagged("json")) {
    std::cout << paths.dump(2) << std::endl;
  } else {
    std::cout << "lms200     " << paths["lms200"].get<std::string>() << "\n"
              << "pitch_unit " << paths["pitch_unit"].get<std::string>() << "\n"
              << "base       " << paths["base"].get<std::string>() << std::endl;
  }
  while (!g_interrupted) std::this_thread::sleep_for(std::chrono::milliseconds(100));
  return 0;
}

int RunLms200(int argc, char** argv) {
  CliArgs args("hw lms200", "Connects to an LMS200 and prints one scan.");
  args.Option("device", "PATH", "serial device (e.g. /dev/ttyUSB0 or an emulator's path)")
      .Option("baud", "B", "rate to switch to: 9600, 19200, 38400, 500000", "38400")
      .Option("fov", "DEG", "field of view: 100 or 180", "180")
      .Option("resolution", "DEG", "1, 0.5 or 0.25", "0.5")
      .Option("units", "cm|mm", "range mode", "cm")
      .Flag("once", "one scan, then exit (the only mode so far)")
      .Flag("json", "print the scan as JSON");
  if (!args.Parse(argc, argv)) return 0;
  if (!args.Flagged("once")) {
    throw CliError("lms200 needs --once (one scan, then exit: the only mode so far)");
  }
  hw::Lms200DriverConfig config;
  config.device = args.Get("device");
  config.lms.baud = ParseBaud(args.Get("baud"));
  config.lms.fov_deg = args.GetNumbers("fov", 1)[0];
  config.lms.resolution_deg = args.GetNumbers("resolution", 1)[0];
  try {  // a variant the LMS200 does not have is a command-line mistake: exit 2
    config.lms.Validate();
  } catch (const std::invalid_argument& e) {
    throw CliError(std::string("--fov / --resolution: ") + e.what());
  }
  const std::string units = args.Get("units");
  if (units != "cm" && units != "mm") throw CliError("--units '" + units + "' is not cm or mm");
  config.lms.range_mode =
      units == "mm" ? sensors::Lms200RangeMode::kMm : sensors::Lms200RangeMode::kCm;
  // Ctrl-C: the driver returns within one read timeout and its destructor stops a streaming
  // device; then a clear message and 128 + signal.
  hw::InstallStopSignalHandlers();
  const auto interrupted = [&] {
    std::fprintf(stderr, "hw lms200: %s; %s left in on-request mode\n", hw::StopReason().c_str(),
                 config.device.c_str());
    return hw::StopExitCode();
  };
  std::unique_ptr<hw::Lms200Driver> driver;
  try {
    driver = std::make_unique<hw::Lms200Driver>(config);
  } catch (const std::runtime_error&) {
    if (hw::StopRequested()) return interrupted();
    throw;
  }
  Result<sensors::LaserLine> line = driver->NextLine(std::chrono::milliseconds(3000));
  if (!line && hw::StopRequested()) {
    driver.reset();
    return interrupted();
  }
  if (!line) throw std::runtime_error(line.error().message);
  nlohmann::json ranges = nlohmann::json::array(), status = nlohmann::json::array();
  std::size_t valid = 0;
  for (std::size_t i = 0; i < line->ranges_m.size(); ++i) {
    const bool ok = line->status[i] == sensors::ReadingStatus::kValid;
    valid += ok;
    ranges.push_back(ok ? nlohmann::json(line->ranges_m[i]) : nlohmann::json(nullptr));
    status.push_back(StatusName(line->status[i]));
  }
  const hw::Lms200DriverStats& stats = driver->stats();
  nlohmann::json out = {{"device", config.device},
                        {"type", driver->type()},
                        {"baud", config.lms.baud},
                        {"units", units},
                        {"stamp_s", line->stamp_s},
                        {"angle_min_deg", line->angle_min_rad * kRadToDeg},
                        {"angle_increment_deg", line->angle_increment_rad * kRadToDeg},
                        {"readings", line->ranges_m.size()},
                        {"valid", valid},
                        {"ranges_m", ranges},
                        {"status", status},
                        {"link",
                         {{"retries", stats.retries},
                          {"crc_errors", stats.reader.crc_errors},
                          {"garbage_bytes", stats.reader.garbage_bytes},
                          {"naks", stats.reader.naks},
                          {"reconnects", stats.reconnects}}}};
  if (args.Flagged("json")) {
    std::cout << out.dump(2) << "\n";
  } else {
    std::cout << config.device << " (" << driver->type() << "): " << line->ranges_m.size()
              << " readings, " << valid << " valid\n";
  }
  return 0;
}

}  // namespace

int RunHw(int argc, char** argv) {
  const std::string usage =
      "usage: pitchlab hw <emulate|lms200> [options]   (pitchlab hw <sub> --help)\n"
      "  emulate  emulated LMS200, pitch unit and P3 on ptys, driven by the simulator\n"
      "  lms200   one scan from an LMS200 as JSON\n";
  if (argc < 1 || std::string(argv[0]) == "--help" || std::string(argv[0]) == "-h") {
    (argc < 1 ? std::cerr : std::cout) << usage;
    return argc < 1 ? 2 : 0;
  }
  const std::string sub = argv[0];
  if (sub == "emulate") return RunEmulate(argc - 1, argv + 1);
  if (sub == "lms200") return RunLms200(argc - 1, argv + 1);
  throw CliError("unknown hw command '" + sub + "'\n" + usage);
}

}  // namespace pitchlab::apps
