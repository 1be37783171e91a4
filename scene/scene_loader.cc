#include <algorithm>
#include <cmath>
#include <limits>

#include "base/error.h"
#include "base/files.h"
#include "base/log.h"
#include "base/statistics.h"
#include "capture/frame_source.h"
#include "capture/v4l2_source.h"
#include "scene/json_fields.h"
#include "scene/object_mesh.h"
#include "scene/scene.h"

namespace daylit::scene {
namespace {

namespace fs = std::filesystem;

// A number of scene.json within [lo, hi], else the field's one-line error naming the range and
// what it means. Everything downstream (the bake's rays, the GL, float maps) assumes such sizes.
double InRange(const JsonField& field, double value, double lo, double hi, const std::string& meaning) {
  if (!(value >= lo && value <= hi)) field.Fail(fmt::format("{:g} is outside [{:g}, {:g}] ({})", value, lo, hi, meaning));
  return value;
}

// A point of the scene: each coordinate within kMaxObjectExtent of the origin.
glm::dvec3 ScenePoint(const JsonField& field) {
  const glm::dvec3 p = field.Vec3();
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(p[i]) <= kMaxObjectExtent)) {
      field.Fail(fmt::format("{:g} m is beyond {:g} m of the scene's origin", p[i], kMaxObjectExtent));
    }
  }
  return p;
}

// Tolerance on |RᵀR − I| for a rotation typed with ~9 significant digits.
constexpr double kRotationTolerance = 1e-5;
constexpr double kMaxClockOffsetS = 86400.0;  // frames.clock_offset_s: a clock a day off is not a drift

bool allow_paths_outside = false;

// The path `field` names (`relative`: its text, or a pattern made from it), against the
// recording folder. One that leaves the folder (absolute, or climbing out with "..") is refused
// unless AllowPathsOutsideRecording(true): a recording made by someone else must not make daylit
// read /etc/passwd. The check is lexical; symbolic links inside the folder are followed.
fs::path Resolve(const Scene& scene, const JsonField& field, const std::string& relative) {
  const fs::path p(relative);
  const fs::path path = p.is_absolute() ? p : scene.folder / p;
  if (!allow_paths_outside) {
    const fs::path inside = p.lexically_normal();
    const bool leaves = p.is_absolute() || inside.empty() || *inside.begin() == "..";
    if (leaves) {
      field.Fail(fmt::format("'{}' is outside the recording folder {} (daylit --allow-outside-paths allows it)",
                             relative, scene.folder.string()));
    }
  }
  return path;
}

// The path a field names, which must exist as a regular file.
fs::path RequireFile(const Scene& scene, const JsonField& field) {
  const std::string relative = field.String();
  const fs::path path = Resolve(scene, field, relative);
  const std::string why = WhyNotAFile(path);
  if (why == "no such file") field.Fail(fmt::format("file '{}' not found", path.string()));
  if (!why.empty()) field.Fail(fmt::format("'{}' {}", path.string(), why));
  return path;
}

void LoadLocation(const JsonField& root, Scene* scene) {
  const JsonField location = root.Get("location");
  location.WarnUnknownKeys({"latitude_deg", "longitude_deg", "elevation_m"});
  scene->location.latitude_deg = location.Get("latitude_deg").Number();
  scene->location.longitude_deg = location.Get("longitude_deg").Number();
  if (auto e = location.Find("elevation_m")) scene->location.elevation_m = e->Number();
  if (const std::string why = scene->location.Check(); !why.empty()) location.Fail(why);
  if (auto n = root.Find("north_azimuth_deg")) {
    scene->north_azimuth_deg = InRange(*n, n->Number(), -360.0, 360.0, "an angle in degrees");
  }
}

