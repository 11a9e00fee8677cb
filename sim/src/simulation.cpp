#include "pitchlab/sim/simulation.hpp"

#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <memory>
#include <sstream>
#include <stdexcept>

#include <mujoco/mujoco.h>

#include "mujoco_handlers.hpp"
#include "robot_layout.hpp"
#include "simulation_impl.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::sim {
namespace {

constexpr double kImpRatio = 10.0;
constexpr int kNoslipIterations = 10;  // MuJoCo's noslip pass, iterations per step
// HoldStill: a free body (the base, a loose box) is at rest below these, as SimBase::Stop's still
// base.
constexpr double kStillSpeed_mps = 0.005;
constexpr double kStillRate_rps = 0.01;
// The held joints' armature: against the laser's few kg at a decimetre's lever, a base that weighs
// 1e9 (kg, kg m^2) is immovable to within 1e-9 of its coupling to the pitch joint.
constexpr double kHeldArmature = 1e9;
constexpr double kMujocoDefaultTimestep = 0.002;  // <option timestep> when a world sets none
// The laser locks on the base once its servo holds a fixed setpoint to within this, at rest (well
// inside the pitch encoder's half count, 0.005 deg = 8.7e-5 rad).
constexpr double kPitchLockTolerance_rad = 2e-5;

// MuJoCo 2.2's scratch stack (mjData::stack), in mjtNums, for a model whose constraint rows fill
// njmax at most. Its compiler's default, 5 (njmax + nv)^2, bounds dense nefc x nefc work that the
// Newton solver and the noslip pass do not put on the stack (the AR matrix they read is a field of
// mjData). Measured maxuse_stack grows with rows times dofs: 2.0 nefc nv on terrain (126 rows, nv
// 11), 2.4 in the cluttered office (48 rows, nv 29), 4.0 for 96 loose boxes filling the P3-AT's
// 400 contacts (1188 rows, nv 587, MuJoCo's sparse path; simulation_test). The bound is twice the
// largest of those at a full njmax. The default (13 M numbers, 104 MB at njmax 1600) was cleared
// at every mjData made: 3.4 % of an urban run's CPU for its two. Too small is no silent error:
// mj_stackAlloc fails through mju_error, which throws (ThrowOnError), naming the stack.
int SolverStack(const mjModel& m) {
  const long rows = m.njmax + m.nv;
  return static_cast<int>(std::min<long>(8 * rows * (m.nv + 10), std::numeric_limits<int>::max()));
}

std::string ReadFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error("world " + path + ": cannot open the file");
  std::ostringstream os;
  os << in.rdbuf();
  return os.str();
}

std::string DirOf(const std::string& path) {
  const std::size_t slash = path.rfind('/');
  std::string dir = slash == std::string::npos ? "." : path.substr(0, slash);
  if (dir.empty()) dir = "/";
  if (dir.front() != '/') {
    char cwd[4096];
    if (getcwd(cwd, sizeof cwd) != nullptr) dir = std::string(cwd) + "/" + dir;
  }
  return dir;
}

// Compiles the composed text from memory, through MuJoCo's virtual file system: no temp file that
// a kill mid-load would leave behind (a test's interrupted runs left the yard's composed text in
// /tmp), and no need of a writable TMPDIR. The asset paths in the text are absolute
// (ComposeWorldXml), and MuJoCo reads files the VFS does not hold from disk.
mjModel* LoadComposed(const std::string& xml, const std::string& source) {
  static constexpr char kName[] = "pitchlab_composed_world.xml";
  // ~2 MB of name slots, not on the stack; its file freed also when mj_loadXML throws (our
  // mju_user_error handler throws).
  const auto free_vfs = [](mjVFS* v) {
    mj_deleteVFS(v);
    delete v;
  };
  const std::unique_ptr<mjVFS, decltype(free_vfs)> vfs(new mjVFS, free_vfs);
  mj_defaultVFS(vfs.get());
  if (xml.size() > static_cast<std::size_t>(std::numeric_limits<int>::max()) ||
      mj_makeEmptyFileVFS(vfs.get(), kName, static_cast<int>(xml.size())) != 0) {
    throw std::runtime_error("world " + source + ": its composed text (" +
                             std::to_string(xml.size()) + " bytes) does not fit MuJoCo's VFS");
  }
  std::memcpy(vfs->filedata[mj_findFileVFS(vfs.get(), kName)], xml.data(), xml.size());
  char error[1024] = "";
  mjModel* model = mj_loadXML(kName, vfs.get(), error, sizeof error);
  if (model == nullptr) {
    // The user's file, not our composition, is what the message names: MuJoCo's own error
    // (element, attribute, line of the composed text) says what it could not take.
    throw std::runtime_error("world " + source + ": MuJoCo cannot load it with the robot added: " +
                             error);
  }
  return model;
}

