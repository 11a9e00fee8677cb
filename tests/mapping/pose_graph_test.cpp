// The pose graph against known answers: a square loop with drifted odometry closed by a true loop
// while a false one is refused, the edge weight being the registration's information as it is,
// the robust kernel's bounded pull, relative covariances of a chain, loop candidates.

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "pitchlab/mapping/pose_graph.hpp"
#include "pitchlab/mapping/registration.hpp"
#include "pitchlab/mapping/trajectory_metrics.hpp"

namespace pitchlab::mapping {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
constexpr double kPi = 3.14159265358979323846;
constexpr double kDeg = kPi / 180;

// The registration's perturbation: Exp(omega, v) = [R(omega), v], applied on the left.
Eigen::Isometry3d Exp(const Vector6d& e) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  const double angle = e.head<3>().norm();
  if (angle > 0) T.linear() = Eigen::AngleAxisd(angle, e.head<3>() / angle).toRotationMatrix();
  T.translation() = e.tail<3>();
  return T;
}

Vector6d Sigmas(double rotation_deg, double translation_m) {
  Vector6d s;
  s << Eigen::Vector3d::Constant(rotation_deg * kDeg), Eigen::Vector3d::Constant(translation_m);
  return s;
}

Matrix6d InformationOf(const Vector6d& sigmas) {
  return sigmas.cwiseProduct(sigmas).cwiseInverse().asDiagonal();
}

// A draw of the error e ~ N(0, diag(sigmas^2)).
Vector6d Draw(const Vector6d& sigmas, std::mt19937& rng) {
  std::normal_distribution<double> n(0, 1);
  Vector6d e;
  for (int i = 0; i < 6; ++i) e(i) = sigmas(i) * n(rng);
  return e;
}

PoseGraphEdge EdgeFrom(const std::vector<Eigen::Isometry3d>& truth, int from, int to,
                       const Vector6d& error, const Vector6d& sigmas, EdgeKind kind) {
  return {from, to, Exp(error) * truth[from].inverse() * truth[to], InformationOf(sigmas), kind};
}

// --- The square loop (issue 20's "done when") ---------------------------------------------------

constexpr int kSquareNodes = 32;  // an 8 m square, a stop every metre
// Sequential registrations good to 0.5 mm / 0.005 deg per axis (at 1 mm / 0.01 deg their random
// walk alone leaves the best estimate 1.0 cm off at the far corner); two that drifted within their
// (weak) bounds: a corridor-like stop slipped 0.5 m along its free axis (bound 0.3 m, as an
// odometry guess carried there) and an open-plane stop turned 3 deg about its free yaw (2 deg).
const Vector6d kPrecise = Sigmas(0.005, 0.0005);
constexpr int kSlipEdge = 5, kTurnEdge = 20;

std::vector<Eigen::Isometry3d> SquareTruth() {
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k < kSquareNodes; ++k) {
    const int side = k / 8, along = k % 8;
    const Eigen::Vector2d corners[4] = {{0, 0}, {8, 0}, {8, 8}, {0, 8}};
    const Eigen::Vector2d directions[4] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}};
    const Eigen::Vector2d xy = corners[side] + along * directions[side];
    // The floor undulates by 5 cm, and the robot pitches with it: a 3-D loop, not a planar one.
    const double z = 0.05 * std::sin(0.7 * k);
    truth.push_back(PoseFromXyzRpyDeg(xy.x(), xy.y(), z, 0.5 * std::cos(k), 1.0 * std::sin(0.7 * k),
                                      90.0 * side));
  }
  return truth;
}

std::vector<PoseGraphEdge> SquareOdometry(const std::vector<Eigen::Isometry3d>& truth) {
  std::mt19937 rng(20);
  std::vector<PoseGraphEdge> edges;
  for (int k = 0; k + 1 < kSquareNodes; ++k) {
    Vector6d sigmas = kPrecise;
    Vector6d error = Draw(kPrecise, rng);
    if (k == kSlipEdge) sigmas(3) = 0.3, error(3) = 0.5;            // forward, the corridor's axis
    if (k == kTurnEdge) sigmas(2) = 2 * kDeg, error(2) = 3 * kDeg;  // yaw
    edges.push_back(EdgeFrom(truth, k, k + 1, error, sigmas, EdgeKind::kSequential));
  }
  return edges;
}

