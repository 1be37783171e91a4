#include "lightfit/light_fit.h"

#include "base/options_check.h"

#include <algorithm>
#include <cmath>
#include <memory>

#include <ceres/ceres.h>
#include <fmt/format.h>

#include "base/check.h"
#include "bake/sampling.h"
#include "base/error.h"
#include "sh/exact_irradiance.h"

namespace daylit::lightfit {
namespace {

constexpr int kChunk = 256;  // normals per residual block: few blocks, so little Ceres overhead

// Light i's direction from its two angles (a, b) in the frame (t1, t2, d0) around its initial
// direction d0: d = cos b (cos a d0 + sin a t1) + sin b t2, with ∂d/∂a and ∂d/∂b.
struct AngleFrame {
  glm::dvec3 d0, t1, t2;

  explicit AngleFrame(const glm::vec3& initial) {
    const glm::mat3 basis = bake::BasisAround(glm::normalize(initial));
    t1 = glm::dvec3(basis[0]), t2 = glm::dvec3(basis[1]), d0 = glm::dvec3(basis[2]);
  }
  void Direction(double a, double b, glm::dvec3* d, glm::dvec3* dd_da, glm::dvec3* dd_db) const {
    const glm::dvec3 in_plane = std::cos(a) * d0 + std::sin(a) * t1;
    *d = std::cos(b) * in_plane + std::sin(b) * t2;
    *dd_da = std::cos(b) * (-std::sin(a) * d0 + std::cos(a) * t1);
    *dd_db = -std::sin(b) * in_plane + std::cos(b) * t2;
  }
};

struct Target {
  glm::dvec3 normal;
  glm::dvec3 inverse_truth;  // the weights that make residuals relative
};

// Residuals r_k = (ambient_k + Σ_i c_ik max(0, n·d_i)) / E_k − 1 for a span of normals.
// parameters[0]: ambient (3); parameters[1 + 2i]: light i's irradiance (3); [2 + 2i]: angles (2).
// `jacobians`, when given, are the per-block row-major 3·count × size matrices Ceres expects.
void EvaluateChunk(const std::vector<AngleFrame>& frames, const Target* targets, int count, double const* const* parameters,
              double* residuals, double** jacobians) {
  const size_t n_lights = frames.size();
  std::vector<glm::dvec3> d(n_lights), dd_da(n_lights), dd_db(n_lights);
  for (size_t i = 0; i < n_lights; ++i) {
    frames[i].Direction(parameters[2 + 2 * i][0], parameters[2 + 2 * i][1], &d[i], &dd_da[i], &dd_db[i]);
  }
  const glm::dvec3 ambient(parameters[0][0], parameters[0][1], parameters[0][2]);
  if (jacobians != nullptr) {
    for (size_t b = 0; b < 1 + 2 * n_lights; ++b) {
      if (jacobians[b] == nullptr) continue;
      const int size = b == 0 || b % 2 == 1 ? 3 : 2;
      std::fill_n(jacobians[b], static_cast<size_t>(3 * count * size), 0.0);
    }
  }
  for (int j = 0; j < count; ++j) {
    const Target& t = targets[j];
    glm::dvec3 e = ambient;
    for (size_t i = 0; i < n_lights; ++i) {
      const double cosine = glm::dot(t.normal, d[i]);
      if (cosine <= 0.0) continue;
      const double* c = parameters[1 + 2 * i];
      e += cosine * glm::dvec3(c[0], c[1], c[2]);
      if (jacobians == nullptr) continue;
      const double da = glm::dot(t.normal, dd_da[i]), db = glm::dot(t.normal, dd_db[i]);
      for (int k = 0; k < 3; ++k) {
        const int row = 3 * j + k;
        if (jacobians[1 + 2 * i] != nullptr) jacobians[1 + 2 * i][row * 3 + k] = t.inverse_truth[k] * cosine;
        if (jacobians[2 + 2 * i] != nullptr) {
          jacobians[2 + 2 * i][row * 2 + 0] = t.inverse_truth[k] * c[k] * da;
          jacobians[2 + 2 * i][row * 2 + 1] = t.inverse_truth[k] * c[k] * db;
        }
      }
    }
    for (int k = 0; k < 3; ++k) {
      residuals[3 * j + k] = e[k] * t.inverse_truth[k] - 1.0;
      if (jacobians != nullptr && jacobians[0] != nullptr) jacobians[0][(3 * j + k) * 3 + k] = t.inverse_truth[k];
    }
  }
}

class ChunkCost final : public ceres::CostFunction {
 public:
  ChunkCost(const std::vector<AngleFrame>* frames, const Target* targets, int count)
      : frames_(frames), targets_(targets), count_(count) {
    set_num_residuals(3 * count);
    mutable_parameter_block_sizes()->push_back(3);
    for (size_t i = 0; i < frames->size(); ++i) {
      mutable_parameter_block_sizes()->push_back(3);
      mutable_parameter_block_sizes()->push_back(2);
    }
  }
  bool Evaluate(double const* const* parameters, double* residuals, double** jacobians) const override {
    EvaluateChunk(*frames_, targets_, count_, parameters, residuals, jacobians);
    return true;
  }

