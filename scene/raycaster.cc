#include "scene/raycaster.h"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
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

// Lane i of a packet: the ray origin + t·dir, t ≥ t_near, valid or not.
void SetLane(RTCRay16& ray, int* valid, size_t i, bool on, const glm::vec3& origin, const glm::vec3& dir, float t_near) {
  valid[i] = on ? -1 : 0;
  ray.org_x[i] = origin.x, ray.org_y[i] = origin.y, ray.org_z[i] = origin.z;
  ray.dir_x[i] = dir.x, ray.dir_y[i] = dir.y, ray.dir_z[i] = dir.z;
  ray.tnear[i] = t_near, ray.tfar[i] = 1e30f, ray.time[i] = 0.0f;
  ray.mask[i] = 0xFFFFFFFFu, ray.id[i] = 0, ray.flags[i] = 0;
}

// A hit as RayHit: the model's triangle and surface, the normal turned toward the origin.
RayHit HitOf(const SceneModel& model, const std::vector<uint32_t>& triangle_of_primitive, uint32_t prim, float t,
             const glm::vec3& ng, const glm::vec3& dir) {
  RayHit hit;
  hit.t = t;
  hit.triangle = triangle_of_primitive[prim];
  hit.surface = model.triangles[hit.triangle].surface;
  const glm::vec3 n = glm::normalize(ng);
  hit.back_face = glm::dot(n, dir) > 0.0f;
  hit.normal = hit.back_face ? -n : n;
  return hit;
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
  if (r.hit.geomID == RTC_INVALID_GEOMETRY_ID) return RayHit{-1.0f};
  return HitOf(model_, triangle_of_primitive_, r.hit.primID, r.ray.tfar, glm::vec3(r.hit.Ng_x, r.hit.Ng_y, r.hit.Ng_z), dir);
}

void RayCaster::IntersectFrom(const glm::vec3& origin, const glm::vec3* dirs, size_t count, float t_near,
                              RayHit* hits) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  alignas(64) RTCRayHit16 packet;
  alignas(64) int valid[16];
  for (size_t begin = 0; begin < count; begin += 16) {
    const size_t n = std::min<size_t>(16, count - begin);
    for (size_t i = 0; i < 16; ++i) {
      SetLane(packet.ray, valid, i, i < n, origin, dirs[begin + std::min(i, n - 1)], t_near);
      packet.hit.geomID[i] = RTC_INVALID_GEOMETRY_ID, packet.hit.instID[0][i] = RTC_INVALID_GEOMETRY_ID;
    }
    rtcIntersect16(valid, embree_->scene, &context, &packet);
    for (size_t i = 0; i < n; ++i) {
      hits[begin + i] = packet.hit.geomID[i] == RTC_INVALID_GEOMETRY_ID
                            ? RayHit{-1.0f}
                            : HitOf(model_, triangle_of_primitive_, packet.hit.primID[i], packet.ray.tfar[i],
                                    glm::vec3(packet.hit.Ng_x[i], packet.hit.Ng_y[i], packet.hit.Ng_z[i]), dirs[begin + i]);
    }
  }
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

void RayCaster::OccludedAlong(const glm::vec3* origins, size_t count, const glm::vec3& dir, float t_near,
                              uint8_t* occluded) const {
  RTCIntersectContext context;
  rtcInitIntersectContext(&context);
  context.flags = RTC_INTERSECT_CONTEXT_FLAG_COHERENT;
  alignas(64) RTCRay16 packet;
  alignas(64) int valid[16];
  for (size_t begin = 0; begin < count; begin += 16) {
    const size_t n = std::min<size_t>(16, count - begin);
    for (size_t i = 0; i < 16; ++i) SetLane(packet, valid, i, i < n, origins[begin + std::min(i, n - 1)], dir, t_near);
    rtcOccluded16(valid, embree_->scene, &context, &packet);
    for (size_t i = 0; i < n; ++i) occluded[begin + i] = packet.tfar[i] < 0.0f ? 1 : 0;
  }
}

}  // namespace daylit::scene