// Nodes chained from the known start through the sequential edges: dead reckoning.
PoseGraph ChainedGraph(const Eigen::Isometry3d& start, const std::vector<PoseGraphEdge>& odometry) {
  PoseGraph graph;
  Eigen::Isometry3d T = start;
  EXPECT_TRUE(graph.AddNode(T));
  for (const PoseGraphEdge& edge : odometry) {
    T = T * edge.T_from_to;
    EXPECT_TRUE(graph.AddNode(T));
    EXPECT_TRUE(graph.AddEdge(edge));
  }
  return graph;
}

struct WorstError {
  double translation_m = 0, rotation_deg = 0;
};
WorstError Worst(const std::vector<Eigen::Isometry3d>& estimate,
                 const std::vector<Eigen::Isometry3d>& truth) {
  WorstError w;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const PoseError e = ComparePoses(estimate[i], truth[i]);
    w.translation_m = std::max(w.translation_m, e.translation_m);
    w.rotation_deg = std::max(w.rotation_deg, e.rotation_deg);
  }
  return w;
}

// Node 31 (1 m south of the start, heading south) registered against node 0: the true loop.
PoseGraphEdge TrueLoop(const std::vector<Eigen::Isometry3d>& truth) {
  std::mt19937 rng(31);
  return EdgeFrom(truth, 0, 31, Draw(kPrecise, rng), kPrecise, EdgeKind::kLoop);
}

// Node 27 (on the west side, 5 m north of the start) registered against node 2 one desk row,
// 2 m, off along the row, a precise-looking fit: the false loop (office pair 35 of
// registration_eval aligned 2.05 m along a desk row).
PoseGraphEdge FalseLoop(const std::vector<Eigen::Isometry3d>& truth) {
  Vector6d error = Vector6d::Zero();
  error(4) = 2.0;  // along node 2's y: north, the row's direction
  return EdgeFrom(truth, 2, 27, error, kPrecise, EdgeKind::kLoop);
}

TEST(PoseGraph, SquareLoopRecoversTheTruePosesAndRefusesTheFalseLoop) {
  const std::vector<Eigen::Isometry3d> truth = SquareTruth();
  PoseGraph graph = ChainedGraph(truth[0], SquareOdometry(truth));
  ASSERT_TRUE(graph.Optimize());
  const WorstError drifted = Worst(graph.Poses(), truth);
  EXPECT_GT(drifted.translation_m, 0.5);  // the slip and the turn: dead reckoning is far off
  EXPECT_GT(drifted.rotation_deg, 2.5);

  const auto true_loop = graph.TryAddLoopEdge(TrueLoop(truth));
  ASSERT_TRUE(true_loop) << true_loop.error().message;
  EXPECT_TRUE(true_loop->accepted) << "chi2 rose by " << true_loop->chi2_increase;
  const auto false_loop = graph.TryAddLoopEdge(FalseLoop(truth));
  ASSERT_TRUE(false_loop) << false_loop.error().message;
  EXPECT_FALSE(false_loop->accepted) << "chi2 rose by " << false_loop->chi2_increase;
  EXPECT_GT(false_loop->chi2_increase, false_loop->gate_chi2);
  EXPECT_EQ(graph.EdgeCount(), kSquareNodes);  // 31 sequential + the true loop

  const WorstError closed = Worst(graph.Poses(), truth);
  EXPECT_LT(closed.translation_m, 0.01);  // issue 20: within 1 cm
  EXPECT_LT(closed.rotation_deg, 0.1);    // and 0.1 deg
  const auto ate = AbsoluteTrajectoryErrorUnaligned(graph.Poses(), truth);
  ASSERT_TRUE(ate);
  EXPECT_LT(ate->rmse_m, 0.01);
}