 private:
  const std::vector<AngleFrame>* frames_;
  const Target* targets_;
  int count_;
};

// Stops the solver, successfully, once `window` iterations have lowered the cost by less than
// `fraction` of it.
class StallCallback final : public ceres::IterationCallback {
 public:
  StallCallback(int window, double fraction) : window_(window), fraction_(fraction) {}
  ceres::CallbackReturnType operator()(const ceres::IterationSummary& summary) override {
    costs_.push_back(summary.cost);
    if (window_ <= 0 || costs_.size() <= static_cast<size_t>(window_)) return ceres::SOLVER_CONTINUE;
    const double before = costs_[costs_.size() - 1 - window_];
    return before - summary.cost < fraction_ * before ? ceres::SOLVER_TERMINATE_SUCCESSFULLY : ceres::SOLVER_CONTINUE;
  }

 private:
  int window_;
  double fraction_;
  std::vector<double> costs_;
};

std::vector<Target> TargetsOf(const std::vector<glm::vec3>& normals, const std::vector<glm::dvec3>& truth) {
  DAYLIT_CHECK(normals.size() == truth.size(), "{} normals but {} true irradiances", normals.size(), truth.size());
  glm::dvec3 peak(0.0);
  for (const glm::dvec3& e : truth) peak = glm::max(peak, e);
  std::vector<Target> targets;
  for (size_t i = 0; i < normals.size(); ++i) {
    if (!glm::all(glm::greaterThanEqual(truth[i], 1e-3 * peak)) || !glm::all(glm::greaterThan(truth[i], glm::dvec3(0.0)))) continue;
    targets.push_back({glm::dvec3(normals[i]), 1.0 / truth[i]});
  }
  return targets;
}

}  // namespace

void LightFitResidual(const LightSet& initial, const glm::vec3& normal, const glm::dvec3& truth,
                      const std::vector<double>& parameters, double residuals[3], std::vector<double>* jacobian) {
  std::vector<AngleFrame> frames;
  for (const DirectionalLight& l : initial.lights) frames.emplace_back(l.direction);
  const size_t blocks = 1 + 2 * frames.size();
  std::vector<const double*> p(blocks);
  std::vector<std::vector<double>> j(blocks);
  std::vector<double*> jp(blocks);
  size_t offset = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const size_t size = b == 0 || b % 2 == 1 ? 3 : 2;
    p[b] = parameters.data() + offset;
    j[b].resize(3 * size);
    jp[b] = j[b].data();
    offset += size;
  }
  const Target target{glm::dvec3(normal), 1.0 / truth};
  EvaluateChunk(frames, &target, 1, p.data(), residuals, jacobian != nullptr ? jp.data() : nullptr);
  if (jacobian == nullptr) return;
  jacobian->assign(3 * offset, 0.0);
  size_t column = 0;
  for (size_t b = 0; b < blocks; ++b) {
    const size_t size = j[b].size() / 3;
    for (size_t row = 0; row < 3; ++row) {
      for (size_t c = 0; c < size; ++c) (*jacobian)[row * offset + column + c] = j[b][row * size + c];
    }
    column += size;
  }
}