int IdOrThrow(const mjModel* m, mjtObj type, const char* name) {
  const int id = mj_name2id(m, type, name);
  if (id < 0) throw std::runtime_error(std::string("robot model has no element named ") + name);
  return id;
}

// Reads numeric pitchlab:<field> of exactly `n` values; throws naming the field when malformed.
template <int N>
std::optional<Eigen::Matrix<double, N, 1>> Numeric(const mjModel* m, const std::string& field,
                                                   const std::string& source) {
  const int id = mj_name2id(m, mjOBJ_NUMERIC, field.c_str());
  if (id < 0) return std::nullopt;
  if (m->numeric_size[id] != N) {
    throw std::runtime_error("world " + source + ": custom numeric " + field + " has " +
                             std::to_string(m->numeric_size[id]) + " values, expected " +
                             std::to_string(N));
  }
  Eigen::Matrix<double, N, 1> v;
  for (int i = 0; i < N; ++i) v[i] = m->numeric_data[m->numeric_adr[id] + i];
  return v;
}

WorldInfo ReadWorldInfo(const mjModel* m, const std::string& source) {
  WorldInfo info;
  info.path = source;
  const int text = mj_name2id(m, mjOBJ_TEXT, "pitchlab:description");
  if (text >= 0) info.description = std::string(m->text_data + m->text_adr[text]);
  info.geodetic_origin = Numeric<3>(m, "pitchlab:geodetic_origin", source);
  info.bounds = Numeric<4>(m, "pitchlab:bounds", source);
  if (info.bounds &&
      !((*info.bounds)[0] < (*info.bounds)[2] && (*info.bounds)[1] < (*info.bounds)[3])) {
    throw std::runtime_error("world " + source + ": pitchlab:bounds must be xmin ymin xmax ymax");
  }
  info.default_start = Numeric<3>(m, "pitchlab:default_start", source);
  if (info.default_start) (*info.default_start)[2] *= M_PI / 180.0;  // yaw_deg -> rad
  return info;
}

// Whether joint `j` is at rest for HoldStill; its position and dof counts. Only free bodies must
// be at rest: a joint within one (a wheel) is held wherever it is, since a wheel that still turns
// (0.06-0.1 rad/s seen) inside a base that stands still is its tyre's contact settling, not motion.
bool AtRest(const mjModel* m, const mjData* d, int j, int& nq, int& nv) {
  const mjtNum* v = d->qvel + m->jnt_dofadr[j];
  const auto norm3 = [](const mjtNum* x) {
    return std::sqrt(x[0] * x[0] + x[1] * x[1] + x[2] * x[2]);
  };
  switch (m->jnt_type[j]) {
    case mjJNT_FREE:
      nq = 7, nv = 6;
      return norm3(v) < kStillSpeed_mps && norm3(v + 3) < kStillRate_rps;
    case mjJNT_BALL:
      nq = 4, nv = 3;
      return true;
    default:  // hinge, slide
      nq = 1, nv = 1;
      return true;
  }
}

}  // namespace

void Simulation::Impl::HeldJoints::Add(const mjModel* m, const mjData* d, int joint, int nq,
                                       int nv) {
  joints.emplace_back(m->jnt_qposadr[joint], nq);
  for (int i = 0; i < nq; ++i) qpos.push_back(d->qpos[m->jnt_qposadr[joint] + i]);
  for (int i = 0; i < nv; ++i) dofs.push_back(m->jnt_dofadr[joint] + i);
}

void Simulation::Impl::HeldJoints::Freeze(mjModel* m) {
  for (const int dof : dofs) {
    armature.push_back(m->dof_armature[dof]);
    m->dof_armature[dof] = kHeldArmature;
  }
}

void Simulation::Impl::HeldJoints::Keep(mjData* d) const {
  std::size_t k = 0;
  for (const auto& [adr, count] : joints) {
    for (int i = 0; i < count; ++i) d->qpos[adr + i] = qpos[k++];
  }
  for (const int dof : dofs) d->qvel[dof] = 0.0;
}

