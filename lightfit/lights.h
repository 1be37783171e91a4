// An environment map approximated by an ambient term plus N directional lights (seeds 000 and
// 002), so that diffuse shading by the lights matches image-based lighting:
//
//   E(n) = ambient + Σ_i irradiance_i · max(0, n · direction_i)
//
// `irradiance_i` is light i's contribution on a surface facing it; `ambient` the constant
// irradiance it adds to every normal. Directions are unit vectors in the map's frame
// (docs/design.md's lat-long convention).
#pragma once

#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/hdr_image.h"

namespace daylit::lightfit {

struct DirectionalLight {
  glm::vec3 direction{0.0f, 0.0f, 1.0f};
  glm::vec3 irradiance{0.0f};
};

struct LightSet {
  glm::vec3 ambient{0.0f};
  std::vector<DirectionalLight> lights;

  glm::dvec3 Irradiance(const glm::vec3& normal) const;
  std::vector<glm::dvec3> Irradiance(const std::vector<glm::vec3>& normals) const;
};

// `daylit lights`' file format: {"ambient": [r, g, b], "lights": [{"direction": [x, y, z],
// "irradiance": [r, g, b]}, ...]}, with the meanings above.
std::string LightSetJson(const LightSet& set);

// Debevec's Median Cut (seed 002 §4.1): the map, weighted by texel solid angle, is split
// `levels` times, each region along its longer side (width measured at its middle latitude) where
// the luminance on both sides is equal; each of the 2^levels regions becomes one light at its
// luminance-weighted centroid direction carrying the region's whole power Σ L·ΔΩ (RGB). No ambient.
LightSet MedianCut(const HdrImage& map, int levels);

// Median cut for any number of lights n ≥ 1: whole levels while 2^levels ≤ n, then the
// n − 2^levels regions of most power cut once more. For n = 2^levels it is MedianCut.
LightSet MedianCutLights(const HdrImage& map, int n);

// Seed 002's measure over a set of normals: the per-normal relative error |E − E_true| / E_true,
// averaged over RGB; its mean and max over the normals whose true irradiance is at least 1e-3 of
// the maximum (in every channel).
struct ApproximationError {
  double mean = 0.0;
  double max = 0.0;
  size_t normals = 0;
};
ApproximationError RelativeError(const std::vector<glm::dvec3>& truth, const std::vector<glm::dvec3>& approximation);

// Ramamoorthi & Hanrahan's measure: |E − E_true| over the maximum true irradiance (per channel),
// averaged over RGB; mean and max over all normals.
ApproximationError RelativeToMaxError(const std::vector<glm::dvec3>& truth, const std::vector<glm::dvec3>& approximation);

}  // namespace daylit::lightfit