TEST(PoseGraph, FalseLoopsBeyondTheDriftAreRefusedBeforeAnyTrueLoop) {
  // Against the drifted chain alone (0.9 m, 3 deg off): the desk row 2 m along, and a symmetric
  // room registered a quarter turn off (registration_eval's office pairs 10, 11).
  const std::vector<Eigen::Isometry3d> truth = SquareTruth();
  PoseGraph graph = ChainedGraph(truth[0], SquareOdometry(truth));
  ASSERT_TRUE(graph.Optimize());
  const std::vector<Eigen::Isometry3d> before = graph.Poses();
  Vector6d quarter_turn = Vector6d::Zero();
  quarter_turn(2) = 90 * kDeg;
  for (const PoseGraphEdge& wrong :
       {FalseLoop(truth), EdgeFrom(truth, 0, 31, quarter_turn, kPrecise, EdgeKind::kLoop)}) {
    const auto decision = graph.TryAddLoopEdge(wrong);
    ASSERT_TRUE(decision) << decision.error().message;
    EXPECT_FALSE(decision->accepted) << "chi2 rose by " << decision->chi2_increase;
    EXPECT_EQ(graph.EdgeCount(), kSquareNodes - 1);
    for (int i = 0; i < kSquareNodes; ++i) {  // refused: the poses as before, bit for bit
      EXPECT_EQ(graph.Pose(i).matrix(), before[i].matrix()) << i;
    }
  }
  // The true loop is still accepted afterwards, against the drifted chain.
  const auto true_loop = graph.TryAddLoopEdge(TrueLoop(truth));
  ASSERT_TRUE(true_loop);
  EXPECT_TRUE(true_loop->accepted) << "chi2 rose by " << true_loop->chi2_increase;
}

TEST(PoseGraph, TheChiSquareRiseIsTheInnovationsMahalanobisDistance) {
  // Two nodes, one edge of covariance C1, then a loop edge of covariance C2 measuring the same
  // motion off by d: the rise is d^T (C1 + C2)^-1 d (linear here: pure translation).
  PoseGraph graph;
  ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0)));
  const Vector6d s1 = Sigmas(0.01, 0.02), s2 = Sigmas(0.01, 0.01);
  ASSERT_TRUE(graph.AddEdge(
      {0, 1, PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0), InformationOf(s1), EdgeKind::kSequential}));
  const auto decision = graph.TryAddLoopEdge(
      {0, 1, PoseFromXyzRpyDeg(1.05, 0, 0, 0, 0, 0), InformationOf(s2), EdgeKind::kLoop});
  ASSERT_TRUE(decision) << decision.error().message;
  const double expected = 0.05 * 0.05 / (0.02 * 0.02 + 0.01 * 0.01);  // = 5
  EXPECT_NEAR(decision->chi2_increase, expected, 1e-6 * expected);
  EXPECT_TRUE(decision->accepted);
  EXPECT_NEAR(decision->gate_chi2, 16.812, 1e-3);  // 6-dof quantile at 0.99
}

TEST(PoseGraph, AnAcceptedLoopBeyondTheKernelThresholdSettlesUnderTheKernel) {
  // Node 1 registered 1 m ahead (sigma 1 cm); a loop edge of sigma 10 cm claims 1.39 m. The rise
  // d^2 / (s1^2 + s2^2) = 15.06 passes the gate (16.81); the edge's own chi-square after the
  // trial, s2^2 d^2 / (s1^2 + s2^2)^2 = 14.91, is beyond the kernel's 12.59, so the graph settles
  // where the loop pulls with Huber's bounded force: x = 1 + a s1^2 / s2 (without the kernel it
  // would be the weighted mean, 1 + 0.39 / 101 = 1.00386).
  PoseGraph graph;
  ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0)));
  ASSERT_TRUE(graph.AddEdge({0, 1, PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0),
                             InformationOf(Sigmas(0.01, 0.01)), EdgeKind::kSequential}));
  const auto decision = graph.TryAddLoopEdge({0, 1, PoseFromXyzRpyDeg(1.39, 0, 0, 0, 0, 0),
                                              InformationOf(Sigmas(0.01, 0.1)), EdgeKind::kLoop});
  ASSERT_TRUE(decision) << decision.error().message;
  EXPECT_TRUE(decision->accepted);
  EXPECT_NEAR(decision->chi2_increase, 0.39 * 0.39 / 0.0101, 1e-4);
  EXPECT_NEAR(decision->edge_chi2, 0.01 * 0.39 * 0.39 / (0.0101 * 0.0101), 1e-4);
  const double a = std::sqrt(PoseGraphConfig{}.loop_kernel_chi2);
  EXPECT_NEAR(graph.Pose(1).translation().x(), 1 + a * 0.01 * 0.01 / 0.1, 1e-6);
}

// --- The edge's weight is the registration's information as it is ----------------------------

// Point-to-plane pairs in the target frame at the true pose, as ICP sees them at convergence.
struct PlanePair {
  Eigen::Vector3d p, n;  // the source point mapped into the target, the target's normal there
};

