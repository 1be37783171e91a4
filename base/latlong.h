// Geometry of latitude-longitude environment maps (docs/design.md): row 0 at the zenith (+Z),
// the centre column looks along +Y, moving right turns toward +X (clockwise seen from above).
// Texel (u, v) of a W×H map: θ = π(v+0.5)/H, α = 2π((u+0.5)/W − 0.5),
// ω = (sin θ sin α, sin θ cos α, cos θ).
#pragma once

#include <glm/glm.hpp>

namespace daylit {

// Unit direction through texel coordinates (u, v); integer u, v give texel centres.
glm::dvec3 LatLongDirection(double u, double v, int width, int height);

// Continuous texel coordinates (u, v) of a direction, u in [−0.5, W − 0.5), v in [−0.5, H − 0.5]
// (the inverse of LatLongDirection).
glm::dvec2 LatLongCoordinates(const glm::dvec3& dir, int width, int height);

// Index v·W + u of the texel that holds direction `dir` (nearest texel centre).
int LatLongTexel(const glm::dvec3& dir, int width, int height);

// Solid angle of one texel of row v: (2π/W)·(cos θ0 − cos θ1).
double LatLongTexelSolidAngle(int v, int width, int height);

}  // namespace daylit
