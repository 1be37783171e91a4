#include "relight/surface_terms.h"

#include "bake/surface_light.h"

namespace daylit::relight {

SurfaceTerms::SurfaceTerms(const bake::SceneBake& bake, estimation::TransferPoints points, int width, int height,
                           bool wrap_u, const glm::vec3& capture_position, const scene::RayCaster& caster,
                           estimation::TransferOptions options)
    : points_(points), caster_(caster), transfer_(bake, points, capture_position, caster, options) {
  const auto index = [width](int u, int v) {
    return static_cast<uint32_t>(v) * static_cast<uint32_t>(width) + static_cast<uint32_t>(u);
  };
  std::vector<uint8_t> chosen(points.count, 0);
  for (int v = 0; v < height; ++v) {
    for (int u = 0; u < width; ++u) {
      const uint32_t t = index(u, v);
      if (points.surface[t] == bake::kNoSurface) continue;
      model_points_.push_back(t);
      // The nearest corner of its 4×4 block on the same surface, else the point itself.
      const int u0 = u - u % 4, v0 = v - v % 4;
      uint32_t rep = t;
      for (const glm::ivec2& c : {glm::ivec2(u0, v0), glm::ivec2(u0 + 4, v0), glm::ivec2(u0, v0 + 4), glm::ivec2(u0 + 4, v0 + 4)}) {
        if (c.y >= height || (!wrap_u && c.x >= width)) continue;
        const uint32_t ct = index(c.x % width, c.y);
        if (points.surface[ct] == points.surface[t]) {
          rep = ct;
          break;
        }
      }
      representative_.push_back(rep);
      if (!chosen[rep]) chosen[rep] = 1, traced_.push_back(rep);
    }
  }
  std::vector<uint32_t> slot(points.count, 0);
  for (size_t k = 0; k < traced_.size(); ++k) slot[traced_[k]] = static_cast<uint32_t>(k);
  for (uint32_t& rep : representative_) rep = slot[rep];
}

void SurfaceTerms::Compute(const glm::vec3& sun_dir, std::vector<estimation::Transfer>* terms) {
  // The direct sun at every model point.
  std::vector<float> direct(points_.count, 0.0f);
  bake::DirectSun(caster_, points_.point, points_.normal, model_points_, sun_dir, 2e-3f, direct.data());
  // Transfer of the representatives, then every point: its own direct terms, its
  // representative's reflected light (and, for the clear sky, its shape of what V lets through).
  std::vector<estimation::Transfer> total(traced_.size()), reflected(traced_.size());
  transfer_.Compute(traced_, sun_dir, direct.data(), total.data(), reflected.data());
  terms->resize(model_points_.size());
  for (size_t i = 0; i < model_points_.size(); ++i) {
    const size_t k = representative_[i];
    const uint32_t t = model_points_[i], rep = traced_[k];
    const estimation::Transfer& r = reflected[k];
    estimation::Transfer& out = (*terms)[i];
    if (rep == t) {
      out = total[k];
      continue;
    }
    const float v = points_.sky_visibility[t], v_rep = points_.sky_visibility[rep];
    const glm::vec3 clear_direct = total[k].clear - r.clear;
    out.sun = glm::vec3(direct[t]) + r.sun;
    out.overcast = glm::vec3(v) + r.overcast;
    out.clear = (v_rep > 0.01f ? clear_direct * (v / v_rep) : glm::vec3(v)) + r.clear;
  }
}

}  // namespace daylit::relight
