#include "scene/model.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include "base/atomic_file.h"
#include "base/error.h"

namespace daylit::scene {
namespace {

TEST(ModelTest, CourtyardSurfacesAndAreas) {
  const SceneModel model = LoadObjModel(DAYLIT_SOURCE_DIR "/recordings/courtyard-a/model.obj");
  ASSERT_EQ(model.surface_names.size(), 10u);
  EXPECT_EQ(model.surface_names[0], "ground");
  const std::vector<double> areas = model.SurfaceAreas();
  EXPECT_NEAR(areas[static_cast<size_t>(model.SurfaceIndex("ground"))], 80.0 * 80.0, 1e-3);
  // building_south: a 28 x 6 x 7 m block, roof and four walls.
  EXPECT_NEAR(areas[static_cast<size_t>(model.SurfaceIndex("building_south"))],
              28 * 6 + 2 * (28 * 7) + 2 * (6 * 7), 1e-3);
  EXPECT_EQ(model.MatchSurfaces("building_*").size(), 5u);
  EXPECT_EQ(model.MatchSurfaces("wall_?ast").size(), 1u);
  EXPECT_TRUE(model.MatchSurfaces("roof").empty());
  glm::vec3 lo, hi;
  model.Bounds(&lo, &hi);
  EXPECT_FLOAT_EQ(lo.x, -1000.0f);
  EXPECT_FLOAT_EQ(lo.z, -0.02f);
}

TEST(ModelTest, QuadsAreTriangulatedAndNamesMerged) {
  const auto path = std::filesystem::temp_directory_path() / ("daylit_model_" + std::to_string(::getpid()) + ".obj");
  WriteFileAtomically(path,
                      "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n"
                      "o b\nf 1 2 3\no a\nf 2 3 4\n");
  const SceneModel model = LoadObjModel(path);
  std::filesystem::remove(path);
  EXPECT_EQ(model.surface_names, (std::vector<std::string>{"a", "b"}));
  EXPECT_EQ(model.triangles.size(), 4u);
  EXPECT_NEAR(model.SurfaceAreas()[0], 1.0 + 0.5, 1e-6);
}

TEST(ModelTest, NegativeIndicesCountBackFromTheLastVertex) {
  // OBJ's relative indices: -1 is the last vertex defined so far. Texture and normal indices
  // after '/' are carried by the reader and not used.
  const auto path = std::filesystem::temp_directory_path() / ("daylit_model_neg_" + std::to_string(::getpid()) + ".obj");
  WriteFileAtomically(path, "o a\nv 0 0 0\nv 2 0 0\nv 0 2 0\nvt 0 0\nf -3/1 -2/1 -1/1\nv 9 9 9\n");
  const SceneModel model = LoadObjModel(path);
  std::filesystem::remove(path);
  ASSERT_EQ(model.triangles.size(), 1u);
  EXPECT_NEAR(model.SurfaceAreas()[0], 2.0, 1e-6);  // the first three vertices, not the fourth
}

TEST(ModelTest, BadModelsAreInputErrors) {
  const auto path = std::filesystem::temp_directory_path() / ("daylit_bad_" + std::to_string(::getpid()) + ".obj");
  for (const char* text : {"o a\nv 0 0 0\nv inf 1 0\nv 1 1 0\nf 1 2 3\n", "o a\nv 0 0\nf 1 1 1\n",
                           "o a\nv 0 0 0\n", "o a\nv 0 0 0\nv 1 0 0\nv 1 1 0\nf 1 2 4\n"}) {
    WriteFileAtomically(path, text);
    EXPECT_THROW(LoadObjModel(path), InputError) << text;
  }
  std::filesystem::remove(path);
  EXPECT_THROW(LoadObjModel(path), InputError);
}

}  // namespace
}  // namespace daylit::scene
