#include "scene/model.h"

#include <fnmatch.h>

#include <charconv>
#include <cmath>
#include <limits>
#include <tiny_obj_loader.h>

#include "base/csv.h"
#include "base/error.h"

namespace daylit::scene {
namespace {

// A face line ("f 1 2/5 -3//4 ..."): at least 3 vertices, each index an integer that names a
// vertex defined so far when negative (relative, as OBJ says) and is not 0. tinyobjloader drops
// shorter faces and mis-resolves such indices without a word.
void CheckFaceLine(const std::filesystem::path& path, int line, std::string_view l, size_t vertices_so_far) {
  int count = 0;
  while (true) {
    while (!l.empty() && (l.front() == ' ' || l.front() == '\t' || l.front() == '\r')) l.remove_prefix(1);
    if (l.empty() || l.front() == '#') break;
    size_t n = 0;
    while (n < l.size() && l[n] != ' ' && l[n] != '\t' && l[n] != '\r') ++n;
    const std::string_view token = l.substr(0, n), index_text = token.substr(0, token.find('/'));
    long long index = 0;
    const auto [ptr, ec] = std::from_chars(index_text.data(), index_text.data() + index_text.size(), index);
    if (index_text.empty() || ec != std::errc() || ptr != index_text.data() + index_text.size() || index == 0) {
      ThrowInputError("{}:{}: face vertex '{}' is not a vertex index (1-based, or negative from the last)",
                      path.string(), line, Excerpt(token));
    }
    if (index < 0 && static_cast<size_t>(-index) > vertices_so_far) {
      ThrowInputError("{}:{}: face vertex {} reaches before the first vertex ({} defined so far)", path.string(),
                      line, index, vertices_so_far);
    }
    ++count;
    l.remove_prefix(n);
  }
  if (count < 3) ThrowInputError("{}:{}: a face needs at least 3 vertices, this one has {}", path.string(), line, count);
}

// tinyobjloader reads "nan" and "inf" as 0 without a word, so vertex lines are checked here
// first, with their line numbers; and face lines (CheckFaceLine).
void CheckVertexLines(const std::filesystem::path& path, std::string_view text) {
  size_t pos = 0;
  int line = 0;
  size_t vertices = 0;
  while (pos < text.size()) {
    size_t end = text.find('\n', pos);
    if (end == std::string_view::npos) end = text.size();
    std::string_view l = text.substr(pos, end - pos);
    pos = end + 1;
    ++line;
    while (!l.empty() && (l.front() == ' ' || l.front() == '\t')) l.remove_prefix(1);
    if (l.size() >= 2 && l[0] == 'f' && (l[1] == ' ' || l[1] == '\t')) {
      CheckFaceLine(path, line, l.substr(2), vertices);
      continue;
    }
    if (l.size() < 2 || l[0] != 'v' || (l[1] != ' ' && l[1] != '\t')) continue;
    ++vertices;
    l.remove_prefix(2);
    for (int k = 0; k < 3; ++k) {
      while (!l.empty() && (l.front() == ' ' || l.front() == '\t')) l.remove_prefix(1);
      size_t n = 0;
      while (n < l.size() && l[n] != ' ' && l[n] != '\t' && l[n] != '\r') ++n;
      const std::string_view token = l.substr(0, n);
      double value = 0.0;
      const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
      if (token.empty() || ec != std::errc() || ptr != token.data() + token.size() ||
          !std::isfinite(value)) {
        ThrowInputError("{}:{}: vertex coordinate {} is not a finite number ('{}')",
                        path.string(), line, "xyz"[k], Excerpt(token));
      }
      l.remove_prefix(n);
    }
  }
}

}  // namespace

int SceneModel::SurfaceIndex(const std::string& name) const {
  for (size_t i = 0; i < surface_names.size(); ++i) {
    if (surface_names[i] == name) return static_cast<int>(i);
  }
  return -1;
}

std::vector<int> SceneModel::MatchSurfaces(const std::string& glob) const {
  std::vector<int> out;
  for (size_t i = 0; i < surface_names.size(); ++i) {
    if (fnmatch(glob.c_str(), surface_names[i].c_str(), 0) == 0) out.push_back(static_cast<int>(i));
  }
  return out;
}

void SceneModel::Bounds(glm::vec3* lo, glm::vec3* hi) const {
  *lo = glm::vec3(std::numeric_limits<float>::max());
  *hi = glm::vec3(std::numeric_limits<float>::lowest());
  for (const glm::vec3& v : vertices) {
    *lo = glm::min(*lo, v);
    *hi = glm::max(*hi, v);
  }
}

void SceneModel::SurfaceBounds(std::vector<glm::vec3>* lo, std::vector<glm::vec3>* hi) const {
  lo->assign(surface_names.size(), glm::vec3(std::numeric_limits<float>::max()));
  hi->assign(surface_names.size(), glm::vec3(std::numeric_limits<float>::lowest()));
  for (const Triangle& t : triangles) {
    for (const uint32_t v : t.v) {
      (*lo)[t.surface] = glm::min((*lo)[t.surface], vertices[v]);
      (*hi)[t.surface] = glm::max((*hi)[t.surface], vertices[v]);
    }
  }
}

std::vector<double> SceneModel::SurfaceAreas() const {
  std::vector<double> areas(surface_names.size(), 0.0);
  for (const Triangle& t : triangles) {
    const glm::dvec3 a = vertices[t.v[0]], b = vertices[t.v[1]], c = vertices[t.v[2]];
    areas[t.surface] += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return areas;
}

SceneModel LoadObjModel(const std::filesystem::path& path) {
  const std::string text = ReadTextFile(path);
  CheckVertexLines(path, text);

  tinyobj::ObjReader reader;
  tinyobj::ObjReaderConfig config;
  config.triangulate = true;
  config.mtl_search_path = path.parent_path().string();
  // Materials are not trusted as albedo; a missing .mtl only produces a warning we ignore.
  if (!reader.ParseFromString(text, "", config)) {
    ThrowInputError("{}: cannot parse OBJ: {}", path.string(), reader.Error());
  }
  if (reader.Warning().find("out of bounds") != std::string::npos) {
    ThrowInputError("{}: {}", path.string(), reader.Warning().substr(0, reader.Warning().find('\n')));
  }

  SceneModel model;
  model.file = path;
  const std::vector<float>& v = reader.GetAttrib().vertices;
  model.vertices.reserve(v.size() / 3);
  for (size_t i = 0; i + 2 < v.size(); i += 3) model.vertices.emplace_back(v[i], v[i + 1], v[i + 2]);
  for (const tinyobj::shape_t& shape : reader.GetShapes()) {
    const std::string name = shape.name.empty() ? "unnamed" : shape.name;
    int surface = model.SurfaceIndex(name);
    if (surface < 0) {
      surface = static_cast<int>(model.surface_names.size());
      model.surface_names.push_back(name);
    }
    const auto& indices = shape.mesh.indices;
    for (size_t f = 0, offset = 0; f < shape.mesh.num_face_vertices.size(); ++f) {
      const size_t count = shape.mesh.num_face_vertices[f];
      if (count == 3) {
        Triangle t{};
        for (int k = 0; k < 3; ++k) {
          const int index = indices[offset + static_cast<size_t>(k)].vertex_index;
          if (index < 0 || static_cast<size_t>(index) >= model.vertices.size()) {
            ThrowInputError("{}: surface '{}': face {} uses vertex {} of {}", path.string(), name,
                            f + 1, index + 1, model.vertices.size());
          }
          t.v[k] = static_cast<uint32_t>(index);
        }
        t.surface = static_cast<uint32_t>(surface);
        model.triangles.push_back(t);
      }
      offset += count;
    }
  }
  if (model.triangles.empty()) ThrowInputError("{}: the model has no faces", path.string());
  // Drop names that ended up with no faces (an `o` immediately followed by a `g`, say).
  std::vector<int> used(model.surface_names.size(), 0);
  for (const Triangle& t : model.triangles) used[t.surface] = 1;
  std::vector<uint32_t> remap(model.surface_names.size());
  std::vector<std::string> names;
  for (size_t i = 0; i < used.size(); ++i) {
    remap[i] = static_cast<uint32_t>(names.size());
    if (used[i]) names.push_back(model.surface_names[i]);
  }
  for (Triangle& t : model.triangles) t.surface = remap[t.surface];
  model.surface_names = std::move(names);
  return model;
}

}  // namespace daylit::scene
