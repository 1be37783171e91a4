#include "scene/raycaster.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <stdexcept>

#include "base/log.h"

namespace daylit::scene {

struct RayCaster::Embree {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Embree() {
    if (scene != nullptr) rtcReleaseScene(scene);
    if (device != nullptr) rtcReleaseDevice(device);
  }
};

namespace {

void OnEmbreeError(void*, RTCError code, const char* message) {
  Log().error("Embree error {}: {}", static_cast<int>(code), message != nullptr ? message : "");
}

RTCRayHit MakeRay(const glm::vec3& origin, const glm::vec3& dir, float t_near, float t_far) {
  RTCRayHit r{};
  r.ray.org_x = origin.x, r.ray.org_y = origin.y, r.ray.org_z = origin.z;
  r.ray.dir_x = dir.x, r.ray.dir_y = dir.y, r.ray.dir_z = dir.z;
  r.ray.tnear = t_near;
  r.ray.tfar = t_far;
  r.ray.mask = 0xFFFFFFFFu;
  r.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  r.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  return r;
}

}  // namespace

RayCaster::RayCaster(const SceneModel& model) : model_(model), embree_(std::make_unique<Embree>()) {
  embree_->device = rtcNewDevice(nullptr);
  if (embree_->device == nullptr) throw std::runtime_error("Embree: cannot create a device");
  rtcSetDeviceErrorFunction(embree_->device, OnEmbreeError, nullptr);
  embree_->scene = rtcNewScene(embree_->device);
  rtcSetSceneBuildQuality(embree_->scene, RTC_BUILD_QUALITY_HIGH);
  // Watertight: without it, rays through a shared edge (the diagonal of a quad) can miss both
  // triangles, and a pixel of solid ground reads as sky.
  rtcSetSceneFlags(embree_->scene, RTC_SCENE_FLAG_ROBUST);

  std::vector<uint32_t> kept;
  kept.reserve(model.triangles.size());
  for (size_t i = 0; i < model.triangles.size(); ++i) {
    const Triangle& t = model.triangles[i];
    const glm::dvec3 a = model.vertices[t.v[0]], b = model.vertices[t.v[1]], c = model.vertices[t.v[2]];
    const double area = 0.5 * glm::length(glm::cross(b - a, c - a));
    if (!(area > 1e-10)) {
      ++degenerate_;
      continue;
    }
    kept.push_back(static_cast<uint32_t>(i));
  }
  RTCGeometry geometry = rtcNewGeometry(embree_->device, RTC_GEOMETRY_TYPE_TRIANGLE);
  auto* vertices = static_cast<float*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3, 3 * sizeof(float), model.vertices.size()));
  for (size_t i = 0; i < model.vertices.size(); ++i) {
    vertices[3 * i] = model.vertices[i].x, vertices[3 * i + 1] = model.vertices[i].y, vertices[3 * i + 2] = model.vertices[i].z;
  }
  auto* indices = static_cast<uint32_t*>(rtcSetNewGeometryBuffer(
      geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3, 3 * sizeof(uint32_t), kept.size()));
  for (size_t i = 0; i < kept.size(); ++i) {
    for (int k = 0; k < 3; ++k) indices[3 * i + static_cast<size_t>(k)] = model.triangles[kept[i]].v[k];
  }
  rtcCommitGeometry(geometry);
  rtcAttachGeometry(embree_->scene, geometry);
  rtcReleaseGeometry(geometry);
  rtcCommitScene(embree_->scene);
  triangle_of_primitive_ = std::move(kept);
}

RayCaster::~RayCaster() = default;

RayHit RayCaster::Intersect(const glm::vec3& origin, const glm::vec3& dir, float t_near, float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRayHit r = MakeRay(origin, dir, t_near, t_far);
  rtcIntersect1(embree_->scene, &context, &r);
  RayHit hit;
  if (r.hit.geomID == RTC_INVALID_GEOMETRY_ID) {
    hit.t = -1.0f;
    return hit;
  }
  hit.t = r.ray.tfar;
  hit.triangle = triangle_of_primitive_[r.hit.primID];
  hit.surface = model_.triangles[hit.triangle].surface;
  glm::vec3 n(r.hit.Ng_x, r.hit.Ng_y, r.hit.Ng_z);
  n = glm::normalize(n);
  hit.back_face = glm::dot(n, dir) > 0.0f;
  hit.normal = hit.back_face ? -n : n;
  return hit;
}

bool RayCaster::Occluded(const glm::vec3& origin, const glm::vec3& dir, float t_near, float t_far) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  RTCRay ray = MakeRay(origin, dir, t_near, t_far).ray;
  rtcOccluded1(embree_->scene, &context, &ray);
  return ray.tfar < 0.0f;  // Embree sets tfar to −inf on a hit
}

void RayCaster::IntersectMany(const glm::vec3* origins, const glm::vec3* dirs, size_t count, float t_near,
                              RayHit* hits) const {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 1024), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) hits[i] = Intersect(origins[i], dirs[i], t_near);
  });
}

void RayCaster::OccludedMany(const glm::vec3* origins, const glm::vec3* dirs, size_t count, float t_near,
                             float t_far, uint8_t* occluded) const {
  tbb::parallel_for(tbb::blocked_range<size_t>(0, count, 4096), [&](const tbb::blocked_range<size_t>& range) {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    context.flags = RTC_INTERSECT_CONTEXT_FLAG_INCOHERENT;
    for (size_t i = range.begin(); i != range.end(); ++i) {
      RTCRay ray = MakeRay(origins[i], dirs[i], t_near, t_far).ray;
      rtcOccluded1(embree_->scene, &context, &ray);
      occluded[i] = ray.tfar < 0.0f ? 1 : 0;
    }
  });
}

}  // namespace daylit::scene