TEST(PoseGraph, EdgeChiSquareIsThePointToPlaneCostOfTheRegistrationsHessian) {
  // ICP's Hessian (fast_pipeline.cpp: r = n.(p - t), dr/d(omega) = p x n, dr/dv = n, divided
  // by the residual's variance) as the edge's information: for an estimate off the measurement,
  // the edge's chi-square must equal the point-to-plane cost of that estimate / variance (to
  // second order), which holds only with the target-frame perturbation [R(omega), v] * T.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1, 1);
  std::vector<PlanePair> pairs;
  for (int i = 0; i < 400; ++i) {  // points 2-6 m out on randomly oriented surfaces
    const Eigen::Vector3d p =
        Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized() * (4 + 2 * u(rng));
    pairs.push_back({p, Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()});
  }
  const double sigma_m = 0.005;  // the LMS200's range noise (DESIGN.md)
  Matrix6d information = Matrix6d::Zero();
  for (const PlanePair& q : pairs) {
    Vector6d J;
    J << q.p.cross(q.n), q.n;
    information += J * J.transpose() / (sigma_m * sigma_m);
  }
  // The measured motion turns and moves far, so a source-frame convention would differ.
  const Eigen::Isometry3d Z = PoseFromXyzRpyDeg(3, -1, 0.2, 4, -3, 70);
  const Eigen::Isometry3d T_map_a = PoseFromXyzRpyDeg(-2, 5, 0.1, 1, 2, -40);
  Vector6d delta;
  delta << 0.02 * kDeg, -0.03 * kDeg, 0.05 * kDeg, 0.004, -0.003, 0.002;
  const Eigen::Isometry3d estimate = Exp(delta).inverse() * Z;  // Z = Exp(delta) * estimate

  PoseGraph graph;
  ASSERT_TRUE(graph.AddNode(T_map_a));
  ASSERT_TRUE(graph.AddNode(T_map_a * estimate));
  ASSERT_TRUE(graph.AddEdge({0, 1, Z, information, EdgeKind::kSequential}));
  // The point-to-plane cost at the estimate: source points at Z are on their planes, so at the
  // estimate each lies at Exp(delta)^-1 p.
  double cost = 0;
  for (const PlanePair& q : pairs) {
    const double r = q.n.dot(Exp(delta).inverse() * q.p - q.p);
    cost += r * r / (sigma_m * sigma_m);
  }
  ASSERT_GT(cost, 10.0);  // the estimate is clearly off: the comparison means something
  EXPECT_NEAR(graph.Chi2(), cost, 0.01 * cost);
}

TEST(PoseGraph, InformationIsWeightedInTheTargetFrame) {
  // Node 0 turned 90 deg; two registrations of node 1 turned 90 deg further: one sure along the
  // target's x (1 mm) but not its y (1 m), one the other way round. The optimum takes x from
  // the first (1 m) and y from the second (0 m), both in node 0's frame.
  PoseGraph graph;
  const Eigen::Isometry3d T0 = PoseFromXyzRpyDeg(2, 3, 0, 0, 0, 90);
  ASSERT_TRUE(graph.AddNode(T0));
  ASSERT_TRUE(graph.AddNode(T0 * PoseFromXyzRpyDeg(1.2, 0.1, 0, 0, 0, 90)));
  Vector6d sure_x = Sigmas(0.01, 0.001), sure_y = Sigmas(0.01, 0.001);
  sure_x(4) = 1.0;
  sure_y(3) = 1.0;
  ASSERT_TRUE(graph.AddEdge({0, 1, PoseFromXyzRpyDeg(1, 0.2, 0, 0, 0, 90), InformationOf(sure_x),
                             EdgeKind::kSequential}));
  ASSERT_TRUE(graph.AddEdge({0, 1, PoseFromXyzRpyDeg(1.3, 0, 0, 0, 0, 90), InformationOf(sure_y),
                             EdgeKind::kSequential}));
  ASSERT_TRUE(graph.Optimize());
  const Eigen::Isometry3d T_0_1 = graph.Pose(0).inverse() * graph.Pose(1);
  // Weighted means: x = (1 / 1e-6 + 1.3 / 1) / (1e6 + 1), y = (0.2 / 1) / (1 + 1e6).
  EXPECT_NEAR(T_0_1.translation().x(), 1.0, 1e-6);
  EXPECT_NEAR(T_0_1.translation().y(), 0.0, 1e-6);
}