void LoadModelAndSurfaces(const JsonField& root, Scene* scene) {
  const JsonField model = root.Get("model");
  model.WarnUnknownKeys({"file"});
  const JsonField file = model.Get("file");
  scene->model = LoadObjModel(RequireFile(*scene, file));

  if (auto mask = root.Find("diffuse_mask")) scene->diffuse_mask = RequireFile(*scene, *mask);
  const std::optional<JsonField> globs = root.Find("diffuse_surfaces");
  if (!globs && !scene->diffuse_mask) {
    root.Get("diffuse_surfaces");  // throws "missing": one of the two is needed
  }
  if (!globs) return;
  if (globs->Elements().empty() && !scene->diffuse_mask) {
    globs->Fail("empty: name at least one surface whose pixels the estimation may use (or give diffuse_mask)");
  }
  for (const JsonField& g : globs->Elements()) {
    const std::string glob = g.String();
    const std::vector<int> matched = scene->model.MatchSurfaces(glob);
    if (matched.empty()) {
      std::string names;
      for (const std::string& n : scene->model.surface_names) names += (names.empty() ? "" : ", ") + n;
      g.Fail(fmt::format("'{}' matches no surface of {} (surfaces: {})", glob,
                         scene->model.file.filename().string(), names));
    }
    scene->diffuse_globs.push_back(glob);
    for (const int s : matched) {
      if (std::find(scene->diffuse_surfaces.begin(), scene->diffuse_surfaces.end(), s) ==
          scene->diffuse_surfaces.end()) {
        scene->diffuse_surfaces.push_back(s);
      }
    }
  }
}

capture::CameraResponse LoadResponse(Scene& scene, const JsonField& field) {
  capture::CameraResponse response;
  if (field.IsString()) {
    const std::string name = field.String();
    if (name == "srgb") return response;
    if (name == "linear") {
      response.curve = capture::ResponseCurve::kLinear;
      return response;
    }
    field.Fail(fmt::format("'{}' is not a response: use \"linear\", \"srgb\" or {{\"gamma\": g}}", name));
  }
  if (!field.IsObject()) field.Fail("expected \"linear\", \"srgb\", {\"gamma\": g} or {\"curve\": \"response.csv\"}");
  if (auto curve = field.Find("curve")) {
    response.curve = capture::ResponseCurve::kTable;
    const fs::path table = RequireFile(scene, *curve);
    response.table = capture::ReadResponseTable(table);
    scene.response_table = table;
    return response;
  }
  const JsonField gamma = field.Get("gamma");
  response.curve = capture::ResponseCurve::kGamma;
  response.gamma = gamma.Number();
  if (response.gamma < 0.1 || response.gamma > 10.0) {
    gamma.Fail(fmt::format("{} is outside [0.1, 10]", response.gamma));
  }
  return response;
}

void LoadPose(const JsonField& camera, Scene* scene) {
  if (auto correspondences = camera.Find("correspondences")) {
    std::vector<glm::dvec3> world;
    std::vector<glm::dvec2> pixels;
    for (const JsonField& c : correspondences->Elements()) {
      world.push_back(ScenePoint(c.Get("world")));
      const std::vector<double> px = c.Get("pixel").Numbers();
      if (px.size() != 2) c.Get("pixel").Fail(fmt::format("expected 2 numbers, got {}", px.size()));
      pixels.emplace_back(px[0], px[1]);
    }
    PoseFit fit;
    std::string why;
    if (!SolvePoseFromCorrespondences(scene->intrinsics, world, pixels, &fit, &why)) {
      correspondences->Fail(why);
    }
    if (camera.Has("world_to_camera")) {
      Log().info("{}: camera: pose solved from correspondences; world_to_camera ignored",
                 scene->file.string());
    }
    scene->cam_from_world = fit.cam_from_world;
    scene->pose_fit = fit;
    return;
  }
  const JsonField pose = camera.Get("world_to_camera");
  pose.WarnUnknownKeys({"rotation", "translation"});
  const JsonField rotation = pose.Get("rotation");
  const glm::dmat3 r = rotation.Matrix3();
  if (!IsRotation(r, kRotationTolerance)) {
    rotation.Fail(fmt::format("not a rotation (|RᵀR − I| = {:.3g}, det = {:.6g})",
                              OrthonormalityError(r), glm::determinant(r)));
  }
  scene->cam_from_world.rotation = NearestRotation(r);
  scene->cam_from_world.translation = ScenePoint(pose.Get("translation"));
}

