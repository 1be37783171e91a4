// Ground-truth irradiance of a latitude-longitude radiance map (seed 002, eqs. 3-4): for a unit
// normal n, E(n) = Σ over texels of L · max(0, n·ω) · ΔΩ, with ΔΩ the texel's solid angle
// (sin θ-weighted), over the whole hemisphere of n. Direct summation, parallel over normals.
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "scene/hdr_image.h"

namespace daylit::relight {

std::vector<glm::dvec3> ExactIrradiance(const scene::HdrImage& map, const std::vector<glm::vec3>& normals);

// `map` box-filtered down by `factor` in both directions (width and height divisible by it).
// Each new texel holds the solid-angle-weighted mean radiance of the texels it covers, so the
// map's integrals against smooth kernels (irradiance) change by a fraction of a percent.
scene::HdrImage DownsampleLatLong(const scene::HdrImage& map, int factor);

}  // namespace daylit::relight