// --- The robust kernel -------------------------------------------------------------------------

TEST(PoseGraph, RobustKernelBoundsAWrongLoopsPull) {
  // Node 1 registered 1 m ahead (sigma 1 cm) and a wrong loop edge claiming 2 m (sigma 1 cm).
  // Without a kernel they meet half way (1.5 m). With Huber's threshold a (a^2 = 12.59) the loop
  // pulls with a constant force beyond a: the balance is where the sequential edge's whitened
  // residual reaches a, x = 1 + a * 0.01 m, however wrong the loop.
  const double a = std::sqrt(PoseGraphConfig{}.loop_kernel_chi2);
  for (double claim_m : {2.0, 5.0}) {
    for (EdgeKind kind : {EdgeKind::kSequential, EdgeKind::kLoop}) {
      PoseGraph graph;
      ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
      ASSERT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0)));
      const Matrix6d information = InformationOf(Sigmas(0.01, 0.01));
      ASSERT_TRUE(graph.AddEdge(
          {0, 1, PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0), information, EdgeKind::kSequential}));
      ASSERT_TRUE(
          graph.AddEdge({0, 1, PoseFromXyzRpyDeg(claim_m, 0, 0, 0, 0, 0), information, kind}));
      ASSERT_TRUE(graph.Optimize());
      const double x = graph.Pose(1).translation().x();
      const double expected = kind == EdgeKind::kLoop ? 1 + a * 0.01 : (1 + claim_m) / 2;
      // To a thousandth of the edges' 1 cm sigma: Ceres stops on a relative change of the cost.
      EXPECT_NEAR(x, expected, 1e-5) << ToString(kind) << " edge claiming " << claim_m << " m";
    }
  }
}

TEST(PoseGraph, RobustKernelKeepsTheSquareCloserToTheTruthUnderAForcedFalseLoop) {
  // The false loop forced in (as if accepted while the graph was loose) beside the true one.
  const std::vector<Eigen::Isometry3d> truth = SquareTruth();
  WorstError worst[2];
  for (EdgeKind kind : {EdgeKind::kSequential, EdgeKind::kLoop}) {
    PoseGraph graph = ChainedGraph(truth[0], SquareOdometry(truth));
    ASSERT_TRUE(graph.AddEdge(TrueLoop(truth)));
    PoseGraphEdge wrong = FalseLoop(truth);
    wrong.kind = kind;
    ASSERT_TRUE(graph.AddEdge(wrong));
    ASSERT_TRUE(graph.Optimize());
    worst[kind == EdgeKind::kLoop] = Worst(graph.Poses(), truth);
  }
  // Without the kernel the 2 m lie splits between two precise edges: metres off. With it the
  // pull is bounded (about a * sigma of the edges it fights): centimetres.
  EXPECT_GT(worst[0].translation_m, 0.5);
  EXPECT_LT(worst[1].translation_m, 0.1);
}

// --- Covariance and loop candidates ------------------------------------------------------------

// Nodes 1 m apart along x, each edge sigma_t per axis and a near-exact rotation.
PoseGraph Chain(int nodes, double sigma_t) {
  PoseGraph graph;
  const Matrix6d information = InformationOf(Sigmas(1e-4, sigma_t));
  for (int k = 0; k < nodes; ++k) {
    EXPECT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(k, 0, 0, 0, 0, 0)));
    if (k > 0) {
      EXPECT_TRUE(graph.AddEdge(
          {k - 1, k, PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0), information, EdgeKind::kSequential}));
    }
  }
  return graph;
}

TEST(PoseGraph, RelativeCovarianceAddsAlongAChainAndHalvesWithAParallelEdge) {
  PoseGraph graph = Chain(3, 0.1);
  // Rotation sigma 1e-4 deg over a 1 m lever adds ~3e-12 m^2: the translations' 0.01 m^2 add.
  for (auto [anchor, node] : {std::pair{0, 2}, std::pair{2, 0}, std::pair{1, 2}}) {
    const auto C = graph.RelativePositionCovariance(anchor, node);
    ASSERT_TRUE(C) << C.error().message;
    const double per_edge = 0.01 * std::abs(anchor - node);
    EXPECT_TRUE(C->isApprox(per_edge * Eigen::Matrix3d::Identity(), 1e-6))
        << anchor << " -> " << node << ":\n"
        << *C;
  }
  // A second, equal registration of 1 -> 2: that step's covariance halves.
  ASSERT_TRUE(graph.AddEdge({1, 2, PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0),
                             InformationOf(Sigmas(1e-4, 0.1)), EdgeKind::kSequential}));
  const auto C = graph.RelativePositionCovariance(0, 2);
  ASSERT_TRUE(C);
  EXPECT_TRUE(C->isApprox(0.015 * Eigen::Matrix3d::Identity(), 1e-6)) << *C;
}