void LoadCamera(const JsonField& root, Scene* scene) {
  const JsonField camera = root.Get("camera");
  camera.WarnUnknownKeys({"width", "height", "fx", "fy", "cx", "cy", "distortion",
                          "world_to_camera", "correspondences", "response", "exposure"});
  CameraIntrinsics& k = scene->intrinsics;
  for (const auto& [key, value] : {std::pair{"width", &k.width}, std::pair{"height", &k.height}}) {
    const JsonField f = camera.Get(key);
    *value = f.Integer();
    if (*value <= 0 || *value > 16384) f.Fail(fmt::format("{} is outside [1, 16384]", *value));
  }
  // A focal length of 1000 times the image's larger side is a field of view of 0.06°; the principal
  // point lies within one image size of the image.
  const double side = std::max(k.width, k.height);
  for (const auto& [key, value] : {std::pair{"fx", &k.fx}, std::pair{"fy", &k.fy}}) {
    const JsonField f = camera.Get(key);
    *value = f.Number();
    if (*value <= 0.0) f.Fail(fmt::format("must be > 0 (got {})", *value));
    InRange(f, *value, 0.0, 1000.0 * side, "pixels: at most 1000 times the image's larger side");
  }
  const JsonField cx = camera.Get("cx"), cy = camera.Get("cy");
  k.cx = InRange(cx, cx.Number(), -k.width, 2.0 * k.width, "pixels: within one image width of the image");
  k.cy = InRange(cy, cy.Number(), -k.height, 2.0 * k.height, "pixels: within one image height of the image");
  if (auto d = camera.Find("distortion")) {
    k.distortion = d->Numbers();
    const size_t n = k.distortion.size();
    if (n != 0 && n != 4 && n != 5 && n != 8 && n != 12 && n != 14) {
      d->Fail(fmt::format("expected 4, 5, 8, 12 or 14 coefficients (k1, k2, p1, p2, k3, ...), got {}", n));
    }
    // OpenCV's models (radial k1-k6, tangential p1-p2, thin prism s1-s4, tilt τx-τy): calibrated
    // lenses, fisheyes in the rational model included, stay within ±1000.
    for (size_t i = 0; i < n; ++i) {
      if (!(std::abs(k.distortion[i]) <= 1000.0)) {
        d->Fail(fmt::format("coefficient {} is {:g}, outside [-1000, 1000] (OpenCV's distortion models)", i + 1,
                            k.distortion[i]));
      }
    }
  }
  if (auto response = camera.Find("response")) scene->response = LoadResponse(*scene, *response);
  if (auto exposure = camera.Find("exposure")) {
    scene->exposure = exposure->Number();
    if (scene->exposure <= 0.0) exposure->Fail(fmt::format("must be > 0 (got {})", scene->exposure));
    InRange(*exposure, scene->exposure, 0.0, 1e9, "linear pixel value per radiance unit");
  }
  LoadPose(camera, scene);
}

void LoadEnvMap(const JsonField& root, Scene* scene) {
  const std::optional<JsonField> env = root.Find("envmap");
  if (!env) return;
  env->WarnUnknownKeys({"file", "position", "time_utc", "sun_irradiance_rgb"});
  EnvMapSpec spec;
  const JsonField file = env->Get("file");
  spec.file = RequireFile(*scene, file);
  const std::string ext = spec.file.extension().string();
  if (ext != ".exr" && ext != ".hdr") file.Fail("expected an OpenEXR (.exr) or Radiance (.hdr) file");
  spec.position = ScenePoint(env->Get("position"));
  const JsonField time = env->Get("time_utc");
  spec.time_utc = ParseUtcTime(time.String(), fmt::format("{}: {}", scene->file.string(), time.path()));
  if (auto sun = env->Find("sun_irradiance_rgb")) {
    spec.sun_irradiance_rgb = sun->Vec3();
    for (int c = 0; c < 3; ++c) {
      // 1e9: far beyond any sun in any map's units, and its products stay finite in float.
      InRange(*sun, (*spec.sun_irradiance_rgb)[c], 0.0, 1e9, "the sun's DNI in the map's units");
    }
  }
  scene->envmap = spec;
}

// Checks a printf pattern with exactly one integer conversion (%d or %0Nd) and no other %.
bool IsFramePattern(const std::string& pattern) {
  const size_t percent = pattern.find('%');
  if (percent == std::string::npos || pattern.find('%', percent + 1) != std::string::npos) return false;
  size_t i = percent + 1;
  if (i < pattern.size() && pattern[i] == '0') ++i;
  if (i < pattern.size() && pattern[i] >= '1' && pattern[i] <= '9') ++i;
  return i < pattern.size() && pattern[i] == 'd';
}

