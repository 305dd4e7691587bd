// Our own block-sparse Levenberg-Marquardt for pose graphs (pose_graph.hpp): the paper solves
// the hierarchy's factor graph with LM (Sec. "Pose Refinement by Hierarchical Optimization");
// here the structure, the Jacobians, the damping and the loop are ours, and Eigen's
// SimplicialLDLT only factorises.
//
// Conventions this header owns:
//   - Unknowns: every variable not marked fixed, 6 entries each in variable order (the caller
//     fixes a gauge, e.g. the first pose). Steps are left perturbations T <- exp(d) T.
//   - Normal equations H = sum J^T W J, g = sum J^T W r over the factors (IRLS weights for Huber
//     factors), stored in one sparse lower-triangular matrix whose pattern (the 6x6 blocks of
//     variables sharing a factor) is built and analysed ONCE (analyzePattern); each iteration
//     only writes values into fixed slots and re-factorises.
//   - Damping: (H + mu diag(H)) d = -g (Marquardt's scaling: translations and rotations with
//     their own units), mu adapted by Nielsen's rule: after a step with gain ratio rho > 0,
//     mu *= max(1/3, 1 - (2 rho - 1)^3), nu = 2; after a rejected step mu *= nu, nu *= 2.
//   - Converged when a step's largest entry is below step_tolerance, or an accepted step lowers
//     the cost by less than cost_tolerance (relative).
//   - Factors are linearised in parallel into per-factor slots, then summed serially in factor
//     order: the same bits for any number of threads. Nothing here throws or prints.
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <map>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "hots/options.hpp"
#include "hots/pose_graph.hpp"

namespace hots {

enum class SparseLmStatus { ok, not_converged, invalid_input, solver_failed };

inline const char* to_string(SparseLmStatus s) {
  switch (s) {
    case SparseLmStatus::ok:
      return "ok";
    case SparseLmStatus::not_converged:
      return "not_converged";
    case SparseLmStatus::invalid_input:
      return "invalid_input";
    default:
      return "solver_failed";
  }
}

struct SparseLmResult {
  SparseLmStatus status = SparseLmStatus::ok;
  const char* reason = "";
  double initial_cost = 0.0;
  double cost = 0.0;
  int iterations = 0;        ///< steps tried
  int accepted = 0;          ///< steps taken
  std::size_t unknowns = 0;  ///< 6 * free variables
  std::size_t nonzero_blocks = 0;

  bool ok() const { return status == SparseLmStatus::ok; }
};

/// The linear system of a graph at its current variables, with the pattern kept between calls.
class SparseNormalEquations {
 public:
  using SpMat = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  /// Builds the pattern for `graph` (its factors and fixed flags must not change afterwards).
  explicit SparseNormalEquations(const PoseGraph& graph) {
    const std::size_t n = graph.variables.size();
    column_.assign(n, -1);
    int free = 0;
    for (std::size_t v = 0; v < n; ++v)
      if (!graph.fixed[v]) column_[v] = free++;
    dim_ = 6 * free;
    // Blocks (row >= col in free-variable order) that some factor touches.
    std::map<std::pair<int, int>, std::size_t> block_of;
    factor_blocks_.resize(graph.factors.size());
    for (std::size_t k = 0; k < graph.factors.size(); ++k) {
      const auto vars = factor_vars(graph.factors[k]);
      for (int a = 0; a < 3; ++a) {
        for (int b = 0; b < 3; ++b) {
          factor_blocks_[k][static_cast<std::size_t>(3 * a + b)] = kNone;
          if (vars[static_cast<std::size_t>(a)] == kNoVariable ||
              vars[static_cast<std::size_t>(b)] == kNoVariable)
            continue;
          const int ca = column_[vars[static_cast<std::size_t>(a)]];
          const int cb = column_[vars[static_cast<std::size_t>(b)]];
          if (ca < 0 || cb < 0 || ca < cb) continue;  // fixed, or upper triangle
          const auto key = std::make_pair(ca, cb);
          auto it = block_of.find(key);
          if (it == block_of.end()) it = block_of.emplace(key, block_of.size()).first;
          factor_blocks_[k][static_cast<std::size_t>(3 * a + b)] = it->second;
        }
      }
    }
    for (int c = 0; c < free; ++c) {  // every diagonal block, so the damping has a slot
      const auto key = std::make_pair(c, c);
      if (!block_of.count(key)) block_of.emplace(key, block_of.size());
    }
    std::vector<Eigen::Triplet<double, int>> triplets;
    triplets.reserve(block_of.size() * 36);
    blocks_.resize(block_of.size());
    for (const auto& [key, index] : block_of) {
      blocks_[index] = key;
      for (int j = 0; j < 6; ++j)
        for (int i = 0; i < 6; ++i)
          triplets.emplace_back(6 * key.first + i, 6 * key.second + j, 0.0);
    }
    H_.resize(dim_, dim_);
    H_.setFromTriplets(triplets.begin(), triplets.end());
    H_.makeCompressed();
    // Where column j of each block starts in the value array (its 6 rows are contiguous).
    slots_.resize(blocks_.size());
    for (std::size_t b = 0; b < blocks_.size(); ++b) {
      for (int j = 0; j < 6; ++j) {
        const int col = 6 * blocks_[b].second + j;
        const int row = 6 * blocks_[b].first;
        const int* begin = H_.innerIndexPtr() + H_.outerIndexPtr()[col];
        const int* end = H_.innerIndexPtr() + H_.outerIndexPtr()[col + 1];
        slots_[b][static_cast<std::size_t>(j)] =
            static_cast<int>(std::lower_bound(begin, end, row) - H_.innerIndexPtr());
      }
    }
    for (int c = 0; c < free; ++c) diagonal_block_.push_back(block_of.at(std::make_pair(c, c)));
    g_ = Eigen::VectorXd::Zero(dim_);
  }

