#include "pitchlab/mapping/pose_graph.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>
#include <string>
#include <utility>

#include <ceres/ceres.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "chi_square.hpp"
#include "relative_pose_cost.hpp"

#include "pitchlab/sensors/number_text.hpp"

namespace pitchlab::mapping {

namespace {

// One node's parameters as Ceres sees them: a unit quaternion (Eigen order x, y, z, w) on
// EigenQuaternionManifold and a translation [m]. Ceres' tangent step is a rotation applied on
// the left (in map axes) and a translation added in map axes: a translation block's covariance
// is the position's, in map axes.
struct NodeParameters {
  double q[4];
  double t[3];
};

NodeParameters ToParameters(const Eigen::Isometry3d& T) {
  const Eigen::Quaterniond q(T.rotation());
  return {{q.x(), q.y(), q.z(), q.w()},
          {T.translation().x(), T.translation().y(), T.translation().z()}};
}

Eigen::Isometry3d ToIsometry(const NodeParameters& p) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = Eigen::Quaterniond(p.q[3], p.q[0], p.q[1], p.q[2]).normalized().toRotationMatrix();
  T.translation() = Eigen::Vector3d(p.t[0], p.t[1], p.t[2]);
  return T;
}

// A pose is usable when finite and rigid. 1e-6: a rotation stored as doubles and composed a few
// thousand times stays orthonormal to ~1e-12; 1e-6 catches a scaled or sheared matrix, not that.
Result<void> CheckRigid(const Eigen::Isometry3d& T, const std::string& what) {
  if (!T.matrix().allFinite()) return Fail(Error::Code::kInvalidArgument, what + " is not finite");
  const Eigen::Matrix3d R = T.linear();
  if (!(R.transpose() * R).isApprox(Eigen::Matrix3d::Identity(), 1e-6) || R.determinant() < 0) {
    return Fail(Error::Code::kInvalidArgument, what + " is not a rotation and translation");
  }
  return {};
}

// The upper Cholesky factor S of the information (S^T S = information), after checking it is a
// weight: finite, symmetric, positive definite. An eigenvalue below 1e-12 of the largest is zero
// to the ~16 digits the Hessian was summed in: that direction carries no information.
Result<Matrix6d> SqrtInformation(const Matrix6d& information, const std::string& what) {
  if (!information.allFinite()) {
    return Fail(Error::Code::kInvalidArgument, what + ": information is not finite");
  }
  const double scale = information.cwiseAbs().maxCoeff();
  if ((information - information.transpose()).cwiseAbs().maxCoeff() > 1e-9 * scale) {
    return Fail(Error::Code::kInvalidArgument, what + ": information is not symmetric");
  }
  const Matrix6d symmetric = 0.5 * (information + information.transpose());
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eigen(symmetric, Eigen::EigenvaluesOnly);
  if (!(eigen.eigenvalues()(0) > 1e-12 * eigen.eigenvalues()(5))) {
    return Fail(Error::Code::kInvalidArgument,
                what + ": information is not positive definite (smallest eigenvalue " +
                    NumberText(eigen.eigenvalues()(0)) +
                    "): a direction the registration left free; pass the inverse of its "
                    "covariance, which bounds that direction by its guess");
  }
  return Matrix6d(symmetric.llt().matrixU());
}

std::string EdgeName(const PoseGraphEdge& edge) {
  return std::string(ToString(edge.kind)) + " edge " + std::to_string(edge.from) + " -> " +
         std::to_string(edge.to);
}

}  // namespace

const char* ToString(EdgeKind kind) {
  switch (kind) {
    case EdgeKind::kSequential:
      return "sequential";
    case EdgeKind::kLoop:
      return "loop";
  }
  return "unknown";
}