void LoadFrames(const JsonField& root, Scene* scene) {
  const JsonField frames = root.Get("frames");
  frames.WarnUnknownKeys({"video", "images", "timestamps", "device", "fps", "controls", "clock_offset_s"});
  FramesSpec& spec = scene->frames;
  if (auto offset = frames.Find("clock_offset_s")) {
    spec.clock_offset_s = offset->Number();
    if (!(std::abs(spec.clock_offset_s) <= kMaxClockOffsetS)) {
      offset->Fail(fmt::format("{} is outside [-{}, {}] (a day)", spec.clock_offset_s, kMaxClockOffsetS, kMaxClockOffsetS));
    }
  }
  // A rate only a live device uses (docs/recording-format.md), but never an absurd one.
  if (auto fps = frames.Find("fps")) InRange(*fps, fps->Number(), 1e-3, 1000.0, "frames per second");
  const int kinds = frames.Has("video") + frames.Has("images") + frames.Has("device");
  if (kinds != 1) frames.Fail("give exactly one of \"video\", \"images\" or \"device\"");
  if (auto device = frames.Find("device")) {
    spec.kind = FrameSourceKind::kDevice;
    spec.device = device->String();
    if (auto fps = frames.Find("fps")) spec.fps = fps->Number();
    if (auto controls = frames.Find("controls")) {
      controls->WarnUnknownKeys({"exposure_100us", "gain", "white_balance_k"});
      const auto integer = [&](const char* key, std::optional<int64_t>* out) {
        if (auto f = controls->Find(key)) {
          *out = f->Integer();
          if (**out < 0) f->Fail(fmt::format("{} is negative", **out));
        }
      };
      integer("exposure_100us", &spec.controls.exposure_100us);
      integer("gain", &spec.controls.gain);
      integer("white_balance_k", &spec.controls.white_balance_k);
    }
    return;
  }
  if (auto video = frames.Find("video")) {
    spec.kind = FrameSourceKind::kVideo;
    spec.video = RequireFile(*scene, *video);
  } else {
    const JsonField images = frames.Get("images");
    spec.kind = FrameSourceKind::kImages;
    const std::string pattern = images.String();
    if (!IsFramePattern(pattern)) {
      images.Fail(fmt::format("'{}' must contain exactly one %d or %0Nd (e.g. frames/%06d.png)", pattern));
    }
    spec.image_pattern = Resolve(*scene, images, pattern).string();
    if (!fs::is_regular_file(spec.ImagePath(0))) {
      images.Fail(fmt::format("frame 0 ('{}') not found", spec.ImagePath(0).string()));
    }
  }
  spec.timestamps = RequireFile(*scene, frames.Get("timestamps"));
  scene->frame_times = capture::LoadFrameTimes(spec.timestamps);
  if (spec.clock_offset_s != 0.0) {
    for (capture::FrameTime& f : scene->frame_times->frames) f.utc = ShiftedUtc(f.utc, spec.clock_offset_s);
  }
}

// Every vertex of the placed mesh within kMaxObjectExtent of the origin, and the object at least
// kMinObjectSize across.
void CheckObjectExtent(const JsonField& o, const Mesh& mesh, const VirtualObject& object) {
  const auto largest = [](const glm::dvec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  glm::dvec3 lo(std::numeric_limits<double>::max()), hi(-std::numeric_limits<double>::max());
  for (const glm::vec3& p : mesh.positions) {
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      o.Fail(fmt::format("placed by its position, rotation and scale, a vertex is not a finite number"));
    }
    lo = glm::min(lo, glm::dvec3(p)), hi = glm::max(hi, glm::dvec3(p));
  }
  const double far = std::max({largest(lo), largest(hi), largest(object.position)});
  if (far > kMaxObjectExtent) {
    o.Fail(fmt::format("reaches {:.3g} m from the scene's origin; a virtual object must lie within {:g} m", far, kMaxObjectExtent));
  }
  if (largest(hi - lo) < kMinObjectSize) {
    o.Fail(fmt::format("is {:.3g} m across; a virtual object must be at least {:g} m", largest(hi - lo), kMinObjectSize));
  }
}

