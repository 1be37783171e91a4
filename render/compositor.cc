#include "render/compositor.h"

#include "base/options_check.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <string>

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "base/check.h"
#include "base/error.h"
#include "render/gl_program.h"
#include "render/projection.h"
#include "lightfit/env_lights.h"
#include "sh/irradiance_volume.h"
#include "scene/object_mesh.h"

namespace daylit::render {
namespace {

constexpr float kNear = 0.05f, kFar = 2000.0f;
constexpr int kMaxLights = lightfit::EnvLights::kMaxLights;

const char* kDepthVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
uniform mat4 clip_from_world;
void main() { gl_Position = clip_from_world * vec4(position, 1.0); })";

const char* kDepthFragment = R"(#version 330 core
void main() {})";

const char* kObjectVertex = R"(#version 330 core
layout(location = 0) in vec3 position;
layout(location = 1) in vec3 normal;
layout(location = 2) in vec3 sun_loss;
layout(location = 3) in vec3 sky_loss;
layout(location = 4) in vec3 sh[9];
uniform mat4 clip_from_world;
out vec3 world_position;
out vec3 world_normal;
out vec3 vertex_sun_loss;
out vec3 vertex_sky_loss;
out vec3 vertex_sh[9];
void main() {
  world_position = position;
  world_normal = normal;
  vertex_sun_loss = sun_loss;
  vertex_sky_loss = sky_loss;
  for (int c = 0; c < 9; ++c) vertex_sh[c] = sh[c];
  gl_Position = clip_from_world * vec4(position, 1.0);
})";

// ρ/π (E_sun v max(0, n·l) + Σ_c SH_c(p) Y_c(n)); Y_c as sh/sh9.h (the cosine lobe is in
// the coefficients already). SH_c(p): the volume's trilinear coefficients at the vertices,
// interpolated across the triangle (meshes are finer than the probe grid; the builtin ones are),
// evaluated with the fragment's own normal.
// Compiled with LIGHTS defined as CompositorOptions::lights (ObjectFragment): with none, nothing
// of the lights is in the shader, which llvmpipe would otherwise pay for.
const char* kObjectFragment = R"(
in vec3 world_position;
in vec3 world_normal;
in vec3 vertex_sun_loss;
in vec3 vertex_sky_loss;
in vec3 vertex_sh[9];
uniform vec3 albedo;
uniform vec3 sun_dir;
uniform vec3 sun_rgb;
uniform vec3 sky_rgb;
uniform mat4 shadow_from_world;
uniform sampler2DShadow shadow_map;
uniform float shadow_texel;
uniform bool has_volume;
#if LIGHTS > 0
// Instead of the volume: directional lights and an ambient term (lightfit::EnvLights), each light
// with its own shadow map, a layer of light_maps.
uniform vec3 ambient;
uniform vec3 light_dir[LIGHTS];
uniform vec3 light_rgb[LIGHTS];
uniform mat4 light_shadow_from_world[LIGHTS];
uniform float light_texel[LIGHTS];
uniform sampler2DArrayShadow light_maps;
#endif
out vec4 color;
const float kPi = 3.14159265358979;

float SunVisibility(vec3 p, vec3 n) {
  // Offset along the normal against acne; 2×2 taps a texel apart of hardware 2×2 PCF: a tent
  // about 3 texels wide, near the sun's penumbra at the objects' scale.
  vec4 s = shadow_from_world * vec4(p + n * 4.0 * shadow_texel, 1.0);
  vec3 q = s.xyz / s.w * 0.5 + 0.5;
  vec2 d = vec2(0.5) / vec2(textureSize(shadow_map, 0));
  return 0.25 * (texture(shadow_map, vec3(q.xy + vec2(-d.x, -d.y), q.z)) + texture(shadow_map, vec3(q.xy + vec2(d.x, -d.y), q.z)) +
                 texture(shadow_map, vec3(q.xy + vec2(-d.x, d.y), q.z)) + texture(shadow_map, vec3(q.xy + vec2(d.x, d.y), q.z)));
}

#if LIGHTS > 0
// One fetch, the hardware's 2×2 PCF: these lights stand for broad regions of sky, whose
// shadows are soft anyway.
float LightVisibility(int i, vec3 p, vec3 n) {
  vec4 s = light_shadow_from_world[i] * vec4(p + n * 4.0 * light_texel[i], 1.0);
  vec3 q = s.xyz / s.w * 0.5 + 0.5;
  return texture(light_maps, vec4(q.xy, float(i), q.z));
}
#endif

