// Reading an environment map captured at one point from another point: the parallax rule of the
// irradiance volume's gather tables, the objects' lights and the light objects take from real
// surfaces. A ray from elsewhere that meets the model at y reads the texel that shows y from the
// capture point. A ray that escapes reads the sky in its own direction, which the map alone
// cannot give: where the capture point sees the model in that direction (a wall that the ray,
// from lower down or further away, passes over), the map's texel holds the wall. Read straight,
// a sunlit terracotta wall behind the capture point's view of the sky lit a box 13 m from it
// 25% too red (courtyard-c, frame 462).
//
// So these lookups index a stacked map of 2·W·H entries: the map's W·H texels, then its sky
// layer, the sky's radiance in each texel's direction whatever the capture point sees there
// (relight::EnvRelighter::Basis and RelightWithSky make both).
#pragma once

#include <cstddef>
#include <cstdint>

#include <glm/glm.hpp>

#include "scene/raycaster.h"

namespace daylit::bake {

// The stacked index for a ray from `origin` along unit `dir` whose hit is `hit` (no hit: it
// escapes), in a W×H map captured at `capture`.
uint32_t ParallaxTexel(const glm::vec3& origin, const glm::vec3& dir, const scene::RayHit& hit,
                       const glm::vec3& capture, int width, int height);

// Whether a stacked index reads the sky layer.
inline bool IsSkyLayer(uint32_t stacked, size_t map_texels) { return stacked >= map_texels; }

}  // namespace daylit::bake