void LoadObjects(const JsonField& root, Scene* scene) {
  const std::optional<JsonField> objects = root.Find("objects");
  if (!objects) return;
  for (const JsonField& o : objects->Elements()) {
    o.WarnUnknownKeys({"mesh", "radius", "size", "position", "rotation_deg", "scale", "albedo", "name"});
    VirtualObject object;
    const JsonField mesh = o.Get("mesh");
    const std::string kind = mesh.String();
    if (kind == "builtin:sphere") {
      object.kind = MeshKind::kSphere;
      const JsonField radius = o.Get("radius");
      object.radius = radius.Number();
      if (object.radius <= 0.0) radius.Fail(fmt::format("must be > 0 (got {})", object.radius));
    } else if (kind == "builtin:box") {
      object.kind = MeshKind::kBox;
      const JsonField size = o.Get("size");
      object.size = size.Vec3();
      if (glm::any(glm::lessThanEqual(object.size, glm::dvec3(0.0)))) size.Fail("every edge must be > 0");
    } else if (kind.rfind("builtin:", 0) == 0) {
      mesh.Fail(fmt::format("'{}' is not a builtin: use builtin:sphere or builtin:box", kind));
    } else {
      object.kind = MeshKind::kFile;
      object.file = RequireFile(*scene, mesh);
      if (!allow_paths_outside) object.resource_root = scene->folder;
      const std::string ext = object.file.extension().string();
      if (ext != ".gltf" && ext != ".glb" && ext != ".obj") {
        mesh.Fail("expected a glTF 2.0 (.gltf, .glb) or OBJ (.obj) file");
      }
    }
    if (auto p = o.Find("position")) object.position = p->Vec3();
    if (auto r = o.Find("rotation_deg")) {
      object.rotation_deg = r->Vec3();
      for (int i = 0; i < 3; ++i) InRange(*r, object.rotation_deg[i], -360.0, 360.0, "Euler angles in degrees");
    }
    if (auto s = o.Find("scale")) {
      object.scale = s->value().is_number() ? glm::dvec3(s->Number()) : s->Vec3();
      if (glm::any(glm::lessThanEqual(object.scale, glm::dvec3(0.0)))) s->Fail("must be > 0");
    }
    if (auto a = o.Find("albedo")) {
      object.albedo = a->Vec3();
      if (glm::any(glm::lessThan(*object.albedo, glm::dvec3(0.0))) ||
          glm::any(glm::greaterThan(*object.albedo, glm::dvec3(1.0)))) {
        a->Fail("each channel must be in [0, 1]");
      }
    }
    // Read the mesh now: a damaged file (or one that is a planet, or far away) is said here, by
    // every command, not after a bake or inside the ray tracer.
    CheckObjectExtent(o, ObjectMesh(object), object);
    scene->objects.push_back(object);
  }
}

// Probes every 0.5 m over the objects' bounds plus 1 m (shadows and contact light), 2..32 per axis.
VolumeSpec DefaultVolume(const std::vector<VirtualObject>& objects) {
  VolumeSpec v;
  v.min = glm::dvec3(1e300);
  v.max = glm::dvec3(-1e300);
  for (const VirtualObject& o : objects) {
    v.min = glm::min(v.min, o.position - glm::dvec3(o.BoundingRadius() + 1.0));
    v.max = glm::max(v.max, o.position + glm::dvec3(o.BoundingRadius() + 1.0));
  }
  const glm::dvec3 extent = v.max - v.min;
  for (int a = 0; a < 3; ++a) {
    v.resolution[a] = std::clamp(static_cast<int>(std::ceil(extent[a] / 0.5)) + 1, 2, 32);
  }
  v.defaulted = true;
  return v;
}

constexpr long long kMaxProbes = 32768;