void PoseGraphConfig::Validate() const {
  if (!(std::isfinite(loop_kernel_chi2) && loop_kernel_chi2 > 0)) {
    throw std::invalid_argument("pose_graph.loop_kernel_chi2 = " +
                                NumberText(loop_kernel_chi2) + ": must be finite and > 0");
  }
  if (!(loop_acceptance_probability > 0 && loop_acceptance_probability < 1)) {
    throw std::invalid_argument(
        "pose_graph.loop_acceptance_probability = " + NumberText(loop_acceptance_probability) +
        ": must lie in (0, 1)");
  }
  if (max_iterations < 1) {
    throw std::invalid_argument("pose_graph.max_iterations = " + std::to_string(max_iterations) +
                                ": must be >= 1");
  }
}

struct PoseGraph::Impl {
  struct StoredEdge {
    PoseGraphEdge edge;
    ceres::ResidualBlockId block = nullptr;
  };

  explicit Impl(const PoseGraphConfig& c)
      : config(c),
        gate_chi2(ChiSquareQuantile(6, c.loop_acceptance_probability)),
        loop_kernel(std::sqrt(c.loop_kernel_chi2)),  // Huber's a: rho(s) = s up to s = a^2
        problem(ProblemOptions()) {}

  static ceres::Problem::Options ProblemOptions() {
    ceres::Problem::Options options;
    options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;       // quaternion_manifold
    options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;  // loop_kernel
    options.enable_fast_removal = true;  // a rejected loop edge leaves again
    return options;
  }

  ceres::ResidualBlockId AddBlock(const PoseGraphEdge& edge, const Matrix6d& sqrt_information,
                                  bool with_kernel) {
    auto* cost = new ceres::AutoDiffCostFunction<RelativePoseCost, 6, 4, 3, 4, 3>(
        new RelativePoseCost(edge.T_from_to, sqrt_information));
    NodeParameters& a = nodes[edge.from];
    NodeParameters& b = nodes[edge.to];
    return problem.AddResidualBlock(cost, with_kernel ? &loop_kernel : nullptr, a.q, a.t, b.q, b.t);
  }

  Result<Matrix6d> CheckEdge(const PoseGraphEdge& edge) const {
    const std::string name = EdgeName(edge);
    const int n = static_cast<int>(nodes.size());
    if (edge.from < 0 || edge.from >= n || edge.to < 0 || edge.to >= n) {
      return Fail(Error::Code::kInvalidArgument,
                  name + ": no such node (the graph has " + std::to_string(n) + ")");
    }
    if (edge.from == edge.to) {
      return Fail(Error::Code::kInvalidArgument, name + ": joins a node to itself");
    }
    if (auto rigid = CheckRigid(edge.T_from_to, name + ": T_from_to"); !rigid) {
      return tl::make_unexpected(rigid.error());
    }
    return SqrtInformation(edge.information, name);
  }

  // Every node must reach `root` through edges: a node that does not has an undetermined pose.
  Result<void> CheckConnected(int root) const {
    std::vector<std::vector<int>> neighbours(nodes.size());
    for (const StoredEdge& s : edges) {
      neighbours[s.edge.from].push_back(s.edge.to);
      neighbours[s.edge.to].push_back(s.edge.from);
    }
    std::vector<bool> reached(nodes.size(), false);
    std::vector<int> stack{root};
    reached[root] = true;
    while (!stack.empty()) {
      const int node = stack.back();
      stack.pop_back();
      for (int next : neighbours[node]) {
        if (reached[next]) continue;
        reached[next] = true;
        stack.push_back(next);
      }
    }
    const auto lost = std::find(reached.begin(), reached.end(), false);
    if (lost == reached.end()) return {};
    return Fail(Error::Code::kInvalidArgument,
                "pose graph: node " + std::to_string(lost - reached.begin()) +
                    " has no chain of edges to node " + std::to_string(root) +
                    ": its pose is undetermined (add its registration edge first)");
  }

