#include "scene/object_mesh.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <glm/gtc/constants.hpp>

#include "base/error.h"


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

// The renderer's mesh for a builtin sphere: its polygon within 0.1 pixel of the circle at the
// sphere's nearest depth, not coarser than 48 slices, the full 96 where it reaches the camera.
TEST(ObjectMeshTest, ShadingSpheresAreAsFineAsTheirSizeInTheImageNeeds) {
  Scene scene;
  scene.intrinsics.fx = scene.intrinsics.fy = 800.0;  // the camera at the origin, looking along +z
  VirtualObject sphere;
  sphere.radius = 0.5;
  const auto slices = [&](double depth) {
    sphere.position = glm::dvec3(0.0, 0.0, depth);
    const Mesh m = ShadingMesh(sphere, scene);
    const Mesh full = ObjectMesh(sphere);
    EXPECT_EQ(full.positions.size(), 49u * 97u);
    // (n/2 + 1)·(n + 1) vertices for n slices.
    for (int n = 2; n <= kSphereSlices; n += 2) {
      if (m.positions.size() == static_cast<size_t>((n / 2 + 1) * (n + 1))) return n;
    }
    ADD_FAILURE() << m.positions.size() << " vertices";
    return 0;
  };
  const auto stray_px = [](double depth, int n) { return 800.0 * 0.5 / (depth - 0.5) * (1.0 - std::cos(glm::pi<double>() / n)); };
  const int middle = slices(5.0);  // 89 pixels in radius
  EXPECT_LE(stray_px(5.0, middle), 0.1);
  EXPECT_GT(stray_px(5.0, middle - 2), 0.1);
  EXPECT_LT(middle, kSphereSlices);
  EXPECT_GT(middle, 48);
  EXPECT_EQ(slices(2.0), kSphereSlices);  // 267 pixels: the full mesh's
  EXPECT_EQ(slices(100.0), 48);         // 4 pixels: the floor
  EXPECT_EQ(slices(0.3), kSphereSlices);  // around the camera
  VirtualObject box;
  box.kind = MeshKind::kBox;
  box.size = glm::dvec3(1.0);
  box.position = glm::dvec3(0.0, 0.0, 100.0);
  EXPECT_EQ(ShadingMesh(box, scene).positions.size(), ObjectMesh(box).positions.size());
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

// A tetrahedron written as glTF 2.0 (JSON + .bin): glTF's +Y up becomes the scene's +Z, the
// node's translation applies, and the faces stay outward.
TEST(ObjectMeshTest, GltfMeshesAreReadWithTheirNodesAndTurnedToZUp) {
  const std::filesystem::path dir = std::filesystem::temp_directory_path() / ("daylit_gltf_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  // glTF coordinates: A(0,0,0) B(1,0,0) C(0,0,−1) D(0,2,0), i.e. scene (0,0,0) (1,0,0) (0,1,0) (0,0,2).
  const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 2, 0};
  const uint16_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  {
    std::ofstream bin(dir / "tet.bin", std::ios::binary);
    bin.write(reinterpret_cast<const char*>(positions), sizeof(positions));
    bin.write(reinterpret_cast<const char*>(indices), sizeof(indices));
  }
  {
    std::ofstream gltf(dir / "tet.gltf");
    gltf << R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
      "nodes": [{"mesh": 0, "translation": [1, 0, 0]}],
      "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
      "buffers": [{"uri": "tet.bin", "byteLength": 72}],
      "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24}],
      "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, -1], "max": [1, 2, 0]},
                    {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"}]})";
  }
  VirtualObject object;
  object.kind = MeshKind::kFile;
  object.file = dir / "tet.gltf";
  object.position = glm::dvec3(0.0, 0.0, 0.5);
  const Mesh m = ObjectMesh(object);
  ASSERT_EQ(m.indices.size(), 12u);
  EXPECT_NEAR(Volume(m), 1.0 / 3.0, 1e-6) << "outward, the right size";
  EXPECT_TRUE(IsClosedMesh(m.positions, m.indices));
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (const glm::vec3& p : m.positions) lo = glm::min(lo, p), hi = glm::max(hi, p);
  EXPECT_NEAR(lo.x, 1.0f, 1e-6f) << "the node's translation";
  EXPECT_NEAR(hi.y, 1.0f, 1e-6f) << "glTF's −Z is the scene's +Y";
  EXPECT_NEAR(hi.z, 2.5f, 1e-6f) << "glTF's +Y is the scene's +Z, then the object's position";
  // Not a mesh: a clear error naming the file.
  std::ofstream(dir / "bad.gltf") << "this is not json";
  std::ofstream(dir / "bad.glb") << "glTF but not binary";
  for (const char* name : {"bad.gltf", "bad.glb"}) {
    object.file = dir / name;
    try {
      ObjectMesh(object);
      ADD_FAILURE() << name << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(std::string(name) + ": not a glTF 2.0 file"), std::string::npos) << e.what();
    }
  }
  std::filesystem::remove_all(dir);
}

// A glTF's buffer uri is held to the recording folder after tinygltf joins and percent-decodes it:
// "../" and "%2e%2e/" climbing out are refused by name (not read), one inside is read, and with
// no root (--allow-outside-paths) the escape is followed; so is a link out of the folder refused.
TEST(ObjectMeshTest, GltfBuffersOutsideTheRecordingAreRefused) {
  namespace fs = std::filesystem;
  const fs::path dir = fs::temp_directory_path() / ("daylit_gltf_root_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "rec" / "objects");
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (const fs::path& bin : {dir / "tri.bin", dir / "rec" / "tri.bin"}) {
    std::ofstream(bin, std::ios::binary).write(reinterpret_cast<const char*>(positions), sizeof(positions));
  }
  const auto gltf = [&](const std::string& name, const std::string& uri) {
    std::ofstream(dir / "rec" / "objects" / name)
        << R"({"asset": {"version": "2.0"}, "nodes": [{"mesh": 0}], "scenes": [{"nodes": [0]}],
              "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
              "buffers": [{"uri": ")" << uri << R"(", "byteLength": 36}],
              "bufferViews": [{"buffer": 0, "byteLength": 36}],
              "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3"}]})";
    VirtualObject object;
    object.kind = MeshKind::kFile;
    object.file = dir / "rec" / "objects" / name;
    object.resource_root = dir / "rec";
    return object;
  };
  EXPECT_EQ(ObjectMesh(gltf("inside.gltf", "../tri.bin")).indices.size(), 3u);
  for (const auto& [name, uri] : {std::pair<std::string, std::string>{"up.gltf", "../../tri.bin"},
                                  {"encoded.gltf", "%2e%2e/%2E%2E/tri.bin"},
                                  {"deep.gltf", "../../../../../../../../etc/passwd"}}) {
    VirtualObject object = gltf(name, uri);
    try {
      ObjectMesh(object);
      ADD_FAILURE() << uri << " was read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("outside the recording folder"), std::string::npos) << e.what();
    }
    if (name == "up.gltf") {
      object.resource_root.clear();
      EXPECT_EQ(ObjectMesh(object).indices.size(), 3u);
    }
  }
  // A link inside the folder to a file outside it (issue 52: read, and its size in the error): refused
  // before it is read; a link that stays inside is followed.
  fs::create_symlink(dir / "tri.bin", dir / "rec" / "objects" / "evil.bin");
  fs::create_symlink(dir / "rec" / "tri.bin", dir / "rec" / "objects" / "good.bin");
  try {
    ObjectMesh(gltf("linked.gltf", "evil.bin"));
    ADD_FAILURE() << "a link out of the folder was read";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("outside the recording folder"), std::string::npos) << e.what();
  }
  EXPECT_EQ(ObjectMesh(gltf("linked_inside.gltf", "good.bin")).indices.size(), 3u);
  // A uri that names a folder (the glTF's own, or one beside it): an input error, with or without
  // a root, not a request for the 2^63 - 1 bytes a folder seeks to on ext4 (fuzz_gltf found it).
  fs::create_directories(dir / "rec" / "objects" / "sub");
  for (const std::string uri : {"", ".", "sub", "../objects/"}) {
    for (const bool rooted : {true, false}) {
      VirtualObject object = gltf("folder.gltf", uri);
      if (!rooted) object.resource_root.clear();
      EXPECT_THROW(ObjectMesh(object), InputError) << "uri '" << uri << "'";
    }
  }
  fs::remove_all(dir);
}

