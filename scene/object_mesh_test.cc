#include "scene/object_mesh.h"

#include <gtest/gtest.h>

#include <glm/gtc/constants.hpp>


namespace daylit::scene {
namespace {

// Volume by the divergence theorem: Σ over triangles of (a · (b × c)) / 6; positive when every
// triangle winds counter-clockwise seen from outside.
double Volume(const Mesh& m) {
  double v = 0.0;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const glm::dvec3 a = m.positions[m.indices[t]], b = m.positions[m.indices[t + 1]], c = m.positions[m.indices[t + 2]];
    v += glm::dot(a, glm::cross(b, c)) / 6.0;
  }
  return v;
}

TEST(ObjectMeshTest, BuiltinShapesAreClosedOutwardAndTheRightSize) {
  const Mesh sphere = SphereMesh(0.5f, 48, 96);
  EXPECT_NEAR(Volume(sphere), 4.0 / 3.0 * glm::pi<double>() * 0.125, 0.005 * 0.5236);
  for (size_t i = 0; i < sphere.positions.size(); ++i) EXPECT_NEAR(glm::dot(sphere.normals[i], sphere.positions[i]), 0.5f, 1e-5f);
  const Mesh box = BoxMesh(glm::vec3(0.6f, 0.4f, 1.0f));
  EXPECT_NEAR(Volume(box), 0.24, 1e-6);
  // Flat normals point away from the centre.
  for (size_t i = 0; i < box.positions.size(); ++i) EXPECT_GT(glm::dot(box.normals[i], box.positions[i]), 0.0f);
  // Watertight, so the renderer may cull their back faces.
  EXPECT_TRUE(IsClosedMesh(sphere.positions, sphere.indices));
  EXPECT_TRUE(IsClosedMesh(box.positions, box.indices));
  // A face missing, or one turned inside out: not closed.
  std::vector<uint32_t> open_box(box.indices.begin() + 6, box.indices.end());
  EXPECT_FALSE(IsClosedMesh(box.positions, open_box));
  std::vector<uint32_t> flipped = box.indices;
  std::swap(flipped[1], flipped[2]);
  EXPECT_FALSE(IsClosedMesh(box.positions, flipped));
}

TEST(ObjectMeshTest, PlacementRotatesThenMoves) {
  VirtualObject box;
  box.kind = MeshKind::kBox;
  box.size = glm::dvec3(2.0, 1.0, 1.0);
  box.position = glm::dvec3(1.0, 2.0, 3.0);
  box.rotation_deg = glm::dvec3(0.0, 0.0, 90.0);  // the long side turns from x to y
  const Mesh m = ObjectMesh(box);
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  EXPECT_NEAR(hi.x - lo.x, 1.0f, 1e-5f);
  EXPECT_NEAR(hi.y - lo.y, 2.0f, 1e-5f);
  EXPECT_NEAR(0.5f * (hi.y + lo.y), 2.0f, 1e-5f);
  EXPECT_NEAR(Volume(m), 2.0, 1e-5);  // still outward
}

}  // namespace
}  // namespace daylit::scene