void Simulation::Impl::HeldJoints::Restore(mjModel* m) const {
  for (std::size_t i = 0; i < dofs.size(); ++i) m->dof_armature[dofs[i]] = armature[i];
}

void Simulation::Impl::LockPitch() {
  HeldJoints lock;
  lock.Add(m, d, m->dof_jntid[pitch_dof], 1, 1);
  lock.Freeze(m);
  lock.Keep(d);
  pitch_lock = std::move(lock);
  m->opt.timestep = locked_timestep_s;
}

void Simulation::Impl::UnlockPitch() {
  if (!pitch_lock) return;
  pitch_lock->Restore(m);
  pitch_lock.reset();
  m->opt.timestep = world_timestep_s;
}

Simulation::Simulation(const std::string& world_path, const RobotConfig& robot)
    : Simulation(ReadFile(world_path), DirOf(world_path), world_path, robot) {}

std::unique_ptr<Simulation> Simulation::FromString(const std::string& world_xml,
                                                   const std::string& base_dir,
                                                   const RobotConfig& robot) {
  return std::unique_ptr<Simulation>(new Simulation(world_xml, base_dir, "<string>", robot));
}

Simulation::Simulation(const std::string& world_xml, const std::string& base_dir,
                       const std::string& source, const RobotConfig& robot)
    : robot_(robot), impl_(std::make_unique<Impl>()) {
  InstallMujocoHandlers();
  composed_xml_ = ComposeWorldXml(world_xml, base_dir, robot_, source);
  Impl& s = *impl_;
  s.m = LoadComposed(composed_xml_, source);
  // With pyramidal friction cones MuJoCo's soft contacts let a parked robot creep down a slope
  // (0.7 mm/s on 10 deg: a centimetre over one scan); elliptic cones with a high impedance ratio
  // hold it to ~0.1 mm/s. Soft contacts still slip where tyres would grip: parked on a 20 deg
  // heightfield the robot crept 1.1-1.6 mm over a scan's 16 s, and on rough relief (terrain seed
  // 8) a P3-AT with locked wheels slid 1 cm/s and never came to rest for its scan. The noslip
  // solver's post-pass removes slip within the friction cones: 0.2-0.3 mm there, and the robot
  // comes to rest. Worlds that choose their own contact model keep it.
  if (s.m->opt.cone == mjCONE_PYRAMIDAL && s.m->opt.impratio == 1.0 &&
      s.m->opt.noslip_iterations == 0) {
    s.m->opt.cone = mjCONE_ELLIPTIC;
    s.m->opt.impratio = kImpRatio;
    s.m->opt.noslip_iterations = kNoslipIterations;
  }
  if (composed_xml_.find("nstack") == std::string::npos) s.m->nstack = SolverStack(*s.m);
  s.d = mj_makeData(s.m);
  if (s.d == nullptr) throw std::runtime_error("world " + source + ": mj_makeData failed");
  world_ = ReadWorldInfo(s.m, source);

  s.robot_body = IdOrThrow(s.m, mjOBJ_BODY, kRobotBody);
  const int root = IdOrThrow(s.m, mjOBJ_JOINT, "robot_root");
  s.root_qpos = s.m->jnt_qposadr[root];
  s.root_dof = s.m->jnt_dofadr[root];
  s.base_site = IdOrThrow(s.m, mjOBJ_SITE, kBaseLinkSite);
  s.laser_site = IdOrThrow(s.m, mjOBJ_SITE, kLaserSite);
  const int pitch = IdOrThrow(s.m, mjOBJ_JOINT, kPitchJoint);
  s.pitch_qpos = s.m->jnt_qposadr[pitch];
  s.pitch_dof = s.m->jnt_dofadr[pitch];
  s.pitch_act = IdOrThrow(s.m, mjOBJ_ACTUATOR, kPitchActuator);
  for (const WheelSpec& w : Wheels(params())) {
    const int j = IdOrThrow(s.m, mjOBJ_JOINT, w.joint.c_str());
    const int a = IdOrThrow(s.m, mjOBJ_ACTUATOR, (w.joint + "_motor").c_str());
    s.wheels.push_back({s.m->jnt_qposadr[j], s.m->jnt_dofadr[j], a, w.left});
  }
  // The PD servo's velocity gain is explicit in MuJoCo's Euler step: refuse an unstable world.
  const double inertia =
      s.m->dof_armature[s.pitch_dof] + s.m->body_inertia[3 * s.m->jnt_bodyid[pitch] + 1];
  const double courant = robot_.pitch_servo.kv_nms_per_rad * timestep_s() / inertia;
  if (courant > 1.5) {
    throw std::runtime_error("world " + source + ": <option timestep=\"" +
                             NumberText(timestep_s()) +
                             "\"> is too long for robot.pitch_servo.kv = " +
                             NumberText(robot_.pitch_servo.kv_nms_per_rad) +
                             " (kv * timestep / inertia = " + NumberText(courant) + " > 1.5)");
  }
  // MuJoCo's default step, 2 ms, is the world's unless it chose its own; while the laser is
  // locked the robot's own drive step applies (P3Params::locked_timestep_s says why).
  s.world_timestep_s = s.m->opt.timestep;
  s.locked_timestep_s =
      s.m->opt.timestep == kMujocoDefaultTimestep ? params().locked_timestep_s : s.m->opt.timestep;
  mj_forward(s.m, s.d);
}