// A solid wall (a closed box, faces outward): a sphere whose centre is in it is refused, naming
// the object and the wall; one beside it, or sunk halfway into the ground plane, is fine.
TEST(ObjectMeshTest, AnObjectInsideAWallIsRefused) {
  SceneModel model;
  const Mesh wall = BoxMesh(glm::vec3(4.0f, 0.3f, 3.0f));
  for (const glm::vec3& p : wall.positions) model.vertices.push_back(p + glm::vec3(0.0f, 0.0f, 1.5f));
  for (size_t t = 0; t < wall.indices.size(); t += 3) model.triangles.push_back({{wall.indices[t], wall.indices[t + 1], wall.indices[t + 2]}, 0});
  model.surface_names = {"wall_north"};
  const auto ground = static_cast<uint32_t>(model.vertices.size());
  model.vertices.insert(model.vertices.end(), {{-9, -9, 0}, {9, -9, 0}, {9, 9, 0}, {-9, 9, 0}});
  model.triangles.push_back({{ground, ground + 1, ground + 2}, 1});
  model.triangles.push_back({{ground, ground + 2, ground + 3}, 1});
  model.surface_names.push_back("ground");
  const RayCaster caster(model);
  VirtualObject sphere;
  sphere.radius = 0.5;
  sphere.position = glm::dvec3(1.0, 2.0, 0.5);
  EXPECT_NO_THROW(CheckObjectsOutsideModel(ObjectsModel({sphere}), caster, "scene.json"));
  sphere.position = glm::dvec3(1.0, 2.0, 0.0);  // half in the ground: the ground is a surface, not a solid
  EXPECT_NO_THROW(CheckObjectsOutsideModel(ObjectsModel({sphere}), caster, "scene.json"));
  VirtualObject inside = sphere;
  inside.position = glm::dvec3(0.5, 0.05, 1.0);
  try {
    CheckObjectsOutsideModel(ObjectsModel({sphere, inside}), caster, "scene.json");
    ADD_FAILURE() << "an object inside the wall was accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json: objects[1]: its centre (0.50, 0.05, 1.00) is inside the model (surface 'wall_north')"),
              std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace daylit::scene
