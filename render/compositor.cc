#include "render/compositor.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "base/error.h"
#include "render/gl_program.h"
#include "render/projection.h"
#include "scene/object_mesh.h"

namespace daylit::render {
namespace {

constexpr float kNear = 0.05f, kFar = 2000.0f;

const char* kFullScreenVertex = R"(#version 330 core
void main() {
  vec2 p = vec2((gl_VertexID << 1) & 2, gl_VertexID & 2);
  gl_Position = vec4(p * 2.0 - 1.0, 0.0, 1.0);
})";

// The background texture holds the frame with row 0 at the top; GL's window rows count upward.
const char* kBackgroundFragment = R"(#version 330 core
uniform sampler2D background;
uniform int height;
out vec4 color;
void main() {
  ivec2 p = ivec2(gl_FragCoord.xy);
  color = vec4(texelFetch(background, ivec2(p.x, height - 1 - p.y), 0).rgb, 1.0);
})";

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
uniform mat4 clip_from_world;
out vec3 world_position;
out vec3 world_normal;
out vec3 vertex_sun_loss;
out vec3 vertex_sky_loss;
void main() {
  world_position = position;
  world_normal = normal;
  vertex_sun_loss = sun_loss;
  vertex_sky_loss = sky_loss;
  gl_Position = clip_from_world * vec4(position, 1.0);
})";

// ρ/π (E_sun v max(0, n·l) + Σ_c SH_c(p) Y_c(n)); Y_c as relight/sh9.h (the cosine lobe is in
// the coefficients already).
const char* kObjectFragment = R"(#version 330 core
in vec3 world_position;
in vec3 world_normal;
in vec3 vertex_sun_loss;
in vec3 vertex_sky_loss;
uniform vec3 albedo;
uniform vec3 sun_dir;
uniform vec3 sun_rgb;
uniform vec3 sky_rgb;
uniform mat4 shadow_from_world;
uniform sampler2DShadow shadow_map;
uniform float shadow_texel;
uniform bool has_volume;
uniform vec3 volume_min;
uniform vec3 volume_max;
uniform vec3 volume_n;
uniform sampler3D sh0, sh1, sh2, sh3, sh4, sh5, sh6, sh7, sh8;
out vec4 color;
const float kPi = 3.14159265358979;

float SunVisibility(vec3 p, vec3 n) {
  // Offset along the normal against acne; 3×3 taps of hardware 2×2 PCF.
  vec4 s = shadow_from_world * vec4(p + n * 4.0 * shadow_texel, 1.0);
  vec3 q = s.xyz / s.w * 0.5 + 0.5;
  float v = 0.0;
  for (int i = -1; i <= 1; ++i)
    for (int j = -1; j <= 1; ++j) v += texture(shadow_map, vec3(q.xy + vec2(i, j) / textureSize(shadow_map, 0), q.z));
  return v / 9.0;
}

void main() {
  vec3 n = normalize(world_normal);
  float cos_l = max(dot(n, sun_dir), 0.0);
  vec3 e = vec3(0.0);
  if (cos_l > 0.0) e += sun_rgb * cos_l * SunVisibility(world_position, n);
  if (has_volume) {
    vec3 f = clamp((world_position - volume_min) / (volume_max - volume_min), 0.0, 1.0);
    vec3 u = 0.5 / volume_n + f * (volume_n - 1.0) / volume_n;
    float x = n.x, y = n.y, z = n.z;
    e += texture(sh0, u).rgb * 0.282095;
    e += texture(sh1, u).rgb * 0.488603 * y;
    e += texture(sh2, u).rgb * 0.488603 * z;
    e += texture(sh3, u).rgb * 0.488603 * x;
    e += texture(sh4, u).rgb * 1.092548 * x * y;
    e += texture(sh5, u).rgb * 1.092548 * y * z;
    e += texture(sh6, u).rgb * 0.315392 * (3.0 * z * z - 1.0);
    e += texture(sh7, u).rgb * 1.092548 * x * z;
    e += texture(sh8, u).rgb * 0.546274 * (x * x - y * y);
    // The bounce from real ground the objects themselves shade (relight::ObjectBounce).
    e -= sun_rgb * vertex_sun_loss + sky_rgb * vertex_sky_loss;
  }
  color = vec4(albedo / kPi * max(e, vec3(0.0)), 1.0);
})";

struct DrawMesh {
  GlVertexArray vao;
  GlBuffer positions, normals, indices, sun_loss, sky_loss;
  size_t vertices = 0;
  GLsizei count = 0;
  glm::vec3 albedo{0.5f};
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

}  // namespace

