#include "composite/object_light.h"

#include <glm/gtc/constants.hpp>
#include <tbb/parallel_for.h>

#include "base/check.h"

namespace daylit::composite {
namespace {

constexpr float kOffset = 2e-3f;  // ray origins off the surface, as elsewhere

// What an object's side reflects is a small share of a real point's light, smooth over the
// object: a coarser look at what the side sees than the objects' own shading takes.
ObjectBounceOptions CoarseBounce() {
  ObjectBounceOptions options;
  options.rays = 16;
  options.sky_rays = 8;
  return options;
}

ObjectLight::Sides SidesOf(const scene::SceneModel& model, const std::vector<uint32_t>& sides) {
  ObjectLight::Sides out;
  for (const uint32_t side : sides) {
    DAYLIT_CHECK(side / 2 < model.triangles.size(), "side {} of a model of {} triangles", side, model.triangles.size());
    const scene::Triangle& t = model.triangles[side / 2];
    const glm::vec3 a = model.vertices[t.v[0]], b = model.vertices[t.v[1]], c = model.vertices[t.v[2]];
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    out.points.push_back((a + b + c) / 3.0f);
    out.normals.push_back(side % 2 == 0 ? n : -n);
  }
  return out;
}

}  // namespace

ObjectLight::ObjectLight(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
                         const scene::RayCaster& objects, const std::vector<uint32_t>& sides)
    : real_(real),
      objects_(objects),
      sides_(SidesOf(objects.model(), sides)),
      sun_(sides.size(), 0.0f),
      bounce_(scene, bake, real, objects, sides_.points, sides_.normals, CoarseBounce()) {
  for (const uint32_t side : sides) {
    const size_t o = objects.model().triangles[side / 2].surface;  // surface o is object o
    DAYLIT_CHECK(o < scene.objects.size(), "object {} of {}", o, scene.objects.size());
    albedo_over_pi_.push_back(glm::vec3(scene.objects[o].albedo.value_or(glm::dvec3(0.5))) * glm::one_over_pi<float>());
  }
}

void ObjectLight::SetSun(const glm::vec3& sun_dir) {
  const glm::vec3 sun = glm::normalize(sun_dir);
  bounce_.SetSun(sun);
  tbb::parallel_for(tbb::blocked_range<size_t>(0, sides_.points.size(), 256), [&](const tbb::blocked_range<size_t>& range) {
    for (size_t i = range.begin(); i != range.end(); ++i) {
      const float c = glm::dot(sides_.normals[i], sun);
      const glm::vec3 origin = sides_.points[i] + kOffset * sides_.normals[i];
      sun_[i] = sun.z > 0.0f && c > 0.0f && !real_.Occluded(origin, sun) && !objects_.Occluded(origin, sun) ? c : 0.0f;
    }
  });
}

void ObjectLight::Radiance(const std::array<std::vector<glm::vec3>, 3>& indirect,
                           std::array<std::vector<glm::vec3>, 3>* radiance) const {
  for (size_t k = 0; k < 3; ++k) {
    DAYLIT_CHECK(indirect[k].size() == sides_.points.size(), "indirect light for {} sides, not {}", indirect[k].size(), sides_.points.size());
    (*radiance)[k].resize(sides_.points.size());
  }
  // The objects' shadows take E_sun·A_sun and E_sky·A_sky; E_sky = E_clear + E_overcast.
  for (size_t i = 0; i < sides_.points.size(); ++i) {
    const glm::vec3 sun = glm::vec3(sun_[i]) + indirect[0][i] - bounce_.sun_loss()[i];
    const glm::vec3 clear = indirect[1][i] - bounce_.sky_loss()[i], overcast = indirect[2][i] - bounce_.sky_loss()[i];
    (*radiance)[0][i] = albedo_over_pi_[i] * glm::max(sun, glm::vec3(0.0f));
    (*radiance)[1][i] = albedo_over_pi_[i] * glm::max(clear, glm::vec3(0.0f));
    (*radiance)[2][i] = albedo_over_pi_[i] * glm::max(overcast, glm::vec3(0.0f));
  }
}

}  // namespace daylit::composite