LightFitResult FitLights(const std::vector<glm::vec3>& normals, const std::vector<glm::dvec3>& truth,
                         const LightSet& initial, const LightFitOptions& options) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  const std::vector<Target> targets = TargetsOf(normals, truth);
  std::vector<AngleFrame> frames;
  for (const DirectionalLight& l : initial.lights) frames.emplace_back(l.direction);
  std::vector<double> ambient = {initial.ambient.x, initial.ambient.y, initial.ambient.z};
  std::vector<std::array<double, 3>> irradiance;
  std::vector<std::array<double, 2>> angles(initial.lights.size(), {0.0, 0.0});
  for (const DirectionalLight& l : initial.lights) irradiance.push_back({l.irradiance.x, l.irradiance.y, l.irradiance.z});

  ceres::Problem::Options problem_options;
  problem_options.cost_function_ownership = ceres::TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  std::vector<double*> blocks = {ambient.data()};
  for (size_t i = 0; i < frames.size(); ++i) blocks.push_back(irradiance[i].data()), blocks.push_back(angles[i].data());
  for (size_t begin = 0; begin < targets.size(); begin += kChunk) {
    const int count = static_cast<int>(std::min<size_t>(kChunk, targets.size() - begin));
    problem.AddResidualBlock(new ChunkCost(&frames, targets.data() + begin, count), nullptr, blocks);
  }
  LightFitResult result;
  result.lights = initial;
  if (targets.empty()) {
    result.termination = "no normals with irradiance to fit";
    return result;
  }
  for (int k = 0; k < 3; ++k) problem.SetParameterLowerBound(ambient.data(), k, 0.0);
  if (!options.ambient) problem.SetParameterBlockConstant(ambient.data());
  for (auto& c : irradiance) {
    for (int k = 0; k < 3; ++k) problem.SetParameterLowerBound(c.data(), k, 0.0);
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::DENSE_NORMAL_CHOLESKY;
  solver.max_num_iterations = options.max_iterations;
  solver.function_tolerance = options.function_tolerance;
  solver.num_threads = std::max(1, options.threads);
  solver.logging_type = ceres::SILENT;
  StallCallback stall(options.stall_window, options.stall_fraction);
  solver.callbacks.push_back(&stall);
  ceres::Solver::Summary summary;
  ceres::Solve(solver, &problem, &summary);

  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.converged = summary.termination_type == ceres::CONVERGENCE || summary.termination_type == ceres::USER_SUCCESS;
  result.initial_cost = summary.initial_cost;
  result.final_cost = summary.final_cost;
  result.termination = summary.termination_type == ceres::USER_SUCCESS
                           ? fmt::format("the cost fell by less than {}% over {} iterations", 100 * options.stall_fraction,
                                         options.stall_window)
                           : summary.message;
  result.lights.ambient = glm::vec3(ambient[0], ambient[1], ambient[2]);
  for (size_t i = 0; i < frames.size(); ++i) {
    glm::dvec3 d, da, db;
    frames[i].Direction(angles[i][0], angles[i][1], &d, &da, &db);
    result.lights.lights[i] = {glm::vec3(glm::normalize(d)), glm::vec3(irradiance[i][0], irradiance[i][1], irradiance[i][2])};
  }
  return result;
}

std::vector<glm::vec3> FitNormals(int n) {
  int level = 3;
  while (3 * 20 * (1 << (2 * level)) < 20 * (3 + 5 * n) && level < 5) ++level;
  return sh::IcosahedronNormals(level);
}

LightFitResult IrradianceOptimization(const HdrImage& map, int n, const LightFitOptions& options) {
  const std::vector<glm::vec3> normals = FitNormals(n);
  const std::vector<glm::dvec3> truth = sh::ExactIrradiance(map, normals);
  LightSet initial = MedianCutLights(map, n);
  // Median cut's lights carry the whole power of their regions, which overshoots where the
  // regions are wide. Start the ambient at what the lights leave unexplained everywhere.
  glm::dvec3 unexplained(1e300);
  for (size_t i = 0; i < normals.size(); ++i) unexplained = glm::min(unexplained, truth[i] - initial.Irradiance(normals[i]));
  if (options.ambient) initial.ambient = glm::vec3(glm::max(unexplained, glm::dvec3(0.0)));
  return FitLights(normals, truth, initial, options);
}

std::string LightFitOptions::Check() const {
  return FirstProblem({InClosed("max_iterations", max_iterations, 1, 100000),
                       InOpenClosed("function_tolerance", function_tolerance, 0.0, 1.0),
                       InClosed("stall_window", stall_window, 1, 100000), InClosed("stall_fraction", stall_fraction, 0.0, 1.0),
                       InClosed("threads", threads, 1, 256)});
}

}  // namespace daylit::lightfit
