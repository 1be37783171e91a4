// Triangle meshes of the virtual objects in scene coordinates: scene.json's builtin sphere and
// box, or an OBJ file, placed by the object's scale, rotation and position. The renderer draws
// them; the ray caster casts the shadows and sky occlusion they add to the real scene.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "scene/model.h"
#include "scene/raycaster.h"
#include "scene/scene.h"

namespace daylit::scene {

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // unit, per vertex
  std::vector<uint32_t> indices;   // triangles, counter-clockwise seen from outside
};

// A UV sphere of `stacks` × `slices` quads about the origin, normals exact.
Mesh SphereMesh(float radius, int stacks, int slices);
// A box of full edge lengths `size` about the origin, flat normals, each face an 8×8 grid of quads.
Mesh BoxMesh(const glm::vec3& size);

// The object's mesh placed in the scene: R = Rz·Ry·Rx from rotation_deg, then scale, then the
// position. OBJ and glTF 2.0 files (.gltf, .glb: the default scene's triangle primitives, node
// transforms applied, glTF's +Y up turned to the scene's +Z up) get per-face normals. Throws
// InputError naming the file for a mesh that cannot be read or has no triangles. A builtin sphere
// has `sphere_slices` around (kSphereSlices: within 5.4e-4 of its radius) and half as many
// stacks.
constexpr int kSphereSlices = 96;
Mesh ObjectMesh(const VirtualObject& object, int sphere_slices = kSphereSlices);

// The mesh the renderer shades (and computes per-vertex terms on): ObjectMesh with a builtin
// sphere's slices chosen for the scene's camera, so that the polygon strays at most 0.1 pixel
// (a fifth of the 4× MSAA samples' spacing) from the circle at the sphere's nearest depth:
// r·(1 − cos(π/n)) ≤ 0.1 px, and at least 48 for its shading's sake. A sphere 90 pixels wide gets 48 slices instead of 96,
// a quarter of the triangles, where software GL's cost is per triangle. Shadows and occlusion are
// ray cast against ObjectMesh's full one.
Mesh ShadingMesh(const VirtualObject& object, const Scene& scene);

// Whether the triangles close a volume with consistent counter-clockwise-from-outside faces,
// vertices welded by exact position: every edge is traversed once each way (triangles with two
// equal vertices, a pole's fan, are skipped). The renderer culls such a mesh's back faces.
bool IsClosedMesh(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices);

// Throws InputError ("<where>: objects[i]: ... inside the model (surface 'x')") for an object
// whose centre (its bounding-box centre) lies inside the real model: 9 in 10 of 64 rays from it
// leave through the back of a face, as from inside a solid wall. `objects` is ObjectsModel's
// (surface i is object i), `real` a caster over the scene's model.
void CheckObjectsOutsideModel(const SceneModel& objects, const RayCaster& real, const std::string& where);

// All the objects as one triangle model, surface i being object i (for a RayCaster).
SceneModel ObjectsModel(const std::vector<VirtualObject>& objects);

}  // namespace daylit::scene