void LoadVolume(const JsonField& root, Scene* scene) {
  const std::optional<JsonField> volume = root.Find("volume");
  if (!volume) {
    if (!scene->objects.empty()) scene->volume = DefaultVolume(scene->objects);
    return;
  }
  volume->WarnUnknownKeys({"min", "max", "resolution"});
  VolumeSpec v;
  v.min = volume->Get("min").Vec3();
  v.max = volume->Get("max").Vec3();
  if (glm::any(glm::greaterThanEqual(v.min, v.max))) volume->Get("max").Fail("must exceed min on every axis");
  const JsonField resolution = volume->Get("resolution");
  const std::vector<JsonField> r = resolution.Elements();
  if (r.size() != 3) resolution.Fail(fmt::format("expected 3 integers, got {}", r.size()));
  for (int a = 0; a < 3; ++a) {
    v.resolution[a] = r[static_cast<size_t>(a)].Integer();
    if (v.resolution[a] < 1 || v.resolution[a] > kMaxVolumeResolution) {
      r[static_cast<size_t>(a)].Fail(fmt::format("{} is outside [1, {}]", v.resolution[a], kMaxVolumeResolution));
    }
  }
  // Each probe gathers 512 rays in the bake and 512 texels every frame.
  const long long probes = static_cast<long long>(v.resolution.x) * v.resolution.y * v.resolution.z;
  if (probes > kMaxProbes) {
    resolution.Fail(fmt::format("{}×{}×{} = {} probes; at most {}", v.resolution.x, v.resolution.y, v.resolution.z,
                                probes, kMaxProbes));
  }
  // Objects placed where the model is not get light the model cannot know (no walls, no ground
  // to shade or reflect): allowed, but said.
  glm::vec3 lo, hi;
  scene->model.Bounds(&lo, &hi);
  if (glm::any(glm::greaterThan(glm::vec3(v.min), hi)) || glm::any(glm::lessThan(glm::vec3(v.max), lo))) {
    Log().warn("{}: volume: the box ({}, {}, {})-({}, {}, {}) lies outside the model's bounds ({:.2f}, {:.2f}, "
               "{:.2f})-({:.2f}, {:.2f}, {:.2f}); its probes see no model around them",
               scene->file.string(), v.min.x, v.min.y, v.min.z, v.max.x, v.max.y, v.max.z, lo.x, lo.y, lo.z, hi.x,
               hi.y, hi.z);
  }
  scene->volume = v;
}

void LoadGroundTruth(const JsonField& root, Scene* scene) {
  const std::optional<JsonField> gt = root.Find("groundtruth");
  if (!gt) return;
  gt->WarnUnknownKeys({"lighting", "composites"});
  if (auto lighting = gt->Find("lighting")) scene->groundtruth.lighting = RequireFile(*scene, *lighting);
  if (auto composites = gt->Find("composites")) {
    const fs::path folder = Resolve(*scene, *composites, composites->String());
    if (!fs::is_directory(folder)) composites->Fail(fmt::format("folder '{}' not found", folder.string()));
    scene->groundtruth.composites = folder;
  }
}

}  // namespace

fs::path FramesSpec::ImagePath(int index) const { return capture::FramePath(image_pattern, index); }

SceneInputs InputsOf(const Scene& scene) {
  SceneInputs in;
  in.files = {scene.file, scene.model.file};
  if (scene.diffuse_mask) in.files.push_back(*scene.diffuse_mask);
  if (scene.response_table) in.files.push_back(*scene.response_table);
  if (scene.envmap) in.files.push_back(scene.envmap->file);
  if (scene.frames.kind == FrameSourceKind::kVideo) in.files.push_back(scene.frames.video);
  if (scene.frames.kind != FrameSourceKind::kDevice) in.files.push_back(scene.frames.timestamps);
  if (scene.frames.kind == FrameSourceKind::kImages && scene.frame_times) {
    for (const capture::FrameTime& t : scene.frame_times->frames) in.files.push_back(scene.frames.ImagePath(t.index));
  }
  for (const VirtualObject& o : scene.objects) {
    if (o.kind == MeshKind::kFile) in.files.push_back(o.file);
  }
  if (scene.groundtruth.lighting) in.files.push_back(*scene.groundtruth.lighting);
  if (scene.groundtruth.composites) in.folders.push_back(*scene.groundtruth.composites);
  return in;
}