Simulation::~Simulation() = default;

const mjModel_* Simulation::model() const { return impl_->m; }
const mjData_* Simulation::data() const { return impl_->d; }
double Simulation::time_s() const { return impl_->d->time; }
double Simulation::timestep_s() const { return impl_->m->opt.timestep; }

// The pitch servo is stiff (kp 4000 N m/rad on the laser's 0.08 kg m^2: a 37 Hz loop, explicit
// in MuJoCo's Euler step) and needs the world's 2 ms step; the robot on its tyres does not. So
// while the servo holds a fixed setpoint, the robot not held and the laser at rest on it, the
// pitch joint is locked (immovable, as the held joints of HoldStill) and the physics steps at
// P3Params::locked_timestep_s; a new setpoint or HoldStill unlocks it.
void Simulation::Step(int n) {
  Impl& s = *impl_;
  for (int i = 0; i < n; ++i) {
    if (!s.pitch_lock && !s.hold && s.locked_timestep_s > s.world_timestep_s &&
        pitch_setpoint_rate_rps_ == 0.0 &&
        std::abs(s.d->qvel[s.pitch_dof]) < kStillRate_rps &&
        std::abs(s.d->qpos[s.pitch_qpos] - pitch_setpoint_rad_) < kPitchLockTolerance_rad) {
      s.LockPitch();
    }
    mj_step1(s.m, s.d);
    for (auto& [id, hook] : s.hooks) {
      if (hook.first) hook.first();
    }
    // PD servo with bias (gravity) and rate feed-forward: torque = kp (q_sp - q) + kv (rate_sp -
    // qdot) + bias, so q tracks a slewing setpoint and sits exactly on a fixed one.
    const PitchServoConfig& servo = robot_.pitch_servo;
    s.d->ctrl[s.pitch_act] =
        pitch_setpoint_rad_ + (s.d->qfrc_bias[s.pitch_dof] - s.d->qfrc_passive[s.pitch_dof] +
                               servo.kv_nms_per_rad * pitch_setpoint_rate_rps_) /
                                  servo.kp_nm_per_rad;
    mj_step2(s.m, s.d);
    if (s.hold) s.hold->held.Keep(s.d);
    if (s.pitch_lock) s.pitch_lock->Keep(s.d);
    for (auto& [id, hook] : s.hooks) {
      if (hook.second) hook.second();
    }
  }
  mj_kinematics(s.m, s.d);  // fresh xpos/site/geom poses for ground truth and the ray casters
}

bool Simulation::HoldStill() {
  Impl& s = *impl_;
  if (s.hold) return true;
  s.UnlockPitch();  // held, the pitch joint is what moves
  Impl::Hold h;
  const int pitch_joint = s.m->dof_jntid[s.pitch_dof];
  for (int j = 0; j < s.m->njnt; ++j) {
    if (j == pitch_joint) continue;
    int nq = 0, nv = 0;
    if (!AtRest(s.m, s.d, j, nq, nv)) return false;
    h.held.Add(s.m, s.d, j, nq, nv);
  }
  h.held.Freeze(s.m);
  h.qacc_warmstart.assign(s.d->qacc_warmstart, s.d->qacc_warmstart + s.m->nv);
  h.disableflags = s.m->opt.disableflags;
  s.m->opt.disableflags |= mjDSBL_CONTACT;
  s.hold = std::move(h);
  s.hold->held.Keep(s.d);
  return true;
}

