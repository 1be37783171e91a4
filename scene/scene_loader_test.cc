#include <gtest/gtest.h>

#include <unistd.h>

#include <cmath>

#include <fmt/format.h>

#include "base/error.h"
#include "scene/scene.h"
#include "scene/scene_test_util.h"

namespace daylit::scene {
namespace {

using testing::SceneSandbox;

TEST(SceneLoaderTest, LoadsTheBundledRecordingCompletely) {
  const Scene scene = LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  EXPECT_EQ(scene.name, "courtyard-a");
  EXPECT_DOUBLE_EQ(scene.location.latitude_deg, 57.0488);
  EXPECT_DOUBLE_EQ(scene.location.elevation_m, 10.0);
  EXPECT_DOUBLE_EQ(scene.north_azimuth_deg, -20.0);
  EXPECT_EQ(scene.model.surface_names.size(), 10u);
  // ground + wall_east + 5 building_*; far_ground, pillar and bench are not diffuse surfaces.
  EXPECT_EQ(scene.diffuse_surfaces.size(), 7u);
  EXPECT_EQ(scene.intrinsics.width, 960);
  EXPECT_DOUBLE_EQ(scene.intrinsics.cx, 479.5);
  EXPECT_EQ(scene.response.curve, capture::ResponseCurve::kSrgb);
  EXPECT_NEAR(scene.exposure, 0.198425, 1e-6);
  EXPECT_NEAR(glm::determinant(scene.cam_from_world.rotation), 1.0, 1e-12);
  ASSERT_TRUE(scene.envmap.has_value());
  EXPECT_EQ(FormatUtcTime(scene.envmap->time_utc, 0), "2026-06-21T05:00:00Z");
  EXPECT_NEAR(scene.envmap->sun_irradiance_rgb->x, 86.25683, 1e-9);
  EXPECT_EQ(scene.frames.kind, FrameSourceKind::kVideo);
  ASSERT_TRUE(scene.frame_times.has_value());
  EXPECT_EQ(scene.frame_times->frames.size(), 600u);
  ASSERT_EQ(scene.objects.size(), 2u);
  EXPECT_EQ(scene.objects[1].kind, MeshKind::kBox);
  EXPECT_DOUBLE_EQ(scene.objects[1].size.z, 1.0);
  ASSERT_TRUE(scene.volume.has_value());
  EXPECT_FALSE(scene.volume->defaulted);
  EXPECT_EQ(scene.volume->resolution, glm::ivec3(10, 8, 4));
  EXPECT_TRUE(scene.groundtruth.lighting.has_value());
  // The pose as scene.json writes it (world_to_camera R, t), worked out by hand: the centre
  // −Rᵀt = (1.2, 6.5, 1.75) m, and the principal ray, R's third row (0.0415, −0.9861, −0.1609),
  // meets the ground z = 0 at (1.65, −4.23) m, 10.9 m along it.
  const glm::dvec3 center = scene.Camera().CenterInWorld();
  EXPECT_NEAR(glm::distance(center, glm::dvec3(1.2, 6.5, 1.75)), 0.0, 1e-6);
  const glm::dvec3 ray = glm::normalize(scene.Camera().UnprojectToWorldRay({479.5, 269.5}));
  EXPECT_NEAR(glm::distance(ray, glm::dvec3(0.041519865, -0.986098647, -0.160889864)), 0.0, 1e-6);
  const glm::dvec3 ground = center + (-center.z / ray.z) * ray;
  EXPECT_NEAR(ground.x, 1.65, 0.01);
  EXPECT_NEAR(ground.y, -4.23, 0.01);
}

TEST(SceneLoaderTest, DefaultsFillOmittedFields) {
  SceneSandbox sandbox("defaults");
  nlohmann::json& j = sandbox.json();
  j.erase("name");
  j.erase("north_azimuth_deg");
  j["location"].erase("elevation_m");
  j["camera"].erase("distortion");
  j["camera"].erase("response");
  j["camera"].erase("exposure");
  j.erase("volume");
  j.erase("envmap");
  j.erase("groundtruth");
  const Scene scene = LoadScene(sandbox.Write());
  EXPECT_EQ(scene.name, sandbox.dir().filename().string());
  EXPECT_EQ(scene.north_azimuth_deg, 0.0);
  EXPECT_EQ(scene.location.elevation_m, 0.0);
  EXPECT_TRUE(scene.intrinsics.distortion.empty());
  EXPECT_EQ(scene.response.curve, capture::ResponseCurve::kSrgb);
  EXPECT_EQ(scene.exposure, 1.0);
  EXPECT_FALSE(scene.envmap.has_value());
  // Volume around the two objects: sphere r 0.5 at (-0.8,-2.2,0.5) and a box at (1.6,-0.6,0.5).
  ASSERT_TRUE(scene.volume.has_value());
  EXPECT_TRUE(scene.volume->defaulted);
  EXPECT_NEAR(scene.volume->min.x, -0.8 - 0.5 - 1.0, 1e-9);
  EXPECT_GE(scene.volume->resolution.x, 2);
}

TEST(SceneLoaderTest, PoseFromCorrespondencesMatchesTheGivenPose) {
  SceneSandbox sandbox("pnp");
  const Scene reference = LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const CameraModel camera = reference.Camera();
  nlohmann::json correspondences = nlohmann::json::array();
  // Corners of the courtyard's ground, walls and bench that the camera sees.
  for (const glm::dvec3 p : {glm::dvec3(-2, -3, 0), glm::dvec3(2, -3, 0), glm::dvec3(2, 0, 0),
                             glm::dvec3(-2, 0, 0), glm::dvec3(0, -2, 1), glm::dvec3(1, -4, 2),
                             glm::dvec3(-1.5, -1, 0.5), glm::dvec3(1.5, -2, 1.5)}) {
    const glm::dvec2 px = camera.Project(p);
    correspondences.push_back({{"world", {p.x, p.y, p.z}}, {"pixel", {px.x, px.y}}});
  }
  sandbox.json()["camera"]["correspondences"] = correspondences;
  sandbox.json()["camera"].erase("world_to_camera");
  const Scene solved = LoadScene(sandbox.Write());
  ASSERT_TRUE(solved.pose_fit.has_value());
  EXPECT_LT(solved.pose_fit->rms_reprojection_px, 1e-6);
  EXPECT_NEAR(glm::length(solved.Camera().CenterInWorld() - camera.CenterInWorld()), 0.0, 1e-6);
}

TEST(SceneLoaderTest, ImageSequenceAndLiveDeviceSources) {
  SceneSandbox sandbox("images");
  std::filesystem::create_directories(sandbox.dir() / "frames");
  sandbox.WriteText("frames/000000.png", "");  // the loader checks only that frame 0 exists
  sandbox.WriteText("times.csv", "frame,time_utc\n0,2026-06-21T05:00:00Z\n1,2026-06-21T05:00:00.1Z\n");
  sandbox.json()["frames"] = {{"images", "frames/%06d.png"}, {"timestamps", "times.csv"}};
  const Scene images = LoadScene(sandbox.Write());
  EXPECT_EQ(images.frames.kind, FrameSourceKind::kImages);
  EXPECT_EQ(images.frames.ImagePath(42), sandbox.dir() / "frames/000042.png");
  EXPECT_EQ(images.frame_times->frames.size(), 2u);

  sandbox.json()["frames"] = {{"device", "/dev/video0"}, {"fps", 25}};
  const Scene live = LoadScene(sandbox.Write());
  EXPECT_EQ(live.frames.kind, FrameSourceKind::kDevice);
  EXPECT_EQ(live.frames.device, "/dev/video0");
  EXPECT_EQ(live.frames.fps, 25.0);
  EXPECT_FALSE(live.frame_times.has_value());
}

// frames.clock_offset_s moves every frame's time (UTC = frames.csv + offset), so the sun of frame N
// is the ephemeris's at the corrected time; absent, nothing moves; beyond a day, refused by name.
TEST(SceneLoaderTest, AClockOffsetMovesEveryFramesTime) {
  SceneSandbox sandbox("clock");
  std::filesystem::create_directories(sandbox.dir() / "frames");
  sandbox.WriteText("frames/000000.png", "");
  sandbox.WriteText("times.csv", "frame,time_utc\n0,2026-06-21T05:00:00Z\n1,2026-06-21T23:59:59.5Z\n");
  sandbox.json()["frames"] = {{"images", "frames/%06d.png"}, {"timestamps", "times.csv"}};
  const Scene plain = LoadScene(sandbox.Write());
  EXPECT_EQ(plain.frames.clock_offset_s, 0.0);
  EXPECT_EQ(FormatUtcTime(plain.frame_times->frames[0].utc), "2026-06-21T05:00:00.000Z");

  sandbox.json()["frames"]["clock_offset_s"] = -90.25;
  const Scene early = LoadScene(sandbox.Write());
  EXPECT_EQ(FormatUtcTime(early.frame_times->frames[0].utc), "2026-06-21T04:58:29.750Z");
  sandbox.json()["frames"]["clock_offset_s"] = 0.75;
  const Scene late = LoadScene(sandbox.Write());
  EXPECT_EQ(FormatUtcTime(late.frame_times->frames[1].utc), "2026-06-22T00:00:00.250Z");  // over midnight
  EXPECT_EQ(FormatUtcTime(late.frame_times->frames[0].utc), "2026-06-21T05:00:00.750Z");

  for (double bad : {86400.5, -1e9}) {
    sandbox.json()["frames"]["clock_offset_s"] = bad;
    try {
      LoadScene(sandbox.Write());
      ADD_FAILURE() << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("frames.clock_offset_s"), std::string::npos) << e.what();
    }
  }
}

TEST(SceneLoaderTest, ACalibratedResponseCurveIsReadFromItsFile) {
  SceneSandbox sandbox("curve");
  std::string csv = "code,r,g,b\n";
  for (int i = 0; i < 256; ++i) csv += fmt::format("{},{},{},{}\n", i, 2.0 * i * i, i * i, 0.5 * i * i);
  sandbox.WriteText("response.csv", csv);
  sandbox.json()["camera"]["response"] = {{"curve", "response.csv"}};
  const Scene scene = LoadScene(sandbox.Write());
  ASSERT_EQ(scene.response.curve, capture::ResponseCurve::kTable);
  // Each channel scaled to 1 at code 255: all three are (code / 255)² here.
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(scene.response.ToLinear(128.0 / 255.0, c), std::pow(128.0 / 255.0, 2.0), 1e-9);
  sandbox.json()["camera"]["response"] = {{"curve", "missing.csv"}};
  EXPECT_THROW(LoadScene(sandbox.Write()), InputError);
}

struct BadScene {
  const char* what;
  std::function<void(nlohmann::json&, const SceneSandbox&)> edit;
  const char* expected;  // the error message after "<dir>/scene.json: "
};

class SceneLoaderBadInputTest : public ::testing::TestWithParam<BadScene> {};

TEST_P(SceneLoaderBadInputTest, NamesFileAndField) {
  SceneSandbox sandbox("bad");
  GetParam().edit(sandbox.json(), sandbox);
  const std::filesystem::path file = sandbox.Write();
  try {
    LoadScene(file);
    FAIL() << GetParam().what << ": no error";
  } catch (const InputError& e) {
    const std::string message = e.what();
    EXPECT_NE(message.find(GetParam().expected), std::string::npos)
        << GetParam().what << ": got: " << message;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

const BadScene kBadScenes[] = {
    {"missing field", [](auto& j, auto&) { j.erase("location"); }, "scene.json: location: missing"},
    {"wrong format", [](auto& j, auto&) { j["format"] = "daylit-recording/9"; },
     "format: 'daylit-recording/9' is not supported"},
    {"latitude 123", [](auto& j, auto&) { j["location"]["latitude_deg"] = 123; },
     "location: latitude_deg: 123 is outside [-90, 90]"},
    {"wrong type", [](auto& j, auto&) { j["camera"]["fx"] = "760"; },
     "camera.fx: expected a number, got string"},
    {"null number", [](auto& j, auto&) { j["north_azimuth_deg"] = nullptr; },
     "north_azimuth_deg: expected a number, got null"},
    {"negative focal length", [](auto& j, auto&) { j["camera"]["fy"] = -3; },
     "camera.fy: must be > 0 (got -3)"},
    // Numbers no camera, sun or scene has (issue 52): the principal point at 1e308 aborted Embree
    // 29 s into the bake; the others were accepted.
    {"principal point far off", [](auto& j, auto&) { j["camera"]["cx"] = 1e308; },
     "camera.cx: 1e+308 is outside [-"},
    {"focal length beyond any lens", [](auto& j, auto&) { j["camera"]["fy"] = 1e308; },
     "camera.fy: 1e+308 is outside [0, "},
    {"distortion beyond any lens", [](auto& j, auto&) { j["camera"]["distortion"] = {1e308, 0, 0, 0, 0}; },
     "camera.distortion: coefficient 1 is 1e+308, outside [-1000, 1000]"},
    {"north beyond a turn", [](auto& j, auto&) { j["north_azimuth_deg"] = 1e308; },
     "north_azimuth_deg: 1e+308 is outside [-360, 360]"},
    {"object turned beyond a turn", [](auto& j, auto&) { j["objects"][0]["rotation_deg"] = {0, 1e308, 0}; },
     "objects[0].rotation_deg: 1e+308 is outside [-360, 360]"},
    {"no frame rate", [](auto& j, auto&) { j["frames"]["fps"] = 0; },
     "frames.fps: 0 is outside [0.001, 1000]"},
    {"a sun beyond any map", [](auto& j, auto&) { j["envmap"]["sun_irradiance_rgb"] = {1e308, 1, 1}; },
     "envmap.sun_irradiance_rgb: 1e+308 is outside [0, 1e+09]"},
    {"a camera far away", [](auto& j, auto&) { j["camera"]["world_to_camera"]["translation"] = {0, 0, 1e12}; },
     "camera.world_to_camera.translation: 1e+12 m is beyond 10000 m of the scene's origin"},
    {"a capture point far away", [](auto& j, auto&) { j["envmap"]["position"] = {-1e300, 0, 0}; },
     "envmap.position: -1e+300 m is beyond 10000 m"},
    {"an absurd exposure", [](auto& j, auto&) { j["camera"]["exposure"] = 1e300; },
     "camera.exposure: 1e+300 is outside [0, 1e+09]"},
    {"unknown surface", [](auto& j, auto&) { j["diffuse_surfaces"][1] = "wal_*"; },
     "diffuse_surfaces[1]: 'wal_*' matches no surface of model.obj"},
    {"unreadable model", [](auto& j, auto&) { j["model"]["file"] = "missing.obj"; },
     "model.file: file '"},
    {"not a rotation", [](auto& j, auto&) { j["camera"]["world_to_camera"]["rotation"][0][0] = 0.5; },
     "camera.world_to_camera.rotation: not a rotation"},
    {"reflection", [](auto& j, auto&) {
       j["camera"]["world_to_camera"]["rotation"] = {{1, 0, 0}, {0, 1, 0}, {0, 0, -1}};
     }, "camera.world_to_camera.rotation: not a rotation (|RᵀR − I| = 0, det = -1)"},
    {"rotation shape", [](auto& j, auto&) { j["camera"]["world_to_camera"]["rotation"][2] = {1, 2}; },
     "camera.world_to_camera.rotation[2]: expected 3 numbers, got 2"},
    {"time without zone", [](auto& j, auto&) { j["envmap"]["time_utc"] = "2026-06-21T05:00:00"; },
     "envmap.time_utc: time has no zone"},
    {"two frame sources", [](auto& j, auto&) { j["frames"]["device"] = "/dev/video0"; },
     "frames: give exactly one of \"video\", \"images\" or \"device\""},
    {"bad image pattern", [](auto& j, auto&) {
       j["frames"].erase("video");
       j["frames"]["images"] = "frames/%s.png";
     }, "frames.images: 'frames/%s.png' must contain exactly one %d"},
    {"two conversions in the image pattern", [](auto& j, auto&) {
       j["frames"].erase("video");
       j["frames"]["images"] = "frames/%d_%06d.png";
     }, "frames.images: 'frames/%d_%06d.png' must contain exactly one %d"},
    {"bad response", [](auto& j, auto&) { j["camera"]["response"] = "log"; },
     "camera.response: 'log' is not a response"},
    {"bad distortion", [](auto& j, auto&) { j["camera"]["distortion"] = {0.1, 0.2}; },
     "camera.distortion: expected 4, 5, 8, 12 or 14 coefficients"},
    {"negative radius", [](auto& j, auto&) { j["objects"][0]["radius"] = -1; },
     "objects[0].radius: must be > 0 (got -1)"},
    {"unknown builtin", [](auto& j, auto&) { j["objects"][1]["mesh"] = "builtin:cone"; },
     "objects[1].mesh: 'builtin:cone' is not a builtin"},
    {"volume inverted", [](auto& j, auto&) { j["volume"]["max"][2] = -1; },
     "volume.max: must exceed min on every axis"},
    {"volume with no probes", [](auto& j, auto&) { j["volume"]["resolution"][1] = 0; },
     "volume.resolution[1]: 0 is outside [1, 256]"},
    {"volume with too many probes", [](auto& j, auto&) { j["volume"]["resolution"] = {64, 64, 64}; },
     "volume.resolution: 64×64×64 = 262144 probes; at most 32768"},
    {"too few correspondences", [](auto& j, auto&) {
       j["camera"]["correspondences"] = {{{"world", {0, 0, 0}}, {"pixel", {1, 2}}}};
     }, "camera.correspondences: at least 4 correspondences are needed, got 1"},
    {"OBJ with NaN vertex", [](auto& j, const SceneSandbox& s) {
       s.WriteText("nan.obj", "o ground\nv 0 0 0\nv nan 1 0\nv 1 1 0\nf 1 2 3\n");
       j["model"]["file"] = "nan.obj";
     }, "nan.obj:3: vertex coordinate x is not a finite number ('nan')"},
    {"OBJ face out of range", [](auto& j, const SceneSandbox& s) {
       s.WriteText("oob.obj", "o ground\nv 0 0 0\nv 1 1 0\nv 1 0 0\nf 1 2 9\n");
       j["model"]["file"] = "oob.obj";
     }, "oob.obj: Vertex indices out of bounds"},
    {"OBJ face of two vertices", [](auto& j, const SceneSandbox& s) {
       s.WriteText("two.obj", "o ground\nv 0 0 0\nv 1 1 0\nv 1 0 0\nf 1 2 3\nf 1 2\n");
       j["model"]["file"] = "two.obj";
     }, "two.obj:6: a face needs at least 3 vertices, this one has 2"},
    {"OBJ negative index before the start", [](auto& j, const SceneSandbox& s) {
       s.WriteText("neg.obj", "o ground\nv 0 0 0\nv 1 1 0\nf -1 -2 -3\nv 1 0 0\n");
       j["model"]["file"] = "neg.obj";
     }, "neg.obj:4: face vertex -3 reaches before the first vertex (2 defined so far)"},
    {"OBJ index 0", [](auto& j, const SceneSandbox& s) {
       s.WriteText("zero.obj", "o ground\nv 0 0 0\nv 1 1 0\nv 1 0 0\nf 0/1 1/2 2/3\n");
       j["model"]["file"] = "zero.obj";
     }, "zero.obj:5: face vertex '0/1' is not a vertex index"},
    {"model path outside the folder", [](auto& j, auto&) { j["model"]["file"] = "/etc/passwd"; },
     "model.file: '/etc/passwd' is outside the recording folder"},
    {"video path climbing out", [](auto& j, auto&) { j["frames"]["video"] = "frames/../../x/video.mp4"; },
     "frames.video: 'frames/../../x/video.mp4' is outside the recording folder"},
    {"frames.csv without zone", [](auto& j, const SceneSandbox& s) {
       s.WriteText("frames_bad.csv", "frame,time_utc\n0,2026-06-21T05:00:00\n");
       j["frames"]["timestamps"] = "frames_bad.csv";
     }, "frames_bad.csv:2: time_utc: time has no zone"},
};

INSTANTIATE_TEST_SUITE_P(Table, SceneLoaderBadInputTest, ::testing::ValuesIn(kBadScenes),
                         [](const ::testing::TestParamInfo<BadScene>& param_info) {
                           std::string name = param_info.param.what;
                           for (char& c : name) {
                             if (!std::isalnum(static_cast<unsigned char>(c))) c = '_';
                           }
                           return name;
                         });

TEST(SceneLoaderTest, PathsOutsideTheFolderOnlyWhenAllowed) {
  // The same file named by an absolute path: refused, then followed with the option (daylit
  // --allow-outside-paths); a path that goes down and back up again stays inside.
  SceneSandbox sandbox("outside");
  sandbox.json()["model"]["file"] = (sandbox.dir() / "model.obj").string();
  const std::filesystem::path file = sandbox.Write();
  EXPECT_THROW(LoadScene(file), InputError);
  AllowPathsOutsideRecording(true);
  EXPECT_NO_THROW(LoadScene(file));
  AllowPathsOutsideRecording(false);
  sandbox.json()["model"]["file"] = "groundtruth/../model.obj";
  EXPECT_NO_THROW(LoadScene(sandbox.Write()));
}

TEST(SceneLoaderTest, MalformedJsonNamesLineAndColumn) {
  SceneSandbox sandbox("malformed");
  const std::filesystem::path file = sandbox.WriteText("scene.json", "{\n \"format\": \"daylit-recording/1\",\n \"location\": {,\n}\n");
  try {
    LoadScene(file);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json: invalid JSON"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(LoadScene(sandbox.dir() / "nothing.json"), InputError);
}

TEST(SceneLoaderTest, NumbersBeyondDoubleRangeAreRejected) {
  SceneSandbox sandbox("overflow");
  std::string text = sandbox.json().dump(1);
  text.replace(text.find("\"north_azimuth_deg\": -20.0"), 26, "\"north_azimuth_deg\": 1e999");
  const std::filesystem::path file = sandbox.WriteText("scene.json", text);
  try {
    LoadScene(file);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("scene.json: invalid JSON"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("1e999"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace daylit::scene