std::unique_ptr<capture::FrameSource> OpenFrameSource(const Scene& scene) {
  switch (scene.frames.kind) {
    case FrameSourceKind::kVideo: return capture::OpenVideoSource(scene.frames.video, *scene.frame_times, scene.exposure);
    case FrameSourceKind::kImages:
      return capture::OpenImageSequence(scene.frames.image_pattern, *scene.frame_times, scene.exposure);
    case FrameSourceKind::kDevice: break;
  }
  capture::V4l2Options options;
  options.width = scene.intrinsics.width, options.height = scene.intrinsics.height;
  options.fps = scene.frames.fps;
  options.settings = scene.frames.controls;
  options.exposure = scene.exposure;
  options.newest_only = true;  // estimate and live run on what the camera sees now
  std::unique_ptr<capture::FrameSource> source = capture::OpenV4l2Source(scene.frames.device, options);
  if (scene.frames.clock_offset_s == 0.0) return source;
  return capture::ClockShifted(std::move(source), scene.frames.clock_offset_s);
}

SceneSun SunAt(const Scene& scene, const UtcTime& utc) {
  SceneSun sun;
  sun.position = sunmodel::ComputeSunPosition(utc, scene.location,
                                              sunmodel::Atmosphere::Standard(scene.location.elevation_m), {});
  sun.dir = scene.GeoFrame().DirectionInScene(sun.position.azimuth_deg, sun.position.apparent_zenith_deg);
  return sun;
}

size_t FramePosition(const Scene& scene, int frame, std::string_view option) {
  if (!scene.frame_times) ThrowInputError("{}: frames: a live device has no recorded frames", scene.file.string());
  const std::vector<capture::FrameTime>& times = scene.frame_times->frames;
  for (size_t i = 0; i < times.size(); ++i) {
    if (times[i].index == frame) return i;
  }
  ThrowInputError("{}: {} is not in {}", option, frame, scene.frame_times->file.string());
}

double NominalFps(const Scene& scene) {
  if (scene.frames.kind == FrameSourceKind::kDevice || !scene.frame_times) return scene.frames.fps;
  const std::vector<capture::FrameTime>& times = scene.frame_times->frames;
  std::vector<double> steps;
  for (size_t i = 1; i < times.size(); ++i) steps.push_back(times[i].utc.SecondsSince(times[i - 1].utc));
  const double step = MedianInPlace(steps, 1.0 / 30.0);
  return step > 0.0 ? 1.0 / step : 30.0;
}

double VirtualObject::BoundingRadius() const {
  const double s = std::max({scale.x, scale.y, scale.z});
  switch (kind) {
    case MeshKind::kSphere: return radius * s;
    case MeshKind::kBox: return 0.5 * glm::length(size) * s;
    case MeshKind::kFile: return s;
  }
  return s;
}

void AllowPathsOutsideRecording(bool allow) { allow_paths_outside = allow; }

Scene LoadScene(const fs::path& path) {
  Scene scene;
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (status.type() == fs::file_type::not_found) ThrowInputError("{}: no such file or folder", path.string());
  if (ec) ThrowInputError("{}: {}", path.string(), ec.message());
  scene.file = fs::is_directory(status) ? path / "scene.json" : path;
  RequireRegularFile(scene.file);
  scene.folder = scene.file.parent_path();
  if (scene.folder.empty()) scene.folder = ".";  // `scene.json` named from its own folder
  const nlohmann::json json = ReadJsonFile(scene.file);
  const JsonField root(json, scene.file.string(), "");
  if (!json.is_object()) root.Fail("expected a JSON object");
  root.WarnUnknownKeys({"format", "name", "location", "north_azimuth_deg", "model", "diffuse_surfaces",
                        "diffuse_mask", "camera", "envmap", "frames", "objects", "volume",
                        "groundtruth"});
  const JsonField format = root.Get("format");
  if (format.String() != kRecordingFormat) {
    format.Fail(fmt::format("'{}' is not supported (expected '{}')", format.String(), kRecordingFormat));
  }
  scene.name = root.Has("name") ? root.Get("name").String()
                                : fs::absolute(scene.folder).lexically_normal().filename().string();
  LoadLocation(root, &scene);
  LoadModelAndSurfaces(root, &scene);
  LoadCamera(root, &scene);
  LoadEnvMap(root, &scene);
  LoadFrames(root, &scene);
  LoadObjects(root, &scene);
  LoadVolume(root, &scene);
  LoadGroundTruth(root, &scene);
  return scene;
}

}  // namespace daylit::scene