struct Compositor::Gl {
  int width = 0, height = 0;
  CompositorOptions options;
  glm::mat4 clip_from_world{1.0f};
  scene::VolumeSpec volume;
  GlProgram background{kFullScreenVertex, kBackgroundFragment};
  GlProgram depth{kDepthVertex, kDepthFragment};
  GlProgram object{kObjectVertex, kObjectFragment};
  GlVertexArray empty_vao = NewVertexArray();
  DrawMesh model;
  std::vector<DrawMesh> objects;
  glm::vec3 objects_lo{1e30f}, objects_hi{-1e30f}, model_lo{0.0f}, model_hi{0.0f};
  GlTexture background_texture = NewTexture();
  GlFramebuffer msaa = NewFramebuffer(), resolved = NewFramebuffer(), shadow = NewFramebuffer();
  GlRenderbuffer msaa_color = NewRenderbuffer(), msaa_depth = NewRenderbuffer(), resolved_color = NewRenderbuffer();
  GlTexture shadow_map = NewTexture();
  GlTexture sh[9] = {NewTexture(), NewTexture(), NewTexture(), NewTexture(), NewTexture(),
                     NewTexture(), NewTexture(), NewTexture(), NewTexture()};
  std::vector<float> plane;  // one coefficient's RGB over the probes
  std::vector<float> readback;
};

