// The irradiance volume of seed 001: a grid of probes over scene.json's `volume`, each holding
// the L2 spherical-harmonic irradiance (9 RGB coefficients, Ramamoorthi & Hanrahan's cosine
// convolution folded in) of the light arriving there from the relit environment map, with
// parallax through the bake's gather tables (each probe direction reads the env texel that shows
// the model point it hits, or the sky in its direction where it escapes). Updated every frame; evaluated at any point and normal by trilinear
// interpolation of the coefficients. The sun is not in it: the renderer draws the sun as a
// directional light with shadows, and keeping it out of the SH is what keeps SH9 accurate.
//
// Layout of coefficients() (what the renderer reads): probe-major, then coefficient, then RGB,
// float: value [((k·ny + j)·nx + i)·9 + c] for probe (i, j, k) and coefficient c in sh9.h's
// order. Probes sit on the volume's corners and between (ProbePosition: min + (max − min)
// · i/(n − 1)); Irradiance() interpolates the coefficients trilinearly between the eight probes
// around a point, clamped into the box (the compositor interpolates them so to each vertex on
// the CPU and evaluates them with each fragment's normal). The irradiance is E(n) = Σ_c coefficient_c · Y_c(n), no further factors.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "sh/gather_tables.h"
#include "sh/sh9.h"

namespace daylit::sh {

// The eight grid points around `point` (clamped into the box [min, max]) of a grid of
// `resolution` points spanning it (point (i, j, k) at min + (max − min) · (i, j, k)/(n − 1)),
// as indices (k·ny + j)·nx + i, and their trilinear weights, summing to 1.
void TrilinearCorners(const glm::vec3& min, const glm::vec3& max, const glm::ivec3& resolution, const glm::vec3& point,
                      std::array<size_t, 8>* indices, std::array<float, 8>* weights);

// A copy of a volume's coefficients at one moment (IrradianceVolume::Snapshot), for a reader on
// another thread (daylit's lighting server): the same layout and interpolation.
struct Sh9Snapshot {
  glm::vec3 min{0.0f}, max{0.0f};
  glm::ivec3 resolution{0};
  std::vector<float> coefficients;  // IrradianceVolume::coefficients()' layout

  bool empty() const { return coefficients.empty(); }
  // The 9 RGB irradiance coefficients at `point` (trilinear, clamped into the box), coefficient
  // c's R, G, B at [3c], [3c + 1], [3c + 2].
  std::array<float, 27> At(const glm::vec3& point) const;
};

class IrradianceVolume {
 public:
  // `inside[p]` marks probes inside the model (bake::ProbesInsideModel): they take the mean of their
  // valid neighbours after each update instead of the black they would see.
  explicit IrradianceVolume(const GatherTables& gather, std::vector<uint8_t> inside = {});

  // Recomputes every probe from the env map's radiance stacked on its sky layer (2·W·H RGB
  // values: the map's texels row-major, then the sky's radiance in each texel's direction;
  // bake/parallax.h), sun excluded: the gather directions carry 4π/N sr each.
  void Update(const std::vector<glm::vec3>& stacked_radiance);

  // Sets the coefficients to Σ_i weights[i] · parts[i], channel by channel, `parts` being
  // coefficients() after updates from other maps: Update is linear, so this is the update from
  // the map Σ_i weights[i] · map_i (how the renderer follows each frame's light at no cost).
  void SetCombination(const std::array<const std::vector<float>*, 3>& parts, const std::array<glm::vec3, 3>& weights);

  // Irradiance at `point` (clamped into the volume) on a surface with unit normal `normal`.
  glm::vec3 Irradiance(const glm::vec3& point, const glm::vec3& normal) const;
  // Σ_c coefficient_c(point) · weights_c, the coefficients trilinear at `point` (clamped into the
  // volume): Irradiance() with weights Y_c(n); other weights integrate other lobes, e.g. the
  // light arriving from a set of directions.
  glm::vec3 Integrate(const glm::vec3& point, const Sh9Basis& weights) const;
  // The trilinear interpolation at `point` (clamped into the volume): eight probes (indices into
  // the probe-major layout) and their weights, summing to 1.
  void Corners(const glm::vec3& point, std::array<size_t, 8>* probes, std::array<float, 8>* weights) const;
  // The same at probe (i, j, k), no interpolation.
  glm::vec3 ProbeIrradiance(int i, int j, int k, const glm::vec3& normal) const;

  const std::vector<float>& coefficients() const { return coefficients_; }
  // The coefficients and the grid into `out` (its storage reused).
  void Snapshot(Sh9Snapshot* out) const;
  const GatherTables& gather() const { return gather_; }
  size_t InsideCount() const;

 private:
  glm::vec3 Evaluate(size_t probe, const Sh9Basis& y) const;  // Σ_c coefficient_c · y_c

  const GatherTables& gather_;
  std::vector<uint8_t> inside_;
  std::vector<float> basis_;         // [c · N + d]: Â_l · Y_c(direction d) · 4π/N
  std::vector<float> coefficients_;  // layout above
  std::vector<float> gathered_;      // scratch: one probe's radiances, R then G then B
};


}  // namespace daylit::sh