  int dim() const { return dim_; }
  std::size_t block_count() const { return blocks_.size(); }
  int column(std::size_t variable) const { return column_[variable]; }
  const SpMat& H() const { return H_; }
  const Eigen::VectorXd& g() const { return g_; }

  /// Fills H and g at the graph's variables; returns 1/2 sum rho(|e|^2).
  double assemble(const PoseGraph& graph, std::size_t grain) {
    const std::size_t m = graph.factors.size();
    lin_.resize(m);
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, m, std::max<std::size_t>(grain, 1)),
                      [&](const tbb::blocked_range<std::size_t>& r) {
                        for (std::size_t k = r.begin(); k != r.end(); ++k)
                          lin_[k] = whitened(graph.factors[k], graph.variables);
                      });
    std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0);
    g_.setZero();
    double cost = 0.0;
    for (std::size_t k = 0; k < m; ++k) {
      const PoseFactor& f = graph.factors[k];
      const Whitened& w = lin_[k];
      cost += w.cost;
      const auto vars = factor_vars(f);
      for (int a = 0; a < 3; ++a) {
        const std::size_t va = vars[static_cast<std::size_t>(a)];
        if (va == kNoVariable || column_[va] < 0) continue;
        g_.segment<6>(6 * column_[va]) += w.J[a].transpose() * w.e;
        for (int b = 0; b < 3; ++b) {
          const std::size_t block = factor_blocks_[k][static_cast<std::size_t>(3 * a + b)];
          if (block == kNone) continue;
          const Mat6d product = w.J[a].transpose() * w.J[b];
          add_block(block, product);
        }
      }
    }
    return cost;
  }

  /// H + mu diag(H) into `out` (same pattern as H).
  void damped(double mu, double min_diagonal, SpMat& out) const {
    out = H_;
    for (std::size_t c = 0; c < diagonal_block_.size(); ++c) {
      const auto& slot = slots_[diagonal_block_[c]];
      for (int j = 0; j < 6; ++j) {
        double& d = out.valuePtr()[slot[static_cast<std::size_t>(j)] + j];
        d += mu * std::max(d, min_diagonal);
      }
    }
  }

 private:
  static constexpr std::size_t kNone = static_cast<std::size_t>(-1);

  struct Whitened {
    Vec6d e = Vec6d::Zero();
    Mat6d J[3];
    double cost = 0.0;
  };

  static std::array<std::size_t, 3> factor_vars(const PoseFactor& f) {
    return {f.from, f.to, f.measured_var};
  }

  static Whitened whitened(const PoseFactor& f, const std::vector<Isometry3d>& vars) {
    const FactorLinearization lin = linearize_factor(f, vars);
    Whitened w;
    w.e = f.sqrt_information * lin.residual;
    const double sq = w.e.squaredNorm();
    w.cost = 0.5 * huber_cost(sq, f.huber);
    const double s = std::sqrt(huber_weight(std::sqrt(sq), f.huber));
    w.e *= s;
    w.J[0] = s * f.sqrt_information * lin.J_from;
    w.J[1] = s * f.sqrt_information * lin.J_to;
    w.J[2] = s * f.sqrt_information * lin.J_measured;
    return w;
  }

  void add_block(std::size_t block, const Mat6d& m) {
    double* values = H_.valuePtr();
    for (int j = 0; j < 6; ++j) {
      double* col = values + slots_[block][static_cast<std::size_t>(j)];
      for (int i = 0; i < 6; ++i) col[i] += m(i, j);
    }
  }

  std::vector<int> column_;
  int dim_ = 0;
  std::vector<std::array<std::size_t, 9>> factor_blocks_;
  std::vector<std::pair<int, int>> blocks_;
  std::vector<std::array<int, 6>> slots_;
  std::vector<std::size_t> diagonal_block_;
  SpMat H_;
  Eigen::VectorXd g_;
  std::vector<Whitened> lin_;
};