void main() {
  vec3 n = normalize(world_normal);
  float cos_l = max(dot(n, sun_dir), 0.0);
  vec3 e = vec3(0.0);
  if (cos_l > 0.0) e += sun_rgb * cos_l * SunVisibility(world_position, n);
  if (has_volume) {
    float x = n.x, y = n.y, z = n.z;
    e += vertex_sh[0] * 0.282095;
    e += vertex_sh[1] * 0.488603 * y;
    e += vertex_sh[2] * 0.488603 * z;
    e += vertex_sh[3] * 0.488603 * x;
    e += vertex_sh[4] * 1.092548 * x * y;
    e += vertex_sh[5] * 1.092548 * y * z;
    e += vertex_sh[6] * 0.315392 * (3.0 * z * z - 1.0);
    e += vertex_sh[7] * 1.092548 * x * z;
    e += vertex_sh[8] * 0.546274 * (x * x - y * y);
  }
#if LIGHTS > 0
  else {
    e += ambient;
    for (int i = 0; i < LIGHTS; ++i) {
      float c = max(dot(n, light_dir[i]), 0.0);
      if (c > 0.0) e += light_rgb[i] * c * LightVisibility(i, world_position, n);
    }
  }
#endif
  // The bounce from real ground the objects themselves shade (composite::ObjectBounce; zero
  // unless set).
  e -= sun_rgb * vertex_sun_loss + sky_rgb * vertex_sky_loss;
  color = vec4(albedo / kPi * max(e, vec3(0.0)), 1.0);
})";


// A light's view for its shadow map: orthographic along `dir`, its width over the objects'
// bounds, its depth over everything that can stand between them and the light.
struct ShadowView {
  glm::mat4 shadow_from_world{1.0f};
  float texel = 0.0f;  // one texel's width in metres
};

ShadowView ShadowViewOf(const glm::vec3& dir, const glm::vec3& objects_lo, const glm::vec3& objects_hi,
                        const glm::vec3& model_lo, const glm::vec3& model_hi, int size) {
  const glm::vec3 centre = 0.5f * (objects_lo + objects_hi);
  const float radius = 0.5f * glm::length(objects_hi - objects_lo) + 0.05f;
  float reach = radius;
  for (int c = 0; c < 8; ++c) {
    const glm::vec3 corner((c & 1) ? model_hi.x : model_lo.x, (c & 2) ? model_hi.y : model_lo.y, (c & 4) ? model_hi.z : model_lo.z);
    reach = std::max(reach, glm::dot(corner - centre, dir));
  }
  const glm::vec3 up = std::abs(dir.z) < 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
  const glm::mat4 view = glm::lookAt(centre + (reach + 1.0f) * dir, centre, up);
  return {glm::ortho(-radius, radius, -radius, radius, 0.0f, reach + radius + 2.0f) * view, 2.0f * radius / static_cast<float>(size)};
}

