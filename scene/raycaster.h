// Ray casting against the scene model with Embree 3: closest hits and occlusion, one ray or many
// (in parallel over TBB). Nothing else in daylit intersects rays with triangles.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include <glm/glm.hpp>

#include "scene/model.h"

namespace daylit::scene {

struct RayHit {
  float t = 0.0f;            // distance along the unit direction; < 0: no hit (sky)
  uint32_t triangle = 0;     // index into SceneModel::triangles
  uint32_t surface = 0;      // index into SceneModel::surface_names
  glm::vec3 normal{0.0f};    // unit geometric normal, turned to face the ray's origin
  bool back_face = false;    // the triangle's own normal (OBJ winding) faced away from the origin

  bool IsHit() const { return t >= 0.0f; }
};

class RayCaster {
 public:
  // Builds the BVH. Degenerate triangles (zero area or non-finite) are left out and counted.
  explicit RayCaster(const SceneModel& model);
  // The caster keeps a reference to the model (Embree reads its vertices in place): a temporary
  // would dangle.
  explicit RayCaster(SceneModel&& model) = delete;
  ~RayCaster();
  RayCaster(const RayCaster&) = delete;
  RayCaster& operator=(const RayCaster&) = delete;

  const SceneModel& model() const { return model_; }
  size_t degenerate_triangles() const { return degenerate_; }

  // Closest hit of the ray origin + t·dir, t in [t_near, t_far]; `dir` must be unit length.
  RayHit Intersect(const glm::vec3& origin, const glm::vec3& dir, float t_near = 0.0f,
                   float t_far = 1e30f) const;
  // True if anything lies on the segment t in [t_near, t_far].
  bool Occluded(const glm::vec3& origin, const glm::vec3& dir, float t_near = 0.0f, float t_far = 1e30f) const;

  // Many rays at once, in parallel: hits[i] for origins[i] + t·dirs[i].
  void IntersectMany(const glm::vec3* origins, const glm::vec3* dirs, size_t count, float t_near,
                     RayHit* hits) const;
  // occluded[i] = 1 if the ray from origins[i] along dirs[i] hits anything within [t_near, t_far].
  void OccludedMany(const glm::vec3* origins, const glm::vec3* dirs, size_t count, float t_near, float t_far,
                    uint8_t* occluded) const;
  // Rays from one origin, on this thread: hits[i] for origin + t·dirs[i], t ≥ t_near, traced 16
  // at a time as packets (a hemisphere of rays from a surface point).
  void IntersectFrom(const glm::vec3& origin, const glm::vec3* dirs, size_t count, float t_near, RayHit* hits) const;
  // Rays that share one direction (toward the sun), on this thread: occluded[i] = 1 if the ray
  // origins[i] + t·dir, t ≥ t_near, hits anything. Traced 16 at a time as coherent packets, which
  // costs a fraction of one Occluded call per ray on a model of a few dozen triangles.
  void OccludedAlong(const glm::vec3* origins, size_t count, const glm::vec3& dir, float t_near, uint8_t* occluded) const;

 private:
  struct Embree;
  const SceneModel& model_;
  std::unique_ptr<Embree> embree_;
  std::vector<uint32_t> triangle_of_primitive_;  // Embree primID -> model triangle
  size_t degenerate_ = 0;
};

}  // namespace daylit::scene