  Result<OptimizationSummary> Optimize() {
    OptimizationSummary out;
    if (nodes.empty()) {  // nothing to move
      out.converged = true;
      return out;
    }
    if (auto connected = CheckConnected(0); !connected) {
      return tl::make_unexpected(connected.error());
    }
    if (edges.empty()) {  // node 0 alone: nothing to move
      optimised = true;
      optimal_chi2 = 0;
      out.converged = true;
      return out;
    }
    ceres::Solver::Options options;
    options.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
    options.num_threads = 1;  // deterministic: the same calls give the same poses
    options.max_num_iterations = config.max_iterations;
    options.logging_type = ceres::SILENT;
    // Ceres stops when the cost changes by less than this fraction: its default 1e-6 stopped a
    // Huber-weighted edge 3e-4 m short of the optimum (the robust kernel test); 1e-10 leaves
    // 3e-6 m.
    options.function_tolerance = 1e-10;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    if (!summary.IsSolutionUsable()) {
      return Fail(Error::Code::kFailed, "pose graph: Ceres failed: " + summary.message);
    }
    optimised = true;
    optimal_chi2 = 2 * summary.final_cost;  // Ceres minimises 1/2 sum rho(|r|^2)
    out.iterations = summary.num_successful_steps + summary.num_unsuccessful_steps;
    out.chi2_before = 2 * summary.initial_cost;
    out.chi2_after = optimal_chi2;
    out.converged = summary.termination_type == ceres::CONVERGENCE;
    return out;
  }

  double EdgeChi2(ceres::ResidualBlockId block) const {
    double cost = 0;
    problem.EvaluateResidualBlock(block, /*apply_loss_function=*/false, &cost, nullptr, nullptr);
    return 2 * cost;
  }

  void Hold(int node) {
    problem.SetParameterBlockConstant(nodes[node].q);
    problem.SetParameterBlockConstant(nodes[node].t);
  }

  // The gauge: which node is held fixed (node 0, the known start, except while a covariance
  // relative to another node is computed).
  void MoveAnchor(int from, int to) {
    if (from == to) return;
    problem.SetParameterBlockVariable(nodes[from].q);
    problem.SetParameterBlockVariable(nodes[from].t);
    Hold(to);
  }

  // Marginal covariances of the positions of `targets` with `anchor` held instead of node 0.
  Result<std::vector<Eigen::Matrix3d>> PositionCovariances(int anchor,
                                                           const std::vector<int>& targets) {
    if (auto connected = CheckConnected(anchor); !connected) {
      return tl::make_unexpected(connected.error());
    }
    std::vector<std::pair<const double*, const double*>> blocks;
    for (int n : targets) blocks.emplace_back(nodes[n].t, nodes[n].t);
    ceres::Covariance::Options options;
    options.algorithm_type = ceres::SPARSE_QR;
    options.num_threads = 1;
    ceres::Covariance covariance(options);
    MoveAnchor(0, anchor);
    const bool computed = covariance.Compute(blocks, &problem);
    MoveAnchor(anchor, 0);
    if (!computed) {
      return Fail(Error::Code::kFailed, "pose graph: the covariance relative to node " +
                                            std::to_string(anchor) +
                                            " could not be computed (rank-deficient Jacobian)");
    }
    std::vector<Eigen::Matrix3d> out(targets.size());
    for (std::size_t i = 0; i < targets.size(); ++i) {
      Eigen::Matrix<double, 3, 3, Eigen::RowMajor> m;
      covariance.GetCovarianceBlock(nodes[targets[i]].t, nodes[targets[i]].t, m.data());
      out[i] = m;
    }
    return out;
  }

  PoseGraphConfig config;
  double gate_chi2;
  // The manifold and the kernel outlive the problem that points to them (declared before it).
  ceres::EigenQuaternionManifold quaternion_manifold;
  ceres::HuberLoss loop_kernel;
  ceres::Problem problem;
  std::deque<NodeParameters> nodes;  // a deque: Ceres keeps pointers into it
  std::vector<StoredEdge> edges;
  bool optimised = true;    // the poses are the optimum of the current edges
  double optimal_chi2 = 0;  // that optimum's chi-square, when optimised
};

PoseGraph::PoseGraph(const PoseGraphConfig& config) {
  config.Validate();
  impl_ = std::make_unique<Impl>(config);
}

PoseGraph::~PoseGraph() = default;
PoseGraph::PoseGraph(PoseGraph&&) noexcept = default;
PoseGraph& PoseGraph::operator=(PoseGraph&&) noexcept = default;