// Depth with hardware comparison, lit outside the map.
void SetShadowSampling(GLenum target) {
  glTexParameteri(target, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(target, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTexParameteri(target, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float lit[] = {1.0f, 1.0f, 1.0f, 1.0f};
  glTexParameterfv(target, GL_TEXTURE_BORDER_COLOR, lit);
  glTexParameteri(target, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(target, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
}

struct DrawMesh {
  GlVertexArray vao;
  GlBuffer positions, normals, indices, sun_loss, sky_loss, sh;
  size_t vertices = 0;
  std::vector<glm::vec3> world;  // the vertices, for the volume's interpolation
  std::vector<std::array<size_t, 8>> corner_probes;  // per vertex, once the volume is known
  std::vector<std::array<float, 8>> corner_weights;
  GLsizei count = 0;
  glm::vec3 albedo{0.5f};
  bool closed = false;  // every edge shared by two triangles that traverse it in opposite directions
};

DrawMesh Upload(const std::vector<glm::vec3>& positions, const std::vector<glm::vec3>* normals,
                const std::vector<uint32_t>& indices) {
  DrawMesh m;
  m.vao = NewVertexArray();
  glBindVertexArray(m.vao.get());
  m.positions = NewBuffer();
  glBindBuffer(GL_ARRAY_BUFFER, m.positions.get());
  glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(positions.size() * sizeof(glm::vec3)), positions.data(), GL_STATIC_DRAW);
  glEnableVertexAttribArray(0);
  glVertexAttribPointer(0, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  if (normals != nullptr) {
    m.normals = NewBuffer();
    glBindBuffer(GL_ARRAY_BUFFER, m.normals.get());
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(normals->size() * sizeof(glm::vec3)), normals->data(), GL_STATIC_DRAW);
    glEnableVertexAttribArray(1);
    glVertexAttribPointer(1, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
  }
  m.vertices = positions.size();
  if (normals != nullptr) {
    // Per-vertex irradiance losses, zero until SetObjectLosses.
    const std::vector<glm::vec3> zero(positions.size(), glm::vec3(0.0f));
    for (const auto& [buffer, location] : {std::pair{&m.sun_loss, 2u}, std::pair{&m.sky_loss, 3u}}) {
      *buffer = NewBuffer();
      glBindBuffer(GL_ARRAY_BUFFER, buffer->get());
      glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(zero.size() * sizeof(glm::vec3)), zero.data(), GL_DYNAMIC_DRAW);
      glEnableVertexAttribArray(location);
      glVertexAttribPointer(location, 3, GL_FLOAT, GL_FALSE, 0, nullptr);
    }
    // The volume's 9 RGB coefficients per vertex, interleaved; zero until a volume comes.
    m.sh = NewBuffer();
    glBindBuffer(GL_ARRAY_BUFFER, m.sh.get());
    const std::vector<float> none(positions.size() * 27, 0.0f);
    glBufferData(GL_ARRAY_BUFFER, static_cast<GLsizeiptr>(none.size() * sizeof(float)), none.data(), GL_STREAM_DRAW);
    for (GLuint c = 0; c < 9; ++c) {
      glEnableVertexAttribArray(4 + c);
      glVertexAttribPointer(4 + c, 3, GL_FLOAT, GL_FALSE, 27 * sizeof(float),
                            reinterpret_cast<const void*>(static_cast<uintptr_t>(3 * c * sizeof(float))));
    }
    m.world = positions;
    m.closed = scene::IsClosedMesh(positions, indices);
  }
  m.indices = NewBuffer();
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, m.indices.get());
  glBufferData(GL_ELEMENT_ARRAY_BUFFER, static_cast<GLsizeiptr>(indices.size() * sizeof(uint32_t)), indices.data(), GL_STATIC_DRAW);
  m.count = static_cast<GLsizei>(indices.size());
  glBindVertexArray(0);
  return m;
}

void Draw(const DrawMesh& m) {
  glBindVertexArray(m.vao.get());
  glDrawElements(GL_TRIANGLES, m.count, GL_UNSIGNED_INT, nullptr);
}

// The depth of `model` (if given) and `objects` seen along `view`, into the bound framebuffer.
void DrawShadowMap(const GlProgram& depth, const ShadowView& view, int size, const DrawMesh* model,
                   const std::vector<DrawMesh>& objects) {
  glViewport(0, 0, size, size);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glClear(GL_DEPTH_BUFFER_BIT);
  glEnable(GL_POLYGON_OFFSET_FILL);
  glPolygonOffset(2.0f, 4.0f);
  glUseProgram(depth.id());
  glUniformMatrix4fv(depth.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(view.shadow_from_world));
  if (model != nullptr) Draw(*model);
  for (const DrawMesh& m : objects) Draw(m);
  glDisable(GL_POLYGON_OFFSET_FILL);
}

}  // namespace

struct Compositor::Gl {
  int width = 0, height = 0;
  Rect rect;  // what is drawn: FBOs, textures and viewports are its size
  CompositorOptions options;
  glm::mat4 clip_from_world{1.0f};  // for the rectangle's viewport
  bool has_shadow_map = false;
  glm::vec3 shadow_sun{0.0f};
  glm::mat4 shadow_from_world{1.0f};
  float shadow_texel = 0.0f;
  GlProgram depth{kDepthVertex, kDepthFragment};
  std::unique_ptr<GlProgram> object_program;  // ObjectFragment(options.lights)
  DrawMesh model;
  std::vector<DrawMesh> objects;
  glm::vec3 objects_lo{1e30f}, objects_hi{-1e30f}, model_lo{0.0f}, model_hi{0.0f};
  GlFramebuffer msaa = NewFramebuffer(), resolved = NewFramebuffer(), shadow = NewFramebuffer();
  GlRenderbuffer msaa_color = NewRenderbuffer(), msaa_depth = NewRenderbuffer(), resolved_color = NewRenderbuffer();
  GlTexture shadow_map = NewTexture();
  // The lights' shadow maps (CompositeInput::lights): one layer each, for `light_generation`.
  GlTexture light_maps = NewTexture();
  int light_generation = -1;
  std::vector<glm::mat4> light_shadow_from_world;
  std::vector<float> light_texel;
  std::vector<float> vertex_sh;  // one mesh's coefficients per vertex
  std::vector<float> readback;
};

namespace {

// The pixels `vertices` project to in a camera-size image, a pixel wider on each side; the whole
// image when one is behind the near plane.
Compositor::Rect ProjectedRect(const std::vector<glm::vec3>& vertices, const glm::mat4& clip_from_world, int width,
                               int height) {
  if (vertices.empty()) return {};
  glm::vec2 lo(1e30f), hi(-1e30f);
  for (const glm::vec3& p : vertices) {
    const glm::vec4 c = clip_from_world * glm::vec4(p, 1.0f);
    if (c.w < kNear) return {0, 0, width, height};
    // Window coordinates, then image rows from the top.
    const glm::vec2 window(0.5f * (c.x / c.w + 1.0f) * static_cast<float>(width),
                           0.5f * (c.y / c.w + 1.0f) * static_cast<float>(height));
    const glm::vec2 image(window.x, static_cast<float>(height) - window.y);
    lo = glm::min(lo, image), hi = glm::max(hi, image);
  }
  const int x0 = std::clamp(static_cast<int>(std::floor(lo.x)) - 1, 0, width);
  const int y0 = std::clamp(static_cast<int>(std::floor(lo.y)) - 1, 0, height);
  const int x1 = std::clamp(static_cast<int>(std::ceil(hi.x)) + 1, 0, width);
  const int y1 = std::clamp(static_cast<int>(std::ceil(hi.y)) + 1, 0, height);
  if (x1 <= x0 || y1 <= y0) return {};
  return {x0, y0, x1 - x0, y1 - y0};
}

}  // namespace

Compositor::Compositor(const scene::Scene& scene, const CompositorOptions& options) : gl_(std::make_unique<Gl>()) {
  DAYLIT_CHECK(options.Check().empty(), "{}", options.Check());
  Gl& g = *gl_;
  g.options = options;
  DAYLIT_CHECK(options.lights >= 0 && options.lights <= kMaxLights, "{} lights; 0 to {}", options.lights, kMaxLights);
  const std::string fragment = fmt::format("#version 330 core\n#define LIGHTS {}\n", options.lights) + kObjectFragment;
  g.object_program = std::make_unique<GlProgram>(kObjectVertex, fragment.c_str());
  g.width = scene.intrinsics.width, g.height = scene.intrinsics.height;
  const glm::mat4 camera_from_world = CameraFromWorld(scene.cam_from_world);
  // The real model, for depth only.
  std::vector<uint32_t> indices;
  for (const scene::Triangle& t : scene.model.triangles) indices.insert(indices.end(), {t.v[0], t.v[1], t.v[2]});
  g.model = Upload(scene.model.vertices, nullptr, indices);
  scene.model.Bounds(&g.model_lo, &g.model_hi);
  std::vector<glm::vec3> all_vertices;
  for (const scene::VirtualObject& o : scene.objects) {
    const scene::Mesh mesh = scene::ShadingMesh(o, scene);
    g.objects.push_back(Upload(mesh.positions, &mesh.normals, mesh.indices));
    g.objects.back().albedo = glm::vec3(o.albedo.value_or(glm::dvec3(0.5)));
    for (const glm::vec3& p : mesh.positions) g.objects_lo = glm::min(g.objects_lo, p), g.objects_hi = glm::max(g.objects_hi, p);
    all_vertices.insert(all_vertices.end(), mesh.positions.begin(), mesh.positions.end());
  }
  // The rectangle: the camera with its principal point moved to the rectangle's corner.
  g.rect = ProjectedRect(all_vertices, ClipFromCamera(scene.intrinsics, kNear, kFar) * camera_from_world, g.width, g.height);
  scene::CameraIntrinsics k = scene.intrinsics;
  k.cx -= g.rect.x, k.cy -= g.rect.y;
  k.width = std::max(g.rect.width, 1), k.height = std::max(g.rect.height, 1);
  g.clip_from_world = ClipFromCamera(k, kNear, kFar) * camera_from_world;
  const int rw = k.width, rh = k.height;
  // Framebuffers: 4× MSAA float colour + depth, resolved into single-sample float.
  glBindRenderbuffer(GL_RENDERBUFFER, g.msaa_color.get());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, options.samples, GL_RGBA32F, rw, rh);
  glBindRenderbuffer(GL_RENDERBUFFER, g.msaa_depth.get());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, options.samples, GL_DEPTH_COMPONENT24, rw, rh);
  glBindFramebuffer(GL_FRAMEBUFFER, g.msaa.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.msaa_color.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g.msaa_depth.get());
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) ThrowSystemError("OpenGL: no {}× MSAA float framebuffer", options.samples);
  glBindRenderbuffer(GL_RENDERBUFFER, g.resolved_color.get());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, rw, rh);
  glBindFramebuffer(GL_FRAMEBUFFER, g.resolved.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.resolved_color.get());
  // The sun's shadow map: depth with hardware comparison.
  glBindTexture(GL_TEXTURE_2D, g.shadow_map.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, options.shadow_map_size, options.shadow_map_size, 0,
               GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  SetShadowSampling(GL_TEXTURE_2D);
  glBindFramebuffer(GL_FRAMEBUFFER, g.shadow.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g.shadow_map.get(), 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  // The lights' shadow maps, a layer each.
  if (options.lights > 0) {
    glBindTexture(GL_TEXTURE_2D_ARRAY, g.light_maps.get());
    glTexImage3D(GL_TEXTURE_2D_ARRAY, 0, GL_DEPTH_COMPONENT24, options.light_shadow_map_size, options.light_shadow_map_size,
                 options.lights, 0, GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
    SetShadowSampling(GL_TEXTURE_2D_ARRAY);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (glGetError() != GL_NO_ERROR) ThrowSystemError("OpenGL: setting up the compositor failed");
}

Compositor::~Compositor() = default;

void Compositor::SetObjectLosses(const std::vector<glm::vec3>& sun_loss, const std::vector<glm::vec3>& sky_loss) {
  size_t vertices = 0;
  for (const DrawMesh& m : gl_->objects) vertices += m.vertices;
  DAYLIT_CHECK(sun_loss.size() == vertices && sky_loss.size() == vertices, "{} and {} values for {} vertices (scene::ShadingMesh)",
               sun_loss.size(), sky_loss.size(), vertices);
  size_t offset = 0;
  for (const DrawMesh& m : gl_->objects) {
    glBindBuffer(GL_ARRAY_BUFFER, m.sun_loss.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(m.vertices * sizeof(glm::vec3)), sun_loss.data() + offset);
    glBindBuffer(GL_ARRAY_BUFFER, m.sky_loss.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(m.vertices * sizeof(glm::vec3)), sky_loss.data() + offset);
    offset += m.vertices;
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

int Compositor::width() const { return gl_->width; }
const Compositor::Rect& Compositor::objects_rect() const { return gl_->rect; }
int Compositor::height() const { return gl_->height; }

void Compositor::Render(const CompositeInput& input, float* image) {
  if (gl_->rect.width == 0) return;  // no objects in view
  const glm::vec3 sun = glm::normalize(input.sun_dir);
  UpdateShadowMaps(input, sun);
  if (input.volume != nullptr) UpdateVertexLight(*input.volume);
  DrawObjects(input, sun);
  BlendOver(image);
}

namespace {

// The lights of CompositeInput: as many per object as the options say, one set per object.
int LightCount(const CompositeInput& input) {
  if (input.lights == nullptr || input.lights->empty()) return 0;
  const size_t count = input.lights->front().lights.size();
  for (const lightfit::LightSet& set : *input.lights) {
    DAYLIT_CHECK(set.lights.size() == count, "light sets of {} and {} lights", count, set.lights.size());
  }
  return static_cast<int>(count);
}

}  // namespace

// The sun's shadow map, redrawn for another sun (scene::SunTracker says when it moved); the
// lights' shadow maps, redrawn when their directions change, of the objects only (each object's
// lights already hold what the real model hides or reflects from where it stands).
void Compositor::UpdateShadowMaps(const CompositeInput& input, const glm::vec3& sun) {
  Gl& g = *gl_;
  if (sun.z > 0.0f && (!g.has_shadow_map || sun != g.shadow_sun)) {
    g.has_shadow_map = true;
    g.shadow_sun = sun;
    const ShadowView view = ShadowViewOf(sun, g.objects_lo, g.objects_hi, g.model_lo, g.model_hi, g.options.shadow_map_size);
    g.shadow_from_world = view.shadow_from_world;
    g.shadow_texel = view.texel;
    glBindFramebuffer(GL_FRAMEBUFFER, g.shadow.get());
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g.shadow_map.get(), 0);
    DrawShadowMap(g.depth, view, g.options.shadow_map_size, &g.model, g.objects);
  }
  const int light_count = LightCount(input);
  DAYLIT_CHECK(light_count == 0 || light_count == g.options.lights, "{} lights given, made for {}", light_count,
               g.options.lights);
  if (light_count == 0 || input.lights_generation == g.light_generation) return;
  const int size = g.options.light_shadow_map_size;
  g.light_generation = input.lights_generation;
  g.light_shadow_from_world.resize(static_cast<size_t>(light_count));
  g.light_texel.resize(static_cast<size_t>(light_count));
  glBindFramebuffer(GL_FRAMEBUFFER, g.shadow.get());
  for (int i = 0; i < light_count; ++i) {
    const glm::vec3 dir = glm::normalize(input.lights->front().lights[static_cast<size_t>(i)].direction);
    const ShadowView view = ShadowViewOf(dir, g.objects_lo, g.objects_hi, g.model_lo, g.model_hi, size);
    g.light_shadow_from_world[i] = view.shadow_from_world;
    g.light_texel[i] = view.texel;
    glFramebufferTextureLayer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, g.light_maps.get(), 0, i);
    DrawShadowMap(g.depth, view, size, nullptr, g.objects);
  }
}

// The volume's coefficients at every object vertex (trilinear, the corners found once).
void Compositor::UpdateVertexLight(const sh::IrradianceVolume& volume) {
  Gl& g = *gl_;
  const std::vector<float>& coefficients = volume.coefficients();
  for (DrawMesh& m : g.objects) {
    if (m.corner_probes.empty()) {
      m.corner_probes.resize(m.vertices), m.corner_weights.resize(m.vertices);
      for (size_t v = 0; v < m.vertices; ++v) volume.Corners(m.world[v], &m.corner_probes[v], &m.corner_weights[v]);
    }
    g.vertex_sh.assign(m.vertices * 27, 0.0f);
    for (size_t v = 0; v < m.vertices; ++v) {
      float* out = &g.vertex_sh[v * 27];
      for (size_t corner = 0; corner < 8; ++corner) {
        const float w = m.corner_weights[v][corner];
        if (w == 0.0f) continue;
        const float* in = &coefficients[m.corner_probes[v][corner] * 27];
        for (int k = 0; k < 27; ++k) out[k] += w * in[k];
      }
    }
    glBindBuffer(GL_ARRAY_BUFFER, m.sh.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(g.vertex_sh.size() * sizeof(float)), g.vertex_sh.data());
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

// The phantom and the objects over transparent black: the resolved alpha is each pixel's
// object coverage, its colour the covered samples' sum over all samples, so the frame is
// blended in below as MSAA over a drawn background would (every sample of a pixel shows the
// same background) without drawing, uploading or resolving the background.
void Compositor::DrawObjects(const CompositeInput& input, const glm::vec3& sun) {
  Gl& g = *gl_;
  const Rect& r = g.rect;
  glBindFramebuffer(GL_FRAMEBUFFER, g.msaa.get());
  glViewport(0, 0, r.width, r.height);
  glClearColor(0.0f, 0.0f, 0.0f, 0.0f);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glUseProgram(g.depth.id());
  glUniformMatrix4fv(g.depth.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(g.clip_from_world));
  Draw(g.model);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  const GlProgram& program = *g.object_program;
  glUseProgram(program.id());
  glUniformMatrix4fv(program.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(g.clip_from_world));
  glUniformMatrix4fv(program.Uniform("shadow_from_world"), 1, GL_FALSE, glm::value_ptr(g.shadow_from_world));
  glUniform3fv(program.Uniform("sun_dir"), 1, glm::value_ptr(sun));
  const glm::vec3 sun_rgb = sun.z > 0.0f ? glm::vec3(input.light.sun_rgb) : glm::vec3(0.0f);
  glUniform3fv(program.Uniform("sun_rgb"), 1, glm::value_ptr(sun_rgb));
  const glm::vec3 sky_rgb(input.light.sky_rgb);
  glUniform3fv(program.Uniform("sky_rgb"), 1, glm::value_ptr(sky_rgb));
  glUniform1f(program.Uniform("shadow_texel"), g.shadow_texel);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, g.shadow_map.get());
  glUniform1i(program.Uniform("shadow_map"), 1);
  glUniform1i(program.Uniform("has_volume"), input.volume != nullptr ? 1 : 0);
  const int light_count = LightCount(input);
  if (light_count > 0) {
    DAYLIT_CHECK(input.lights->size() == g.objects.size(), "light sets for {} objects, not {}", input.lights->size(),
                 g.objects.size());
    std::vector<glm::vec3> dirs;
    for (const lightfit::DirectionalLight& l : input.lights->front().lights) dirs.push_back(glm::normalize(l.direction));
    glUniform3fv(program.Uniform("light_dir"), light_count, glm::value_ptr(dirs[0]));
    glUniformMatrix4fv(program.Uniform("light_shadow_from_world"), light_count, GL_FALSE,
                       glm::value_ptr(g.light_shadow_from_world[0]));
    glUniform1fv(program.Uniform("light_texel"), light_count, g.light_texel.data());
    glActiveTexture(GL_TEXTURE2);
    glBindTexture(GL_TEXTURE_2D_ARRAY, g.light_maps.get());
    glUniform1i(program.Uniform("light_maps"), 2);
  }
  for (size_t o = 0; o < g.objects.size(); ++o) {
    const DrawMesh& m = g.objects[o];
    if (light_count > 0) {  // this object's own lights
      const lightfit::LightSet& own = (*input.lights)[o];
      std::vector<glm::vec3> rgbs;
      for (const lightfit::DirectionalLight& l : own.lights) rgbs.push_back(l.irradiance);
      glUniform3fv(program.Uniform("ambient"), 1, glm::value_ptr(own.ambient));
      glUniform3fv(program.Uniform("light_rgb"), light_count, glm::value_ptr(rgbs[0]));
    }
    // A closed mesh's back faces are hidden by its front ones: not drawing them halves the work.
    if (m.closed) glEnable(GL_CULL_FACE);
    glUniform3fv(program.Uniform("albedo"), 1, glm::value_ptr(m.albedo));
    Draw(m);
    glDisable(GL_CULL_FACE);
  }
  glBindVertexArray(0);
}

// Resolve, read back, and blend over the image's rectangle, top row first.
void Compositor::BlendOver(float* image) {
  Gl& g = *gl_;
  const Rect& r = g.rect;
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.msaa.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.resolved.get());
  glBlitFramebuffer(0, 0, r.width, r.height, 0, 0, r.width, r.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.resolved.get());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  const size_t row = static_cast<size_t>(r.width) * 4;
  g.readback.resize(row * static_cast<size_t>(r.height));
  glReadPixels(0, 0, r.width, r.height, GL_RGBA, GL_FLOAT, g.readback.data());
  for (int y = 0; y < r.height; ++y) {
    const float* drawn = g.readback.data() + static_cast<size_t>(r.height - 1 - y) * row;
    float* out = image + (static_cast<size_t>(r.y + y) * g.width + r.x) * 3;
    for (int x = 0; x < r.width; ++x, drawn += 4, out += 3) {
      const float coverage = drawn[3];
      if (coverage == 0.0f) continue;
      for (int c = 0; c < 3; ++c) out[c] = drawn[c] + (1.0f - coverage) * out[c];
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

std::string CompositorOptions::Check() const {
  if (samples != 1 && samples != 2 && samples != 4 && samples != 8) return fmt::format("samples: {} is not 1, 2, 4 or 8", samples);
  return FirstProblem({InClosed("shadow_map_size", shadow_map_size, 64, 16384), InClosed("lights", lights, 0, kMaxLights),
                       InClosed("light_shadow_map_size", light_shadow_map_size, 64, 16384)});
}

}  // namespace daylit::render