void Simulation::Release() {
  Impl& s = *impl_;
  if (!s.hold) return;
  const Impl::Hold& h = *s.hold;
  h.held.Restore(s.m);
  std::copy(h.qacc_warmstart.begin(), h.qacc_warmstart.end(), s.d->qacc_warmstart);
  s.m->opt.disableflags = h.disableflags;
  h.held.Keep(s.d);
  s.hold.reset();
}

bool Simulation::held() const { return impl_->hold.has_value(); }

void Simulation::StepFor(double duration_s) {
  if (!(duration_s > 0.0)) return;
  // The step may change on the way (the laser locking): steps until the nearest step to the end.
  const double end_s = time_s() + duration_s;
  do {
    Step(1);
  } while (time_s() + 0.5 * timestep_s() < end_s);
}

Eigen::Isometry3d Simulation::T_world_base() const {
  const mjData* d = impl_->d;
  const int site = impl_->base_site;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(d->site_xpos + 3 * site);
  T.linear() =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->site_xmat + 9 * site);
  return T;
}

Eigen::Isometry3d Simulation::T_world_laser() const {
  const mjData* d = impl_->d;
  const int site = impl_->laser_site;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Map<const Eigen::Vector3d>(d->site_xpos + 3 * site);
  T.linear() =
      Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d->site_xmat + 9 * site);
  return T;
}

double Simulation::pitch_rad() const { return impl_->d->qpos[impl_->pitch_qpos]; }
double Simulation::pitch_rate_rps() const { return impl_->d->qvel[impl_->pitch_dof]; }
void Simulation::SetPitchSetpoint(double pitch_rad, double rate_rps) {
  if (pitch_rad != pitch_setpoint_rad_ || rate_rps != 0.0) impl_->UnlockPitch();
  pitch_setpoint_rad_ = pitch_rad;
  pitch_setpoint_rate_rps_ = rate_rps;
}

void Simulation::SetWheelSpeeds(double left_rps, double right_rps) {
  for (const Impl::Wheel& w : impl_->wheels) impl_->d->ctrl[w.act] = w.left ? left_rps : right_rps;
}

Eigen::Vector2d Simulation::WheelAngles() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero(), count = Eigen::Vector2d::Zero();
  for (const Impl::Wheel& w : impl_->wheels) {
    sum[w.left ? 0 : 1] += impl_->d->qpos[w.qpos];
    count[w.left ? 0 : 1] += 1;
  }
  return sum.cwiseQuotient(count);
}

Eigen::Vector2d Simulation::WheelSpeeds() const {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero(), count = Eigen::Vector2d::Zero();
  for (const Impl::Wheel& w : impl_->wheels) {
    sum[w.left ? 0 : 1] += impl_->d->qvel[w.dof];
    count[w.left ? 0 : 1] += 1;
  }
  return sum.cwiseQuotient(count);
}

bool Simulation::WheelStalled() const {
  const mjModel* m = impl_->m;
  const mjData* d = impl_->d;
  for (const Impl::Wheel& w : impl_->wheels) {
    const double limit = m->actuator_forcerange[2 * w.act + 1];
    const double cmd = d->ctrl[w.act];
    if (std::abs(d->actuator_force[w.act]) >= 0.99 * limit && std::abs(cmd) > 0.1 &&
        std::abs(d->qvel[w.dof]) < 0.5 * std::abs(cmd)) {
      return true;
    }
  }
  return false;
}

Eigen::Vector2d Simulation::BaseSpeeds() const {
  const mjtNum* v = impl_->d->qvel + impl_->root_dof;
  return {Eigen::Vector3d(v[0], v[1], v[2]).norm(), Eigen::Vector3d(v[3], v[4], v[5]).norm()};
}

int Simulation::AddStepHooks(StepHook before, StepHook after) {
  const int id = impl_->next_hook++;
  impl_->hooks[id] = {std::move(before), std::move(after)};
  return id;
}

void Simulation::RemoveHooks(int id) { impl_->hooks.erase(id); }

std::vector<std::string> Simulation::TakeWarnings() {
  std::vector<std::string> out = TakeMujocoWarnings();
  mjData* d = impl_->d;
  for (int i = 0; i < mjNWARNING; ++i) {
    if (d->warning[i].number > 0) {
      out.push_back("MuJoCo warning " + std::to_string(i) + " raised " +
                    std::to_string(d->warning[i].number) + " times (info " +
                    std::to_string(d->warning[i].lastinfo) + ")");
      d->warning[i].number = 0;
    }
  }
  return out;
}

}  // namespace pitchlab::sim
