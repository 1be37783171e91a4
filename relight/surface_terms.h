// The model's terms T_sun, T_clear and T_overcast (estimation/transfer.h) at every model point of
// a grid of points: the env map's texels (the relit map) or the camera's pixels (image relighting).
// When the sun moves, the direct terms are recomputed for every point (a shadow ray each); the
// reflected light, which is smooth, comes from the transfer of one point in 4×4 (the nearest
// such point on the same surface; points with none get their own).
#pragma once

#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "estimation/transfer.h"
#include "scene/raycaster.h"

namespace daylit::relight {

class SurfaceTerms {
 public:
  // `points`: a width × height grid (row-major), kNoSurface where a point shows sky. `wrap_u`:
  // the grid wraps around horizontally (a lat-long map). `bake`, the arrays behind `points` and
  // `caster` must outlive this.
  SurfaceTerms(const bake::SceneBake& bake, estimation::TransferPoints points, int width, int height, bool wrap_u,
               const glm::vec3& capture_position, const scene::RayCaster& caster,
               estimation::TransferOptions options = {});

  // The terms of every model point (in model_points() order) under the unit sun `sun_dir`.
  void Compute(const glm::vec3& sun_dir, std::vector<estimation::Transfer>* terms);

  // The grid's model points, row-major.
  const std::vector<uint32_t>& model_points() const { return model_points_; }
  const estimation::LightTransfer& transfer() const { return transfer_; }

 private:
  estimation::TransferPoints points_;
  const scene::RayCaster& caster_;
  estimation::LightTransfer transfer_;
  std::vector<uint32_t> model_points_;
  std::vector<uint32_t> traced_;          // the representatives, each once
  std::vector<uint32_t> representative_;  // per model point: its representative, index into traced_
};

}  // namespace daylit::relight
