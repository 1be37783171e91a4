#include "sh/irradiance_volume.h"

#include "base/check.h"
#include "base/error.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Core>
#include <glm/gtc/constants.hpp>

#include "sh/sh9.h"

namespace daylit::sh {
namespace {

constexpr int kCoefficients = 9;


}  // namespace

IrradianceVolume::IrradianceVolume(const sh::GatherTables& gather, std::vector<uint8_t> inside)
    : gather_(gather), inside_(std::move(inside)) {
  const size_t dirs = gather.directions.size();
  inside_.resize(gather.ProbeCount(), 0);
  basis_.resize(kCoefficients * dirs);
  const double weight = 4.0 * glm::pi<double>() / static_cast<double>(dirs);
  for (size_t d = 0; d < dirs; ++d) {
    const Sh9Basis y = EvalSh9(glm::dvec3(gather.directions[d]));
    for (int c = 0; c < kCoefficients; ++c) {
      basis_[static_cast<size_t>(c) * dirs + d] = static_cast<float>(kCosineLobe[static_cast<size_t>(c)] * y[static_cast<size_t>(c)] * weight);
    }
  }
  coefficients_.assign(gather.ProbeCount() * kCoefficients * 3, 0.0f);
  gathered_.resize(3 * dirs);
}

size_t IrradianceVolume::InsideCount() const {
  return static_cast<size_t>(std::count(inside_.begin(), inside_.end(), 1));
}

void IrradianceVolume::Update(const std::vector<glm::vec3>& stacked_radiance) {
  DAYLIT_CHECK(stacked_radiance.size() == 2 * gather_.map_texels, "a stacked map of {} values for an env map of {} texels",
               stacked_radiance.size(), gather_.map_texels);
  const size_t dirs = gather_.directions.size();
  const size_t probes = gather_.ProbeCount();
  // Per probe: gather its radiances into one array per channel, then 27 dot products of length
  // N with the basis rows (vectorised by Eigen).
  const Eigen::Index length = static_cast<Eigen::Index>(dirs);
  float* r = gathered_.data();
  float* g = r + dirs;
  float* b = g + dirs;
  const Eigen::Map<const Eigen::VectorXf> red(r, length), green(g, length), blue(b, length);
  for (size_t p = 0; p < probes; ++p) {
    const uint32_t* texel = &gather_.texel[p * dirs];
    for (size_t d = 0; d < dirs; ++d) {
      const glm::vec3& l = stacked_radiance[texel[d]];
      r[d] = l.x, g[d] = l.y, b[d] = l.z;
    }
    float* out = &coefficients_[p * kCoefficients * 3];
    for (int c = 0; c < kCoefficients; ++c) {
      const Eigen::Map<const Eigen::VectorXf> y(&basis_[static_cast<size_t>(c) * dirs], length);
      out[3 * c + 0] = y.dot(red), out[3 * c + 1] = y.dot(green), out[3 * c + 2] = y.dot(blue);
    }
  }
  if (InsideCount() == 0) return;
  // Probes inside the model: the mean of their valid neighbours (6-connected), repeated outward
  // until every inside probe with a valid probe anywhere has a value.
  const glm::ivec3 n = gather_.resolution;
  std::vector<uint8_t> valid(probes);
  for (size_t p = 0; p < probes; ++p) valid[p] = inside_[p] ? 0 : 1;
  const auto index = [&](int i, int j, int k) { return (static_cast<size_t>(k) * n.y + j) * n.x + i; };
  for (bool changed = true; changed;) {
    changed = false;
    std::vector<uint8_t> next = valid;
    for (int k = 0; k < n.z; ++k) {
      for (int j = 0; j < n.y; ++j) {
        for (int i = 0; i < n.x; ++i) {
          const size_t p = index(i, j, k);
          if (valid[p]) continue;
          std::array<float, kCoefficients * 3> sum{};
          int count = 0;
          for (const glm::ivec3& o : {glm::ivec3(-1, 0, 0), glm::ivec3(1, 0, 0), glm::ivec3(0, -1, 0),
                                      glm::ivec3(0, 1, 0), glm::ivec3(0, 0, -1), glm::ivec3(0, 0, 1)}) {
            const glm::ivec3 q = glm::ivec3(i, j, k) + o;
            if (glm::any(glm::lessThan(q, glm::ivec3(0))) || glm::any(glm::greaterThanEqual(q, n))) continue;
            const size_t qi = index(q.x, q.y, q.z);
            if (!valid[qi]) continue;
            for (size_t v = 0; v < sum.size(); ++v) sum[v] += coefficients_[qi * sum.size() + v];
            ++count;
          }
          if (count == 0) continue;
          for (size_t v = 0; v < sum.size(); ++v) coefficients_[p * sum.size() + v] = sum[v] / static_cast<float>(count);
          next[p] = 1;
          changed = true;
        }
      }
    }
    valid.swap(next);
  }
}

glm::vec3 IrradianceVolume::Evaluate(size_t probe, const Sh9Basis& y) const {
  glm::vec3 e(0.0f);
  for (int c = 0; c < kCoefficients; ++c) {
    const float* v = &coefficients_[(probe * kCoefficients + static_cast<size_t>(c)) * 3];
    e += static_cast<float>(y[static_cast<size_t>(c)]) * glm::vec3(v[0], v[1], v[2]);
  }
  return e;
}

glm::vec3 IrradianceVolume::ProbeIrradiance(int i, int j, int k, const glm::vec3& normal) const {
  const glm::ivec3 n = gather_.resolution;
  const size_t p = (static_cast<size_t>(k) * n.y + j) * n.x + i;
  return glm::max(Evaluate(p, EvalSh9(glm::dvec3(normal))), glm::vec3(0.0f));
}

void IrradianceVolume::SetCombination(const std::array<const std::vector<float>*, 3>& parts,
                                      const std::array<glm::vec3, 3>& weights) {
  for (const std::vector<float>* part : parts) {
    DAYLIT_CHECK(part->size() == coefficients_.size(), "{} coefficients for a volume of {}", part->size(), coefficients_.size());
  }
  for (size_t i = 0; i < coefficients_.size(); i += 3) {
    for (int k = 0; k < 3; ++k) {
      const size_t j = i + static_cast<size_t>(k);
      coefficients_[j] = weights[0][k] * (*parts[0])[j] + weights[1][k] * (*parts[1])[j] + weights[2][k] * (*parts[2])[j];
    }
  }
}

glm::vec3 IrradianceVolume::Irradiance(const glm::vec3& point, const glm::vec3& normal) const {
  return glm::max(Integrate(point, EvalSh9(glm::dvec3(normal))), glm::vec3(0.0f));
}

void TrilinearCorners(const glm::vec3& min, const glm::vec3& max, const glm::ivec3& n, const glm::vec3& point,
                      std::array<size_t, 8>* indices, std::array<float, 8>* weights) {
  // Continuous grid coordinates, clamped into the grid.
  glm::vec3 g;
  for (int a = 0; a < 3; ++a) {
    g[a] = n[a] <= 1 ? 0.0f : std::clamp((point[a] - min[a]) / (max[a] - min[a]), 0.0f, 1.0f) * static_cast<float>(n[a] - 1);
  }
  const glm::ivec3 i0 = glm::min(glm::ivec3(g), glm::max(n - 2, glm::ivec3(0)));
  const glm::vec3 f = g - glm::vec3(i0);
  for (int corner = 0; corner < 8; ++corner) {
    const glm::ivec3 o((corner & 1) != 0, (corner & 2) != 0, (corner & 4) != 0);
    const glm::ivec3 q = glm::min(i0 + o, n - 1);
    float w = 1.0f;
    for (int a = 0; a < 3; ++a) w *= o[a] ? f[a] : 1.0f - f[a];
    (*indices)[static_cast<size_t>(corner)] = (static_cast<size_t>(q.z) * n.y + q.y) * n.x + q.x;
    (*weights)[static_cast<size_t>(corner)] = w;
  }
}

std::array<float, 27> Sh9Snapshot::At(const glm::vec3& point) const {
  std::array<float, 27> out{};
  if (coefficients.empty()) return out;
  std::array<size_t, 8> probes;
  std::array<float, 8> weights;
  TrilinearCorners(min, max, resolution, point, &probes, &weights);
  for (size_t corner = 0; corner < 8; ++corner) {
    if (weights[corner] == 0.0f) continue;
    const float* c = &coefficients[probes[corner] * 27];
    for (size_t k = 0; k < 27; ++k) out[k] += weights[corner] * c[k];
  }
  return out;
}

void IrradianceVolume::Snapshot(Sh9Snapshot* out) const {
  out->min = gather_.min, out->max = gather_.max, out->resolution = gather_.resolution;
  out->coefficients.assign(coefficients_.begin(), coefficients_.end());
}

void IrradianceVolume::Corners(const glm::vec3& point, std::array<size_t, 8>* probes, std::array<float, 8>* weights) const {
  TrilinearCorners(gather_.min, gather_.max, gather_.resolution, point, probes, weights);
}

glm::vec3 IrradianceVolume::Integrate(const glm::vec3& point, const Sh9Basis& y) const {
  std::array<size_t, 8> probes;
  std::array<float, 8> weights;
  Corners(point, &probes, &weights);
  glm::vec3 e(0.0f);
  for (size_t corner = 0; corner < 8; ++corner) {
    if (weights[corner] != 0.0f) e += weights[corner] * Evaluate(probes[corner], y);
  }
  return e;
}


}  // namespace daylit::sh
