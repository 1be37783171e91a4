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
// reprojected (as the volume's gather tables do for each probe): a ray per direction, and the
// texel that shows where it meets the model from the capture point, or the sky layer's texel in
// its direction where it escapes (bake/parallax.h). The directions are fitted to the map seen from
// the objects' common centre; each object then gets its own lights' irradiances, fitted with those
// directions to the map seen from its own centre. So the real model's occlusion and reflection
// are in each object's lights, as from where it stands (an object behind a wall gets the wall's
// light in the wall's direction, one in the open the sky's), and only the objects shadow the
// lights. Shadowing a light by the real model instead was all or nothing: a light standing for a
// band of sky just over a wall, seen from the centre, went dark on an object whose own view of that
// band the wall blocked in part (courtyard-a's box under an overcast sky: 16% dark).
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

  // `n` lights (1..kMaxLights) for objects centred at `object_centres` (at least one), from maps
  // of `env_width` × `env_height` captured at `capture`; `model` is the scene's real model and
  // must outlive this.
  EnvLights(int n, const scene::RayCaster& model, const std::vector<glm::vec3>& object_centres, const glm::vec3& capture,
            int env_width, int env_height);

  // The sun moved: the maps of `basis` (stacked on their sky layer), seen from the objects' common
  // centre and from each object's, and their irradiance. The directions are fitted at the next
  // Update.
  void SetBasis(const relight::EnvBasis& basis);

  // This frame's lights under `parts`, one set per object (in the order of `object_centres`, the
  // same directions in each): each part's irradiances weighted by its light (clamped at 0), the
  // directions fitted again first when needed.
  const std::vector<LightSet>& Update(const estimation::LightParts& parts);

  int count() const { return n_; }
  // Bumped whenever the directions change (the shadow maps are then redrawn).
  int generation() const { return generation_; }
  // Of those fits, how many stopped on the iteration limit rather than converging.
  int unconverged_fits() const { return unconverged_fits_; }
  // The last Update's mean relative error against the map's exact irradiance (the fit's normals).
  double error() const { return error_; }

 private:
  // The maps as seen from one point, and the lights' irradiances there.
  struct View {
    glm::vec3 position{0.0f};
    std::vector<uint32_t> source;                   // per fit texel, 4 stacked-map indices (2×2 rays)
    std::array<HdrImage, 3> maps;                   // the parts' maps seen from `position`
    std::array<std::vector<glm::dvec3>, 3> truth;   // their exact irradiance at normals_
    std::array<LightSet, 3> parts;                  // per part: ambient and irradiances per unit of its light
  };
  View MakeView(const scene::RayCaster& model, const glm::vec3& position, const glm::vec3& capture, int env_width,
                int env_height) const;
  void FitDirections(const estimation::LightParts& parts);
  void FitIrradiances(const estimation::LightParts& parts, View* view) const;
  LightSet Combine(const View& view, const estimation::LightParts& parts) const;
  double ErrorOf(const LightSet& lights, const estimation::LightParts& parts) const;

  int n_;
  std::vector<glm::vec3> normals_;  // FitNormals(n)
  int env_size_ = 0;                // texels in the captured maps
  HdrImage layout_;                 // the fit's map size (rgb unused)
  View centre_;                     // the objects' common centre: the directions, and the error
  std::vector<View> objects_;       // each object's own centre
  bool stale_ = true;               // the basis changed since the directions were fitted
  double fit_error_ = 0.0;          // the error just after the last fit
  std::vector<glm::vec3> directions_;
  std::vector<LightSet> current_;   // per object
  double error_ = 0.0;
  int generation_ = 0;
  int unconverged_fits_ = 0;
};

}  // namespace daylit::lightfit