/// Solves the graph in place (see the header comment).
inline SparseLmResult solve_pose_graph(PoseGraph& graph, const SparseLmOptions& options = {}) {
  SparseLmResult result;
  if (!graph.valid() || options.max_iterations < 0 || !(options.initial_damping > 0.0)) {
    result.status = SparseLmStatus::invalid_input;
    result.reason = "bad indices, non-finite values, or bad options";
    return result;
  }
  SparseNormalEquations system(graph);
  result.unknowns = static_cast<std::size_t>(system.dim());
  result.nonzero_blocks = system.block_count();
  double cost = system.assemble(graph, options.grain);
  result.initial_cost = result.cost = cost;
  if (system.dim() == 0) return result;

  Eigen::SimplicialLDLT<SparseNormalEquations::SpMat, Eigen::Lower> solver;
  SparseNormalEquations::SpMat A;
  system.damped(options.initial_damping, options.min_diagonal, A);
  solver.analyzePattern(A);  // once: the pattern never changes

  double mu = options.initial_damping;
  double nu = 2.0;
  bool converged = false;
  std::vector<Isometry3d> trial;
  for (int it = 0; it < options.max_iterations && !converged; ++it) {
    ++result.iterations;
    system.damped(mu, options.min_diagonal, A);
    solver.factorize(A);
    bool usable = solver.info() == Eigen::Success && solver.vectorD().minCoeff() > 0.0;
    Eigen::VectorXd step;
    if (usable) {
      step = solver.solve(-system.g());
      usable = solver.info() == Eigen::Success && step.allFinite();
    }
    if (!usable) {
      mu *= nu;
      nu *= 2.0;
      if (!(mu < 1e30)) {
        result.status = SparseLmStatus::solver_failed;
        result.reason = "the damped normal equations could not be factorised";
        return result;
      }
      continue;
    }
    if (step.cwiseAbs().maxCoeff() < options.step_tolerance) {
      converged = true;
      break;
    }
    trial = graph.variables;
    for (std::size_t v = 0; v < trial.size(); ++v) {
      const int c = system.column(v);
      if (c >= 0) trial[v] = ulc::se3_exp(Vec6d(step.segment<6>(6 * c))) * trial[v];
    }
    // Predicted decrease of the Gauss-Newton model, 1/2 |e + J d|^2.
    const double predicted =
        -(system.g().dot(step) + 0.5 * step.dot(system.H().selfadjointView<Eigen::Lower>() * step));
    std::swap(graph.variables, trial);
    const double new_cost = graph.cost();
    const double actual = cost - new_cost;
    const double rho = predicted > 0.0 ? actual / predicted : -1.0;
    if (rho > 0.0 && std::isfinite(new_cost)) {
      ++result.accepted;
      mu *= std::max(1.0 / 3.0, 1.0 - std::pow(2.0 * rho - 1.0, 3));
      nu = 2.0;
      if (actual < options.cost_tolerance * cost) converged = true;
      cost = system.assemble(graph, options.grain);
    } else {
      std::swap(graph.variables, trial);  // back to the previous variables
      mu *= nu;
      nu *= 2.0;
    }
  }
  result.cost = cost;
  if (!converged && options.max_iterations > 0) {
    result.status = SparseLmStatus::not_converged;
    result.reason = "max_iterations reached before the step or the cost change was small";
  }
  return result;
}

/// The marginal covariance (6x6) of a free variable at the graph's current values: the
/// corresponding block of H^-1 (Gauss-Newton, no damping). Zero when H cannot be factorised or
/// the variable is fixed.
inline Mat6d marginal_covariance(const PoseGraph& graph, std::size_t variable,
                                 std::size_t grain = 256) {
  if (!graph.valid() || variable >= graph.variables.size() || graph.fixed[variable])
    return Mat6d::Zero();
  SparseNormalEquations system(graph);
  system.assemble(graph, grain);
  Eigen::SimplicialLDLT<SparseNormalEquations::SpMat, Eigen::Lower> solver(system.H());
  if (solver.info() != Eigen::Success) return Mat6d::Zero();
  Eigen::MatrixXd rhs = Eigen::MatrixXd::Zero(system.dim(), 6);
  const int c = system.column(variable);
  rhs.block<6, 6>(6 * c, 0).setIdentity();
  const Eigen::MatrixXd x = solver.solve(rhs);
  if (solver.info() != Eigen::Success || !x.allFinite()) return Mat6d::Zero();
  const Mat6d block = x.block<6, 6>(6 * c, 0);
  return 0.5 * (block + block.transpose());
}

}  // namespace hots