Result<int> PoseGraph::AddNode(const Eigen::Isometry3d& T_map_base) {
  const int index = static_cast<int>(impl_->nodes.size());
  if (auto rigid = CheckRigid(T_map_base, "node " + std::to_string(index) + ": T_map_base");
      !rigid) {
    return tl::make_unexpected(rigid.error());
  }
  NodeParameters& p = impl_->nodes.emplace_back(ToParameters(T_map_base));
  impl_->problem.AddParameterBlock(p.q, 4, &impl_->quaternion_manifold);
  impl_->problem.AddParameterBlock(p.t, 3);
  if (index == 0) impl_->Hold(0);  // the start is known
  impl_->optimised = false;
  return index;
}

Result<void> PoseGraph::AddEdge(const PoseGraphEdge& edge) {
  const Result<Matrix6d> sqrt_information = impl_->CheckEdge(edge);
  if (!sqrt_information) return tl::make_unexpected(sqrt_information.error());
  const bool kernel = edge.kind == EdgeKind::kLoop;
  impl_->edges.push_back({edge, impl_->AddBlock(edge, *sqrt_information, kernel)});
  impl_->optimised = false;
  return {};
}

Result<OptimizationSummary> PoseGraph::Optimize() { return impl_->Optimize(); }

Result<LoopDecision> PoseGraph::TryAddLoopEdge(const PoseGraphEdge& edge) {
  Impl& g = *impl_;
  if (edge.kind != EdgeKind::kLoop) {
    return Fail(Error::Code::kInvalidArgument,
                EdgeName(edge) + ": TryAddLoopEdge takes loop edges (kind kLoop)");
  }
  const Result<Matrix6d> sqrt_information = g.CheckEdge(edge);
  if (!sqrt_information) return tl::make_unexpected(sqrt_information.error());
  if (!g.optimised) {  // the test compares optima: the graph's without the edge first
    if (auto before = g.Optimize(); !before) return tl::make_unexpected(before.error());
  }
  const double chi2_before = g.optimal_chi2;
  const std::deque<NodeParameters> saved = g.nodes;
  // The trial: the edge without its kernel, so the rise in chi-square is chi-square distributed.
  g.edges.push_back({edge, g.AddBlock(edge, *sqrt_information, false)});
  const Result<OptimizationSummary> trial = g.Optimize();
  LoopDecision decision;
  decision.gate_chi2 = g.gate_chi2;
  if (trial) {
    decision.chi2_increase = trial->chi2_after - chi2_before;
    decision.edge_chi2 = g.EdgeChi2(g.edges.back().block);
    decision.accepted = decision.chi2_increase <= g.gate_chi2;
  }
  g.problem.RemoveResidualBlock(g.edges.back().block);
  g.edges.pop_back();
  if (!decision.accepted) {  // rejected (or failed): the graph as it was
    std::copy(saved.begin(), saved.end(), g.nodes.begin());
    g.optimal_chi2 = chi2_before;
    g.optimised = true;
    if (!trial) return tl::make_unexpected(trial.error());
    return decision;
  }
  g.edges.push_back({edge, g.AddBlock(edge, *sqrt_information, true)});
  // Within the kernel's threshold Huber is the square: the trial's optimum stands. Beyond it the
  // edge pulls less, so the optimum moves.
  if (decision.edge_chi2 > g.config.loop_kernel_chi2) {
    if (auto settled = g.Optimize(); !settled) return tl::make_unexpected(settled.error());
  }
  return decision;
}

Result<Eigen::Matrix3d> PoseGraph::RelativePositionCovariance(int anchor, int node) const {
  const int n = NodeCount();
  if (anchor < 0 || anchor >= n || node < 0 || node >= n || anchor == node) {
    return Fail(Error::Code::kInvalidArgument,
                "pose graph: relative covariance of node " + std::to_string(node) + " to node " +
                    std::to_string(anchor) + ": needs two distinct nodes of " + std::to_string(n));
  }
  auto covariances = impl_->PositionCovariances(anchor, {node});
  if (!covariances) return tl::make_unexpected(covariances.error());
  return covariances->front();
}

