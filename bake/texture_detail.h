// Texture detail for the camera G-buffer's albedo. The env map fixes albedo at its own
// resolution (a texel spans ~6 cm on a wall 10 m away); the camera resolves ~1 cm, and a median
// over blurred brick and mortar is not the median of the texture (the bundled recording's red
// brick wall reads 6–8% too grey in G and B). The camera frames carry the detail:
// D(px) = I(px) / blur(I)(px), per channel, the blur as wide as an env texel seen at that pixel,
// and albedo_px = albedo_env(px) · D(px). Lighting is smooth at that scale except at shadow edges,
// which move between frames hours apart: the median of D over frames spread across the recording
// drops them.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/scene.h"

namespace daylit::bake {

struct DetailOptions {
  int frames = 9;                 // frames spread evenly over the recording
  float footprint_scale = 1.5f;   // env texel footprint × this (the map's pixel filter, bilinear lookup)
  // Empty when every field is in range, else the first problem, naming the field.
  std::string Check() const;
};

// D for every camera pixel (1 where unknown: no model point, no frames, too few usable samples).
// `points`, `surface` and `has_point` are the G-buffer's; `env_height` is the env map's height
// (rows over π). blur(I) is over the pixel's own surface only: the env albedo it multiplies is
// (EnvAlbedoAt), and a box reaching into a brighter neighbour (a sunlit wall, the sky-lit far
// ground under a white building) made D, and the albedo, too low along every edge.
std::vector<glm::vec3> CameraTextureDetail(const scene::Scene& scene, const std::vector<glm::vec3>& points,
                                           const std::vector<uint32_t>& surface, const std::vector<uint8_t>& has_point,
                                           int env_height, const DetailOptions& options);

}  // namespace daylit::bake