// Out along y = 0 and back along y = 2.5 m: nodes 0..5 at x = 0..5, node 6 at (5, 2.5), nodes
// 7..11 at x = 4..0. From node 11 at (0, 2.5): node 9 lies 2 m away, node 0 2.5 m, node 1
// sqrt(7.25) = 2.69 m, node 8 3 m, node 2 sqrt(10.25) = 3.20 m, node 3 sqrt(15.25) = 3.91 m.
PoseGraph OutAndBack(double sigma_t) {
  PoseGraph graph;
  std::vector<Eigen::Isometry3d> truth;
  for (int k = 0; k <= 5; ++k) truth.push_back(PoseFromXyzRpyDeg(k, 0, 0, 0, 0, 0));
  truth.push_back(PoseFromXyzRpyDeg(5, 2.5, 0, 0, 0, 180));
  for (int k = 4; k >= 0; --k) truth.push_back(PoseFromXyzRpyDeg(k, 2.5, 0, 0, 0, 180));
  const Matrix6d information = InformationOf(Sigmas(0.01, sigma_t));
  for (std::size_t k = 0; k < truth.size(); ++k) {
    EXPECT_TRUE(graph.AddNode(truth[k]));
    if (k > 0) {
      EXPECT_TRUE(
          graph.AddEdge({static_cast<int>(k) - 1, static_cast<int>(k),
                         truth[k - 1].inverse() * truth[k], information, EdgeKind::kSequential}));
    }
  }
  return graph;
}

std::vector<int> Nodes(const std::vector<LoopCandidate>& candidates) {
  std::vector<int> out;
  for (const LoopCandidate& c : candidates) out.push_back(c.node);
  return out;
}

TEST(PoseGraph, LoopCandidatesAreTheEarlierNodesWithinReachNearestFirst) {
  LoopCandidateQuery query;
  query.max_distance_m = 3.1;
  // Precise odometry (1 mm per step): the bound is about a centimetre, so the distance decides.
  // Node 10 is joined to node 11 by its edge; node 9, 2 m back along the way, is within reach.
  const auto precise = OutAndBack(0.001).LoopCandidates(11, query);
  ASSERT_TRUE(precise) << precise.error().message;
  EXPECT_EQ(Nodes(*precise), (std::vector<int>{9, 0, 1, 8}));
  EXPECT_NEAR(precise->at(1).distance_m, 2.5, 1e-9);
  EXPECT_LT(precise->at(1).uncertainty_m, 0.05);
  // At least 5 m back along the trajectory: nodes 10..7 are the way just driven.
  query.min_travel_m = 5.0;
  const auto travelled = OutAndBack(0.001).LoopCandidates(11, query);
  ASSERT_TRUE(travelled);
  EXPECT_EQ(Nodes(*travelled), (std::vector<int>{0, 1}));
  // Odometry good to 10 cm per axis per step: node 3, 8 steps (0.28 m sigma) and 3.91 m away,
  // may lie within 3.1 m (4.03 sigma = 1.14 m); node 4, 4.72 m away, 7 steps, may not.
  const auto loose = OutAndBack(0.1).LoopCandidates(11, query);
  ASSERT_TRUE(loose);
  EXPECT_EQ(Nodes(*loose), (std::vector<int>{0, 1, 2, 3}));
  EXPECT_NEAR(loose->back().uncertainty_m, 4.03 * std::sqrt(8 * 0.01), 0.02);
}

// --- Contracts -------------------------------------------------------------------------------

