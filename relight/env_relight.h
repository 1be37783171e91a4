// The environment map of the scene as it looks now (seed 001's online stage after estimation):
// every texel re-evaluated with the current sun direction and the estimated E_sun, E_sky and
// overcast share, by the model the estimation fits (estimation/transfer.h):
//
//   model texels  L = ρ/π · (E_sun·T_sun + E_sky·((1 − o)·T_clear + o·T_overcast))
//   sky texels    L = E_sky · ((1 − o)·L_clear(ω)/DHI + o/π)
//
// with ρ the bake's albedo, o the overcast share and L_clear/DHI the captured sky's shape under
// the current sun (not a flat colour). The sun itself is not in the map: the renderer draws it
// as a directional light.
//
// When the sun moves, the model texels' terms are recomputed (relight/surface_terms.h).
#pragma once

#include <filesystem>
#include <optional>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "estimation/lighting_model.h"
#include "estimation/transfer.h"
#include "relight/surface_terms.h"
#include "scene/hdr_image.h"
#include "scene/raycaster.h"

namespace daylit::relight {

// The relit map per unit of each light, per channel, stacked on its sky layer (2·W·H values: the
// map's texels, then the sky's radiance in each texel's direction; bake/parallax.h):
// RelightWithSky gives E_sun·sun + (1 − o)·E_sky·clear + o·E_sky·overcast, value by value.
struct EnvBasis {
  std::vector<glm::vec3> sun, clear, overcast;
};

// The weights of EnvBasis's maps: estimation::LightParts (lighting_model.h), the one radiometric type.
using estimation::LightParts;
using estimation::SplitLight;

class EnvRelighter {
 public:
  // `bake`, `caster` must outlive this.
  EnvRelighter(const bake::SceneBake& bake, const glm::vec3& capture_position, const scene::RayCaster& caster,
               estimation::TransferOptions options = {});

  // Recomputes the per-texel terms for the unit sun `sun_dir` (scene coordinates) when it is not
  // the direction they were last made for (a new one only when the sun has moved:
  // scene::SunTracker's one rule). Returns true if it did.
  bool SetSun(const glm::vec3& sun_dir);

  // The relit radiance of every texel (row-major, like the map): `light` the estimated E_sun
  // and E_sky, `overcast_share` the share of E_sky from a uniform overcast sky.
  void Relight(const estimation::SunSky& light, double overcast_share, std::vector<glm::vec3>* radiance) const;

  // The same followed by the sky layer: 2·W·H values, what parallax lookups read
  // (bake/parallax.h): the sky alone in each texel's direction, also where the map shows the model.
  void RelightWithSky(const estimation::SunSky& light, double overcast_share, std::vector<glm::vec3>* stacked) const;

  // The three stacked maps RelightWithSky combines, for the current sun.
  void Basis(EnvBasis* basis) const;

  int width() const { return bake_.env.width; }
  int height() const { return bake_.env.height; }

 private:
  const bake::SceneBake& bake_;
  SurfaceTerms surface_;
  std::optional<glm::vec3> sun_;
  std::vector<glm::vec3> texel_dirs_;  // every texel's direction
  // Per model texel (in surface_.model_points() order): the terms.
  std::vector<estimation::Transfer> terms_;
  // Per texel: the clear sky's radiance per unit DHI in its direction (the sky layer's shape; the
  // map's own where it shows sky).
  std::vector<glm::vec3> sky_shape_;
};

// A relit map against a true one (same size): the mean relative error over the texels of model
// surfaces, |L − L_true| / L_true averaged over RGB (texels whose true luminance is below 1e-3 of
// the median left out), and the DHI of the sky each holds (∫ L cos θ dω over the upper
// hemisphere's sky texels, luminance).
struct EnvComparison {
  double surface_error = 0.0;
  double sky_dhi = 0.0, true_sky_dhi = 0.0;
  size_t surface_texels = 0;
};
EnvComparison CompareEnvMaps(const bake::EnvMapMaps& env, const std::vector<glm::vec3>& relit,
                             const HdrImage& truth);

// truth | relit | relative difference (blue −25% … white 0 … red +25%), stacked, as a PNG.
void WriteEnvComparison(const std::filesystem::path& png, const bake::EnvMapMaps& env,
                        const std::vector<glm::vec3>& relit, const HdrImage& truth);

// Writes `radiance` (width × height) as a float EXR and a tone-mapped PNG preview next to it
// (same name, .png), each through a temporary name.
void WriteEnvMap(const std::filesystem::path& exr, int width, int height, const std::vector<glm::vec3>& radiance);

}  // namespace daylit::relight
