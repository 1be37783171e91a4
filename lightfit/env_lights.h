// The objects' light as N directional lights plus an ambient term fitted to the relit environment
// map (seed 000's Irradiance Optimization; lightfit/light_fit.h), the alternative to the irradiance
// volume (daylit render/replay --lighting lights:N). The sun stays the sun; the lights stand for
// the sky and the light the courtyard reflects.
//
// The relit map is linear in E_sun, E_clear and E_overcast (relight::EnvBasis), and so are the lights once
// their directions are fixed. When the sun moves, the three maps' exact irradiance is taken at
// the fit's normals. The directions come from an Irradiance Optimization of the map under the
// light of the moment, and each part's irradiances from a linear least-squares fit with those
// directions (weighted as the optimisation is, by the relative error); a frame then combines
// them, Σ_k e_k·I_k, as the volume does. The combination's error against the map's irradiance
// (itself Σ_k e_k·E_k) is checked every frame at the same normals, which costs microseconds; when
// the light has changed so much that it is 3 points worse than just after the fit (a cloud), the
// directions are fitted again.
//
// The maps are seen from the capture point; the lights are for the objects, so the maps are
// first reprojected to the objects' centre (as the volume's gather tables do for each probe): a
// ray from there per direction, and the texel that shows where it meets the model from the
// capture point (the sky's texels straight).
//
// Each light casts shadows: a light whose direction, seen from the objects, meets the real model
// stands for light that model reflects, so only the objects shadow it (the wall it comes from
// must not block it); the others are shadowed by the real model and the objects alike.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "relight/env_relight.h"
#include "lightfit/lights.h"
#include "scene/hdr_image.h"
#include "scene/raycaster.h"

namespace daylit::lightfit {

class EnvLights {
 public:
  static constexpr int kMaxLights = 16;

  // `n` lights (1..kMaxLights) for the objects around `objects_centre`, from maps of
  // `env_width` × `env_height` captured at `capture`; `model` is the scene's real model and must
  // outlive this.
  EnvLights(int n, const scene::RayCaster& model, const glm::vec3& objects_centre, const glm::vec3& capture,
            int env_width, int env_height);

  // The sun moved: the maps of `basis`, seen from the objects' centre, and their irradiance. The
  // directions are fitted at the next Update.
  void SetBasis(const relight::EnvBasis& basis);

  // This frame's lights under `parts`: each part's irradiances weighted by its light (clamped at
  // 0), the directions fitted again first when needed.
  const LightSet& Update(const estimation::LightParts& parts);

  int count() const { return n_; }
  // Per light: 1 when it stands for light the real model reflects (only the objects shadow it).
  const std::vector<uint8_t>& reflected() const { return reflected_; }
  // Bumped whenever the directions change (the shadow maps are then redrawn).
  int generation() const { return generation_; }
  // Of those fits, how many stopped on the iteration limit rather than converging.
  int unconverged_fits() const { return unconverged_fits_; }
  // The last Update's mean relative error against the map's exact irradiance (the fit's normals).
  double error() const { return error_; }

 private:
  void FitDirections(const estimation::LightParts& parts);
  LightSet Combine(const estimation::LightParts& parts) const;
  double ErrorOf(const LightSet& lights, const estimation::LightParts& parts) const;

  int n_;
  const scene::RayCaster& model_;
  glm::vec3 objects_centre_;
  std::vector<glm::vec3> normals_;            // FitNormals(n)
  int env_size_ = 0;                          // texels in the captured maps
  HdrImage layout_;                    // the fit's map size (rgb unused)
  std::vector<uint32_t> source_;              // per fit texel, 4 captured texels (2×2 rays)
  std::array<HdrImage, 3> maps_;       // the parts' maps seen from the objects' centre
  std::array<std::vector<glm::dvec3>, 3> part_truth_;  // their exact irradiance at normals_
  bool stale_ = true;                         // the basis changed since the directions were fitted
  double fit_error_ = 0.0;                    // the error just after the last fit
  std::vector<glm::vec3> directions_;
  std::vector<uint8_t> reflected_;
  // Per part (sun, clear, overcast): the ambient and the lights' irradiance per unit of its light.
  std::array<LightSet, 3> parts_;
  LightSet current_;
  double error_ = 0.0;
  int generation_ = 0;
  int unconverged_fits_ = 0;
};

}  // namespace daylit::lightfit
