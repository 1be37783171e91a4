// Ground-truth irradiance of a latitude-longitude radiance map (seed 002, eqs. 3-4): for a unit
// normal n, E(n) = Σ over texels of L · max(0, n·ω) · ΔΩ, with ΔΩ the texel's solid angle
// (sin θ-weighted), over the whole hemisphere of n. The texels of a row share θ, so per row the
// sum is three prefix-sum differences over the arc of azimuths in front of n: O(rows) per
// normal, parallel over normals (20 480 normals of a 1024×512 map in well under a second).
#pragma once

#include <vector>

#include <glm/glm.hpp>

#include "base/hdr_image.h"

namespace daylit::sh {

std::vector<glm::dvec3> ExactIrradiance(const HdrImage& map, const std::vector<glm::vec3>& normals);

// The centroid directions of the faces of an icosahedron subdivided `levels` times (each level
// splits every triangle in four, vertices pushed onto the sphere): 20·4^levels unit normals,
// nearly uniform; levels = 5 gives seed 002's 20 480.
std::vector<glm::vec3> IcosahedronNormals(int levels);

// The irradiance of every texel direction of a width × height lat-long map (row-major): the
// "irradiance map" of seed 002.
std::vector<glm::dvec3> ExactIrradianceMap(const HdrImage& map, int width, int height);

// `map` box-filtered down by `factor` in both directions (width and height divisible by it).
// Each new texel holds the solid-angle-weighted mean radiance of the texels it covers, so the
// map's integrals against smooth kernels (irradiance) change by a fraction of a percent.
HdrImage DownsampleLatLong(const HdrImage& map, int factor);

}  // namespace daylit::sh