TEST(PoseGraph, SameCallsGiveTheSamePosesBitForBit) {
  const std::vector<Eigen::Isometry3d> truth = SquareTruth();
  std::vector<Eigen::Isometry3d> runs[2];
  for (auto& poses : runs) {
    PoseGraph graph = ChainedGraph(truth[0], SquareOdometry(truth));
    ASSERT_TRUE(graph.TryAddLoopEdge(TrueLoop(truth)));
    poses = graph.Poses();
  }
  for (int i = 0; i < kSquareNodes; ++i) EXPECT_EQ(runs[0][i].matrix(), runs[1][i].matrix());
}

TEST(PoseGraph, AnEmptyGraphOrALoneStartHasNothingToOptimise) {
  PoseGraph graph;
  ASSERT_TRUE(graph.Optimize());
  EXPECT_FALSE(graph.LoopCandidates(0, {}));
  ASSERT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(1, 2, 0, 0, 0, 30)));
  const auto summary = graph.Optimize();
  ASSERT_TRUE(summary);
  EXPECT_EQ(summary->iterations, 0);
  EXPECT_TRUE(graph.Pose(0).isApprox(PoseFromXyzRpyDeg(1, 2, 0, 0, 0, 30), 1e-15));
  const auto none = graph.LoopCandidates(0, {});
  ASSERT_TRUE(none);
  EXPECT_TRUE(none->empty());
}

TEST(PoseGraph, BadEdgesAndNodesAreErrorsNamingThem) {
  PoseGraph graph;
  ASSERT_TRUE(graph.AddNode(Eigen::Isometry3d::Identity()));
  ASSERT_TRUE(graph.AddNode(PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0)));
  const Matrix6d information = InformationOf(Sigmas(0.1, 0.01));
  auto message = [&](const PoseGraphEdge& e) {
    const auto r = graph.AddEdge(e);
    return r ? std::string("accepted") : r.error().message;
  };
  const Eigen::Isometry3d step = PoseFromXyzRpyDeg(1, 0, 0, 0, 0, 0);
  EXPECT_NE(message({0, 2, step, information}).find("no such node"), std::string::npos);
  EXPECT_NE(message({1, 1, step, information}).find("joins a node to itself"), std::string::npos);
  EXPECT_NE(message({0, 1, step}).find("not positive definite"), std::string::npos);  // unset
  Matrix6d free_axis = information;
  free_axis(3, 3) = 0;  // a corridor's axis
  EXPECT_NE(message({0, 1, step, free_axis}).find("not positive definite"), std::string::npos);
  Matrix6d skew = information;
  skew(0, 1) = 5;
  EXPECT_NE(message({0, 1, step, skew}).find("not symmetric"), std::string::npos);
  Eigen::Isometry3d scaled = step;
  scaled.linear() *= 1.1;
  EXPECT_NE(message({0, 1, scaled, information}).find("not a rotation"), std::string::npos);
  EXPECT_EQ(graph.EdgeCount(), 0);

  Eigen::Isometry3d nan_pose = Eigen::Isometry3d::Identity();
  nan_pose.translation().x() = std::nan("");
  EXPECT_FALSE(graph.AddNode(nan_pose));
  EXPECT_EQ(graph.NodeCount(), 2);

  // Node 1 has no edge yet: its pose is undetermined.
  const auto lonely = graph.Optimize();
  ASSERT_FALSE(lonely);
  EXPECT_NE(lonely.error().message.find("node 1 has no chain of edges to node 0"),
            std::string::npos);
  ASSERT_TRUE(graph.AddEdge({0, 1, step, information, EdgeKind::kSequential}));
  EXPECT_FALSE(graph.TryAddLoopEdge({0, 1, step, information, EdgeKind::kSequential}));
  EXPECT_FALSE(graph.RelativePositionCovariance(1, 1));
  EXPECT_FALSE(graph.LoopCandidates(5, {}));
  LoopCandidateQuery negative;
  negative.max_distance_m = -1;
  EXPECT_FALSE(graph.LoopCandidates(1, negative));
}

TEST(PoseGraph, ConfigOutOfRangeThrows) {
  PoseGraphConfig config;
  config.loop_acceptance_probability = 1.0;
  EXPECT_THROW(PoseGraph{config}, std::invalid_argument);
  config = {};
  config.loop_kernel_chi2 = 0;
  EXPECT_THROW(PoseGraph{config}, std::invalid_argument);
  config = {};
  config.max_iterations = 0;
  EXPECT_THROW(PoseGraph{config}, std::invalid_argument);
}

}  // namespace
}  // namespace pitchlab::mapping
