// A recording's scene.json (format daylit-recording/1, docs/recording-format.md), loaded and
// validated: every path resolved against the recording folder, every field checked.
#pragma once

#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include "base/utc_time.h"
#include "capture/frame_source.h"
#include "capture/frame_times.h"
#include "capture/response.h"
#include "capture/v4l2_source.h"
#include "scene/camera.h"
#include "scene/model.h"
#include "sunmodel/geo_frame.h"
#include "sunmodel/solar_position.h"

namespace daylit::scene {

inline constexpr const char* kRecordingFormat = "daylit-recording/1";

struct EnvMapSpec {
  std::filesystem::path file;   // OpenEXR or Radiance .hdr, lat-long
  glm::dvec3 position{0.0};     // capture point, scene coordinates (m)
  UtcTime time_utc;             // capture time
  std::optional<glm::dvec3> sun_irradiance_rgb;  // sun DNI at capture, map units
};

enum class FrameSourceKind { kVideo, kImages, kDevice };

struct FramesSpec {
  FrameSourceKind kind = FrameSourceKind::kVideo;
  std::filesystem::path video;       // kVideo
  std::string image_pattern;         // kImages: absolute path with one %d / %0Nd
  std::filesystem::path timestamps;  // kVideo, kImages
  std::string device;                // kDevice, e.g. /dev/video0
  double fps = 30.0;                 // kDevice
  double clock_offset_s = 0.0;       // UTC = the frames' clock (frames.csv, a device's) + this
  capture::CameraSettings controls;  // kDevice: exposure, gain, white balance (absent: held from auto)

  // The image file of frame `index` (kImages only).
  std::filesystem::path ImagePath(int index) const;
};

enum class MeshKind { kSphere, kBox, kFile };

struct VirtualObject {
  MeshKind kind = MeshKind::kSphere;
  std::filesystem::path file;       // kFile: glTF 2.0 (.gltf/.glb) or OBJ
  double radius = 0.0;              // kSphere, m
  glm::dvec3 size{0.0};             // kBox: full edge lengths, m
  glm::dvec3 position{0.0};         // centre, scene coordinates (m)
  glm::dvec3 rotation_deg{0.0};     // XYZ Euler, R = Rz·Ry·Rx
  glm::dvec3 scale{1.0};
  std::optional<glm::dvec3> albedo;  // override, each in [0, 1]
  // kFile: the folder its glTF buffers and images must lie in (the recording's), empty for
  // anywhere (daylit --allow-outside-paths).
  std::filesystem::path resource_root;

  // Radius of a sphere around `position` that holds the object (mesh files: 1 m × scale until
  // the mesh is loaded by the renderer).
  double BoundingRadius() const;
};

struct VolumeSpec {
  glm::dvec3 min{0.0}, max{0.0};  // scene coordinates (m)
  glm::ivec3 resolution{2};       // probes per axis, each ≥ 2
  bool defaulted = false;         // true when derived from the objects
};
// How far from the scene's origin, and how large, a virtual object may be (m): a courtyard's
// statue, not a planet; past this the ray tracer's single-precision rays lose the object.
inline constexpr double kMaxObjectExtent = 1e4;
// The smallest size a virtual object may have (m).
inline constexpr double kMinObjectSize = 1e-4;
// The most probes a volume may have along one axis (scene.json, and a bake cache's gather tables).
inline constexpr int kMaxVolumeResolution = 256;

struct GroundTruthSpec {
  std::optional<std::filesystem::path> lighting;    // groundtruth.csv
  std::optional<std::filesystem::path> composites;  // groundtruth/ folder
};

struct Scene {
  std::filesystem::path file;    // the scene.json
  std::filesystem::path folder;  // where relative paths start
  std::string name;

  sunmodel::GeoSite location;
  double north_azimuth_deg = 0.0;

  SceneModel model;
  std::vector<std::string> diffuse_globs;
  std::vector<int> diffuse_surfaces;  // surface indices matched by diffuse_globs
  std::optional<std::filesystem::path> diffuse_mask;

  CameraIntrinsics intrinsics;
  RigidPose cam_from_world;
  std::optional<PoseFit> pose_fit;  // set when the pose was solved from correspondences
  capture::CameraResponse response;
  std::optional<std::filesystem::path> response_table;  // {"curve": "response.csv"}
  double exposure = 1.0;

  std::optional<EnvMapSpec> envmap;
  FramesSpec frames;
  std::optional<capture::FrameTimes> frame_times;  // recordings (not live devices)
  std::vector<VirtualObject> objects;
  std::optional<VolumeSpec> volume;  // absent only with neither `volume` nor objects
  GroundTruthSpec groundtruth;

  CameraModel Camera() const { return CameraModel(intrinsics, cam_from_world); }
  sunmodel::SceneGeoFrame GeoFrame() const { return {location, north_azimuth_deg}; }
};

// The sun at `utc` over the scene's site (standard atmosphere at the site's height): its position
// and its unit direction in scene coordinates.
struct SceneSun {
  sunmodel::SunPosition position;
  glm::dvec3 dir{0.0, 0.0, 1.0};
};
SceneSun SunAt(const Scene& scene, const UtcTime& utc);

// Every file and folder the scene reads: scene.json, the model, the diffuse mask, the response
// table, the env map, the video and frames.csv (or every frame's image), the objects' mesh files
// and the ground truth (its CSV and its folder, whose every file counts). The commands refuse to
// write an output over any of them (apps/daylit/outputs.cc).
struct SceneInputs {
  std::vector<std::filesystem::path> files;
  std::vector<std::filesystem::path> folders;  // everything inside them is read
};
SceneInputs InputsOf(const Scene& scene);

// Loads `path` (a scene.json, or a recording folder holding one), the OBJ model it names and
// its frames.csv, and checks every field. Throws InputError "<file>: <field>: <problem>".
Scene LoadScene(const std::filesystem::path& path);
// Paths in scene.json that leave its folder (absolute ones, or "../x") are refused (InputError
// naming the field) unless this is set (daylit --allow-outside-paths). Process-wide.
void AllowPathsOutsideRecording(bool allow);

// The scene's frames as a FrameSource: its video or image sequence with frames.csv (exposures
// falling back to camera.exposure), or its live device.
std::unique_ptr<capture::FrameSource> OpenFrameSource(const Scene& scene);

// The position in frames.csv of frame number `frame` (as frames.csv names it). Throws InputError
// "<option>: <frame> is not in <frames.csv>", or "<scene.json>: frames: a live device has no
// recorded frames".
size_t FramePosition(const Scene& scene, int frame, std::string_view option);

// The frame rate a video of the scene's frames plays at: a device's `fps`, else one over the
// median step of frames.csv (a recording may come in bursts; its times stay the truth).
double NominalFps(const Scene& scene);

}  // namespace daylit::scene