Compositor::Compositor(const scene::Scene& scene, const CompositorOptions& options) : gl_(std::make_unique<Gl>()) {
  Gl& g = *gl_;
  g.options = options;
  g.width = scene.intrinsics.width, g.height = scene.intrinsics.height;
  g.clip_from_world = ClipFromCamera(scene.intrinsics, kNear, kFar) * CameraFromWorld(scene.cam_from_world);
  if (scene.volume) g.volume = *scene.volume;  // else the volume textures stay unused (input.volume must be null)
  // The real model, for depth only.
  std::vector<uint32_t> indices;
  for (const scene::Triangle& t : scene.model.triangles) indices.insert(indices.end(), {t.v[0], t.v[1], t.v[2]});
  g.model = Upload(scene.model.vertices, nullptr, indices);
  scene.model.Bounds(&g.model_lo, &g.model_hi);
  for (const scene::VirtualObject& o : scene.objects) {
    const scene::Mesh mesh = scene::ObjectMesh(o);
    g.objects.push_back(Upload(mesh.positions, &mesh.normals, mesh.indices));
    g.objects.back().albedo = glm::vec3(o.albedo.value_or(glm::dvec3(0.5)));
    for (const glm::vec3& p : mesh.positions) g.objects_lo = glm::min(g.objects_lo, p), g.objects_hi = glm::max(g.objects_hi, p);
  }
  // Framebuffers: 4× MSAA float colour + depth, resolved into single-sample float.
  glBindRenderbuffer(GL_RENDERBUFFER, g.msaa_color.get());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, options.samples, GL_RGBA32F, g.width, g.height);
  glBindRenderbuffer(GL_RENDERBUFFER, g.msaa_depth.get());
  glRenderbufferStorageMultisample(GL_RENDERBUFFER, options.samples, GL_DEPTH_COMPONENT24, g.width, g.height);
  glBindFramebuffer(GL_FRAMEBUFFER, g.msaa.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.msaa_color.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g.msaa_depth.get());
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE) ThrowInputError("OpenGL: no {}× MSAA float framebuffer", options.samples);
  glBindRenderbuffer(GL_RENDERBUFFER, g.resolved_color.get());
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA32F, g.width, g.height);
  glBindFramebuffer(GL_FRAMEBUFFER, g.resolved.get());
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.resolved_color.get());
  // The sun's shadow map: depth with hardware comparison.
  glBindTexture(GL_TEXTURE_2D, g.shadow_map.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_DEPTH_COMPONENT24, options.shadow_map_size, options.shadow_map_size, 0,
               GL_DEPTH_COMPONENT, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_BORDER);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_BORDER);
  const float lit[] = {1.0f, 1.0f, 1.0f, 1.0f};
  glTexParameterfv(GL_TEXTURE_2D, GL_TEXTURE_BORDER_COLOR, lit);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_MODE, GL_COMPARE_REF_TO_TEXTURE);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_COMPARE_FUNC, GL_LEQUAL);
  glBindFramebuffer(GL_FRAMEBUFFER, g.shadow.get());
  glFramebufferTexture2D(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_TEXTURE_2D, g.shadow_map.get(), 0);
  glDrawBuffer(GL_NONE);
  glReadBuffer(GL_NONE);
  glBindTexture(GL_TEXTURE_2D, g.background_texture.get());
  glTexImage2D(GL_TEXTURE_2D, 0, GL_RGB32F, g.width, g.height, 0, GL_RGB, GL_FLOAT, nullptr);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  const glm::ivec3 n = g.volume.resolution;
  for (const GlTexture& t : g.sh) {
    glBindTexture(GL_TEXTURE_3D, t.get());
    glTexImage3D(GL_TEXTURE_3D, 0, GL_RGB32F, n.x, n.y, n.z, 0, GL_RGB, GL_FLOAT, nullptr);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(GL_TEXTURE_3D, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    for (const GLenum wrap : {GL_TEXTURE_WRAP_S, GL_TEXTURE_WRAP_T, GL_TEXTURE_WRAP_R}) glTexParameteri(GL_TEXTURE_3D, wrap, GL_CLAMP_TO_EDGE);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  if (glGetError() != GL_NO_ERROR) ThrowInputError("OpenGL: setting up the compositor failed");
}

Compositor::~Compositor() = default;

void Compositor::SetObjectLosses(const std::vector<glm::vec3>& sun_loss, const std::vector<glm::vec3>& sky_loss) {
  size_t offset = 0;
  for (const DrawMesh& m : gl_->objects) {
    if (offset + m.vertices > sun_loss.size() || offset + m.vertices > sky_loss.size()) {
      ThrowInputError("SetObjectLosses: {} values for {}+ vertices", sun_loss.size(), offset + m.vertices);
    }
    glBindBuffer(GL_ARRAY_BUFFER, m.sun_loss.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(m.vertices * sizeof(glm::vec3)), sun_loss.data() + offset);
    glBindBuffer(GL_ARRAY_BUFFER, m.sky_loss.get());
    glBufferSubData(GL_ARRAY_BUFFER, 0, static_cast<GLsizeiptr>(m.vertices * sizeof(glm::vec3)), sky_loss.data() + offset);
    offset += m.vertices;
  }
  glBindBuffer(GL_ARRAY_BUFFER, 0);
}

int Compositor::width() const { return gl_->width; }
int Compositor::height() const { return gl_->height; }

void Compositor::Render(const CompositeInput& input, std::vector<float>* out) {
  Gl& g = *gl_;
  const glm::vec3 sun = glm::normalize(input.sun_dir);
  // The sun's view: orthographic, its width over the objects' bounds, its depth over everything
  // that can stand between them and the sun.
  glm::mat4 shadow_from_world(1.0f);
  float shadow_texel = 0.0f;
  const bool sun_up = sun.z > 0.0f && !g.objects.empty();
  if (sun_up) {
    const glm::vec3 centre = 0.5f * (g.objects_lo + g.objects_hi);
    const float radius = 0.5f * glm::length(g.objects_hi - g.objects_lo) + 0.05f;
    float reach = radius;
    for (int c = 0; c < 8; ++c) {
      const glm::vec3 corner((c & 1) ? g.model_hi.x : g.model_lo.x, (c & 2) ? g.model_hi.y : g.model_lo.y,
                             (c & 4) ? g.model_hi.z : g.model_lo.z);
      reach = std::max(reach, glm::dot(corner - centre, sun));
    }
    const glm::vec3 up = std::abs(sun.z) < 0.99f ? glm::vec3(0, 0, 1) : glm::vec3(0, 1, 0);
    const glm::mat4 view = glm::lookAt(centre + (reach + 1.0f) * sun, centre, up);
    shadow_from_world = glm::ortho(-radius, radius, -radius, radius, 0.0f, reach + radius + 2.0f) * view;
    shadow_texel = 2.0f * radius / static_cast<float>(g.options.shadow_map_size);
    glBindFramebuffer(GL_FRAMEBUFFER, g.shadow.get());
    glViewport(0, 0, g.options.shadow_map_size, g.options.shadow_map_size);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_TRUE);
    glClear(GL_DEPTH_BUFFER_BIT);
    glEnable(GL_POLYGON_OFFSET_FILL);
    glPolygonOffset(2.0f, 4.0f);
    glUseProgram(g.depth.id());
    glUniformMatrix4fv(g.depth.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(shadow_from_world));
    Draw(g.model);
    for (const DrawMesh& m : g.objects) Draw(m);
    glDisable(GL_POLYGON_OFFSET_FILL);
  }
  // The volume's coefficients, one 3D texture each.
  const bool has_volume = input.volume != nullptr && !input.volume->empty();
  if (has_volume) {
    const glm::ivec3 n = g.volume.resolution;
    const size_t probes = static_cast<size_t>(n.x) * n.y * n.z;
    g.plane.resize(probes * 3);
    for (int c = 0; c < 9; ++c) {
      for (size_t p = 0; p < probes; ++p) {
        for (int k = 0; k < 3; ++k) g.plane[p * 3 + k] = (*input.volume)[(p * 9 + static_cast<size_t>(c)) * 3 + k];
      }
      glBindTexture(GL_TEXTURE_3D, g.sh[c].get());
      glTexSubImage3D(GL_TEXTURE_3D, 0, 0, 0, 0, n.x, n.y, n.z, GL_RGB, GL_FLOAT, g.plane.data());
    }
  }
  // Background, phantom, objects.
  glBindFramebuffer(GL_FRAMEBUFFER, g.msaa.get());
  glViewport(0, 0, g.width, g.height);
  glClear(GL_DEPTH_BUFFER_BIT);
  glDisable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glActiveTexture(GL_TEXTURE0);
  glBindTexture(GL_TEXTURE_2D, g.background_texture.get());
  glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, g.width, g.height, GL_RGB, GL_FLOAT, input.background);
  glUseProgram(g.background.id());
  glUniform1i(g.background.Uniform("background"), 0);
  glUniform1i(g.background.Uniform("height"), g.height);
  glBindVertexArray(g.empty_vao.get());
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_TRUE);
  glDepthFunc(GL_LESS);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glUseProgram(g.depth.id());
  glUniformMatrix4fv(g.depth.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(g.clip_from_world));
  Draw(g.model);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glUseProgram(g.object.id());
  glUniformMatrix4fv(g.object.Uniform("clip_from_world"), 1, GL_FALSE, glm::value_ptr(g.clip_from_world));
  glUniformMatrix4fv(g.object.Uniform("shadow_from_world"), 1, GL_FALSE, glm::value_ptr(shadow_from_world));
  glUniform3fv(g.object.Uniform("sun_dir"), 1, glm::value_ptr(sun));
  const glm::vec3 sun_rgb = sun_up ? glm::vec3(input.light.sun_rgb) : glm::vec3(0.0f);
  glUniform3fv(g.object.Uniform("sun_rgb"), 1, glm::value_ptr(sun_rgb));
  const glm::vec3 sky_rgb(input.light.sky_rgb);
  glUniform3fv(g.object.Uniform("sky_rgb"), 1, glm::value_ptr(sky_rgb));
  glUniform1f(g.object.Uniform("shadow_texel"), shadow_texel);
  glActiveTexture(GL_TEXTURE1);
  glBindTexture(GL_TEXTURE_2D, g.shadow_map.get());
  glUniform1i(g.object.Uniform("shadow_map"), 1);
  glUniform1i(g.object.Uniform("has_volume"), has_volume ? 1 : 0);
  glUniform3fv(g.object.Uniform("volume_min"), 1, glm::value_ptr(glm::vec3(g.volume.min)));
  glUniform3fv(g.object.Uniform("volume_max"), 1, glm::value_ptr(glm::vec3(g.volume.max)));
  glUniform3fv(g.object.Uniform("volume_n"), 1, glm::value_ptr(glm::vec3(g.volume.resolution)));
  for (int c = 0; c < 9; ++c) {
    glActiveTexture(static_cast<GLenum>(GL_TEXTURE2 + c));
    glBindTexture(GL_TEXTURE_3D, g.sh[c].get());
    const std::string name = "sh" + std::to_string(c);
    glUniform1i(g.object.Uniform(name.c_str()), 2 + c);
  }
  for (const DrawMesh& m : g.objects) {
    glUniform3fv(g.object.Uniform("albedo"), 1, glm::value_ptr(m.albedo));
    Draw(m);
  }
  glBindVertexArray(0);
  // Resolve and read back, top row first.
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.msaa.get());
  glBindFramebuffer(GL_DRAW_FRAMEBUFFER, g.resolved.get());
  glBlitFramebuffer(0, 0, g.width, g.height, 0, 0, g.width, g.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, g.resolved.get());
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  out->resize(static_cast<size_t>(g.width) * g.height * 3);
  g.readback.resize(out->size());
  glReadPixels(0, 0, g.width, g.height, GL_RGB, GL_FLOAT, g.readback.data());
  const size_t row = static_cast<size_t>(g.width) * 3;
  for (int y = 0; y < g.height; ++y) {
    std::copy_n(g.readback.data() + static_cast<size_t>(g.height - 1 - y) * row, row, out->data() + static_cast<size_t>(y) * row);
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
}

}  // namespace daylit::render
