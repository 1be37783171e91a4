// The light the virtual objects' own surfaces send out, for what they reflect onto the real
// surfaces around them (ObjectShadows::SetObjectRadiance): at the triangle sides of the objects'
// model that real surfaces see, per unit of each part of the light (E_sun, E_clear, E_overcast),
//
//   L = ρ/π · (E_sun·s·max(0, n·l) + E_indirect − E_lost)
//
// with ρ the object's albedo (scene.json, as the compositor draws it), s the sun's visibility past
// the real model and the objects (one shadow ray from the side's centre), E_indirect the
// irradiance volume's part at the side's centre (given by the caller) and E_lost the light the
// objects' own shadows take from the real surfaces the side sees (ObjectBounce), without which a
// sphere's underside would return the sunlit ground's light into its own contact shadow.
#pragma once

#include <array>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include "bake/bake.h"
#include "composite/object_bounce.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::composite {

class ObjectLight {
 public:
  // `objects` is a caster over scene::ObjectsModel(scene.objects); `sides` its triangle sides
  // (triangle·2, + 1 for the back), as ObjectShadows::ReflectingSides() lists them.
  ObjectLight(const scene::Scene& scene, const bake::SceneBake& bake, const scene::RayCaster& real,
              const scene::RayCaster& objects, const std::vector<uint32_t>& sides);

  // Where the sides are: their centres and unit normals (facing out of the side), for the caller's
  // E_indirect.
  const std::vector<glm::vec3>& points() const { return sides_.points; }
  const std::vector<glm::vec3>& normals() const { return sides_.normals; }

  // The sun's share s·max(0, n·l) per side, and the objects' shadow losses, for a new sun.
  void SetSun(const glm::vec3& sun_dir);

  // Each side's radiance per unit of each part, given `indirect[k][i]`, part k's irradiance at side
  // i (the volume's), for the current sun.
  void Radiance(const std::array<std::vector<glm::vec3>, 3>& indirect, std::array<std::vector<glm::vec3>, 3>* radiance) const;

  struct Sides {
    std::vector<glm::vec3> points, normals;
  };

 private:
  const scene::RayCaster& real_;
  const scene::RayCaster& objects_;
  Sides sides_;
  std::vector<glm::vec3> albedo_over_pi_;
  std::vector<float> sun_;  // s·max(0, n·l)
  ObjectBounce bounce_;
};

}  // namespace daylit::composite
