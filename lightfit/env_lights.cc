#include "lightfit/env_lights.h"

#include <algorithm>

#include <Eigen/Dense>

#include "base/check.h"
#include "base/log.h"
#include "base/error.h"
#include "sh/exact_irradiance.h"
#include "lightfit/light_fit.h"
#include "base/latlong.h"
#include "bake/parallax.h"

namespace daylit::lightfit {
namespace {

// The fit's maps: this wide at most (irradiance is smooth, and the exact sums are cheaper).
constexpr int kFitWidth = 256;
// Directions are fitted again when the combination is this much worse than just after the fit.
constexpr double kRefitWorsening = 0.03;

}  // namespace

EnvLights::EnvLights(int n, const scene::RayCaster& model, const std::vector<glm::vec3>& object_centres,
                     const glm::vec3& capture, int env_width, int env_height)
    : n_(n) {
  DAYLIT_CHECK(n >= 1 && n <= kMaxLights, "{} lights; 1 to {} (render::ParseLighting checks the option)", n, kMaxLights);
  DAYLIT_CHECK(!object_centres.empty(), "lights for no object");
  normals_ = FitNormals(n);
  env_size_ = env_width * env_height;
  const int width = std::min(env_width, kFitWidth), height = std::max(1, width / 2);
  layout_ = HdrImage{width, height, {}};
  glm::vec3 lo(object_centres[0]), hi(object_centres[0]);
  for (const glm::vec3& c : object_centres) lo = glm::min(lo, c), hi = glm::max(hi, c);
  centre_ = MakeView(model, 0.5f * (lo + hi), capture, env_width, env_height);
  for (const glm::vec3& c : object_centres) objects_.push_back(MakeView(model, c, capture, env_width, env_height));
}

EnvLights::View EnvLights::MakeView(const scene::RayCaster& model, const glm::vec3& position, const glm::vec3& capture,
                                    int env_width, int env_height) const {
  // 2×2 rays per fit texel from `position`; each reads what it meets (bake/parallax.h).
  View view;
  view.position = position;
  std::vector<glm::vec3> origins, dirs;
  for (int v = 0; v < layout_.height; ++v) {
    for (int u = 0; u < layout_.width; ++u) {
      for (int s = 0; s < 4; ++s) {
        const glm::dvec3 d = LatLongDirection(u - 0.25 + 0.5 * (s & 1), v - 0.25 + 0.5 * (s >> 1), layout_.width, layout_.height);
        origins.push_back(position), dirs.push_back(glm::normalize(glm::vec3(d)));
      }
    }
  }
  std::vector<scene::RayHit> hits(dirs.size());
  model.IntersectMany(origins.data(), dirs.data(), dirs.size(), 1e-3f, hits.data());
  view.source.resize(dirs.size());
  for (size_t r = 0; r < dirs.size(); ++r) view.source[r] = bake::ParallaxTexel(position, dirs[r], hits[r], capture, env_width, env_height);
  return view;
}

void EnvLights::SetBasis(const relight::EnvBasis& basis) {
  const std::vector<glm::vec3>* maps[3] = {&basis.sun, &basis.clear, &basis.overcast};
  const size_t texels = static_cast<size_t>(layout_.width) * layout_.height;
  for (size_t k = 0; k < 3; ++k) {
    DAYLIT_CHECK(maps[k]->size() == 2 * static_cast<size_t>(env_size_), "a stacked basis of {} values for {} texels",
                 maps[k]->size(), env_size_);
  }
  const auto reproject = [&](View* view) {
    for (size_t k = 0; k < 3; ++k) {
      view->maps[k] = HdrImage{layout_.width, layout_.height, std::vector<float>(texels * 3, 0.0f)};
      for (size_t t = 0; t < texels; ++t) {
        glm::vec3 sum(0.0f);
        for (size_t s = 0; s < 4; ++s) sum += glm::max((*maps[k])[view->source[4 * t + s]], glm::vec3(0.0f));
        for (int c = 0; c < 3; ++c) view->maps[k].rgb[3 * t + c] = 0.25f * sum[c];
      }
      view->truth[k] = sh::ExactIrradiance(view->maps[k], normals_);
    }
  };
  reproject(&centre_);
  for (View& view : objects_) reproject(&view);
  stale_ = true;
}

void EnvLights::FitDirections(const estimation::LightParts& parts) {
  // Irradiance Optimization of the map under this light (all parts alike when there is none).
  std::array<glm::vec3, 3> e = {parts.sun, parts.clear, parts.overcast};
  if (glm::length(e[0]) + glm::length(e[1]) + glm::length(e[2]) <= 0.0f) e.fill(glm::vec3(1.0f));
  HdrImage mixture{layout_.width, layout_.height, std::vector<float>(centre_.maps[0].rgb.size(), 0.0f)};
  for (size_t k = 0; k < 3; ++k) {
    for (size_t i = 0; i < mixture.rgb.size(); ++i) mixture.rgb[i] += e[k][static_cast<int>(i % 3)] * centre_.maps[k].rgb[i];
  }
  const LightFitResult fit = IrradianceOptimization(mixture, n_);
  if (!fit.converged) {
    // The directions are still usable (the fit's cost only falls), but the user should know.
    ++unconverged_fits_;
    Log().debug("lights:{}: the directions' fit stopped at its iteration limit ({})", n_, fit.termination);
  }
  directions_.clear();
  for (const DirectionalLight& l : fit.lights.lights) directions_.push_back(glm::normalize(l.direction));
  FitIrradiances(parts, &centre_);
  for (View& view : objects_) FitIrradiances(parts, &view);
  current_.clear();
  for (const View& view : objects_) current_.push_back(Combine(view, parts));
  error_ = fit_error_ = ErrorOf(Combine(centre_, parts), parts);
  stale_ = false;
  ++generation_;
}

void EnvLights::FitIrradiances(const estimation::LightParts& parts, View* view) const {
  // Each part's irradiances with the directions: min Σ_j ((A x − E_k)_j / E_j)² per channel, E
  // the view's map under `parts`, as the optimisation weighs its residuals.
  std::array<glm::vec3, 3> e = {parts.sun, parts.clear, parts.overcast};
  if (glm::length(e[0]) + glm::length(e[1]) + glm::length(e[2]) <= 0.0f) e.fill(glm::vec3(1.0f));
  std::vector<glm::dvec3> truth(normals_.size(), glm::dvec3(0.0));
  for (size_t k = 0; k < 3; ++k) {
    for (size_t j = 0; j < normals_.size(); ++j) truth[j] += glm::dvec3(e[k]) * view->truth[k][j];
  }
  const int m = static_cast<int>(normals_.size()), unknowns = 1 + static_cast<int>(directions_.size());
  Eigen::MatrixXd design(m, unknowns);
  for (int j = 0; j < m; ++j) {
    design(j, 0) = 1.0;
    for (size_t i = 0; i < directions_.size(); ++i) design(j, 1 + i) = std::max(0.0f, glm::dot(normals_[j], directions_[i]));
  }
  for (LightSet& part : view->parts) {
    part.ambient = glm::vec3(0.0f);
    part.lights.assign(directions_.size(), DirectionalLight{});
    for (size_t i = 0; i < directions_.size(); ++i) part.lights[i].direction = directions_[i];
  }
  for (int c = 0; c < 3; ++c) {
    double top = 0.0;
    for (const glm::dvec3& t : truth) top = std::max(top, t[c]);
    // Normals the map barely lights weigh as if lit at 1e-3 of the brightest.
    Eigen::VectorXd weight(m);
    for (int j = 0; j < m; ++j) weight(j) = 1.0 / std::max(truth[j][c], std::max(1e-3 * top, 1e-12));
    const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(weight.asDiagonal() * design);
    for (size_t k = 0; k < 3; ++k) {
      Eigen::VectorXd rhs(m);
      for (int j = 0; j < m; ++j) rhs(j) = weight(j) * view->truth[k][j][c];
      const Eigen::VectorXd x = qr.solve(rhs);
      view->parts[k].ambient[c] = static_cast<float>(x(0));
      for (size_t i = 0; i < directions_.size(); ++i) view->parts[k].lights[i].irradiance[c] = static_cast<float>(x(1 + i));
    }
  }
}

LightSet EnvLights::Combine(const View& view, const estimation::LightParts& parts) const {
  LightSet set;
  set.lights.resize(directions_.size());
  const glm::vec3 e[3] = {parts.sun, parts.clear, parts.overcast};
  for (size_t k = 0; k < 3; ++k) set.ambient += e[k] * view.parts[k].ambient;
  set.ambient = glm::max(set.ambient, glm::vec3(0.0f));
  for (size_t i = 0; i < directions_.size(); ++i) {
    set.lights[i].direction = directions_[i];
    for (size_t k = 0; k < 3; ++k) set.lights[i].irradiance += e[k] * view.parts[k].lights[i].irradiance;
    set.lights[i].irradiance = glm::max(set.lights[i].irradiance, glm::vec3(0.0f));
  }
  return set;
}

double EnvLights::ErrorOf(const LightSet& lights, const estimation::LightParts& parts) const {
  std::vector<glm::dvec3> truth(normals_.size(), glm::dvec3(0.0));
  const glm::dvec3 e[3] = {glm::dvec3(parts.sun), glm::dvec3(parts.clear), glm::dvec3(parts.overcast)};
  for (size_t k = 0; k < 3; ++k) {
    for (size_t j = 0; j < normals_.size(); ++j) truth[j] += e[k] * centre_.truth[k][j];
  }
  return RelativeError(truth, lights.Irradiance(normals_)).mean;
}

const std::vector<LightSet>& EnvLights::Update(const estimation::LightParts& parts) {
  if (!stale_) {
    error_ = ErrorOf(Combine(centre_, parts), parts);
    if (error_ <= fit_error_ + kRefitWorsening) {
      for (size_t o = 0; o < objects_.size(); ++o) current_[o] = Combine(objects_[o], parts);
      return current_;
    }
  }
  FitDirections(parts);  // a new basis, or drifted too far: current_ and error_ from a new fit
  return current_;
}

}  // namespace daylit::lightfit