namespace {

Result<void> CheckQuery(const LoopCandidateQuery& query) {
  if (std::isfinite(query.max_distance_m) && query.max_distance_m > 0 && query.probability > 0 &&
      query.probability < 1 && std::isfinite(query.min_travel_m) && query.min_travel_m >= 0) {
    return {};
  }
  return Fail(Error::Code::kInvalidArgument,
              "loop candidates: max_distance_m = " + NumberText(query.max_distance_m) +
                  " (finite, > 0), probability = " + NumberText(query.probability) +
                  " (in (0, 1)), min_travel_m = " + NumberText(query.min_travel_m) +
                  " (finite, >= 0)");
}

}  // namespace

// Earlier nodes not joined to `node` by an edge and at least min_travel_m back along the
// estimated trajectory, latest first.
std::vector<int> PoseGraph::EarlierUnjoined(int node, double min_travel_m) const {
  std::vector<bool> joined(node, false);
  for (const Impl::StoredEdge& s : impl_->edges) {
    if (s.edge.to == node && s.edge.from < node) joined[s.edge.from] = true;
    if (s.edge.from == node && s.edge.to < node) joined[s.edge.to] = true;
  }
  const std::vector<Eigen::Isometry3d> poses = Poses();
  std::vector<int> out;
  double travel_m = 0;  // from `node` back to i
  for (int i = node - 1; i >= 0; --i) {
    travel_m += (poses[i + 1].translation() - poses[i].translation()).norm();
    if (!joined[i] && travel_m >= min_travel_m) out.push_back(i);
  }
  return out;
}

Result<std::vector<LoopCandidate>> PoseGraph::LoopCandidates(
    int node, const LoopCandidateQuery& query) const {
  if (node < 0 || node >= NodeCount()) {
    return Fail(Error::Code::kInvalidArgument, "loop candidates: no node " + std::to_string(node));
  }
  if (auto ok = CheckQuery(query); !ok) return tl::make_unexpected(ok.error());
  const std::vector<int> earlier = EarlierUnjoined(node, query.min_travel_m);
  std::vector<LoopCandidate> out;
  if (earlier.empty()) return out;
  auto covariances = impl_->PositionCovariances(node, earlier);
  if (!covariances) return tl::make_unexpected(covariances.error());
  // The relative position lies within k sigma along the most uncertain axis with `probability`.
  const double k = std::sqrt(ChiSquareQuantile(3, query.probability));
  const Eigen::Vector3d here = Pose(node).translation();
  for (std::size_t i = 0; i < earlier.size(); ++i) {
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen((*covariances)[i],
                                                               Eigen::EigenvaluesOnly);
    LoopCandidate c;
    c.node = earlier[i];
    c.distance_m = (Pose(earlier[i]).translation() - here).norm();
    c.uncertainty_m = k * std::sqrt(std::max(0.0, eigen.eigenvalues()(2)));
    if (c.distance_m - c.uncertainty_m <= query.max_distance_m) out.push_back(c);
  }
  std::sort(out.begin(), out.end(), [](const LoopCandidate& a, const LoopCandidate& b) {
    return a.distance_m != b.distance_m ? a.distance_m < b.distance_m : a.node < b.node;
  });
  return out;
}

int PoseGraph::NodeCount() const { return static_cast<int>(impl_->nodes.size()); }
int PoseGraph::EdgeCount() const { return static_cast<int>(impl_->edges.size()); }

Eigen::Isometry3d PoseGraph::Pose(int node) const { return ToIsometry(impl_->nodes.at(node)); }

std::vector<Eigen::Isometry3d> PoseGraph::Poses() const {
  std::vector<Eigen::Isometry3d> out;
  out.reserve(impl_->nodes.size());
  for (const NodeParameters& p : impl_->nodes) out.push_back(ToIsometry(p));
  return out;
}

double PoseGraph::Chi2() const {
  double cost = 0;
  if (!impl_->edges.empty()) {
    impl_->problem.Evaluate(ceres::Problem::EvaluateOptions(), &cost, nullptr, nullptr, nullptr);
  }
  return 2 * cost;
}

}  // namespace pitchlab::mapping
