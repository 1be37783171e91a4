#include "fuzz/targets.h"

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <memory>
#include <string>

#include <ImfHeader.h>
#include <ImfRgbaFile.h>
#include <opencv2/imgcodecs.hpp>

#include "bake/bake.h"
#include "bake/synthetic_recording.h"
#include "base/atomic_file.h"
#include "base/csv.h"
#include "base/error.h"
#include "base/log.h"
#include "capture/frame_times.h"
#include "capture/response.h"
#include "capture/video_decoder.h"
#include "capture/video_encoder.h"
#include "scene/envmap_probe.h"
#include "scene/hdr_image.h"
#include "scene/model.h"
#include "scene/object_mesh.h"
#include "scene/scene.h"
#include "serve/http_request.h"
#include "sunmodel/sunpos_batch.h"

namespace daylit::fuzz {
namespace fs = std::filesystem;
namespace {

// This process's own folder for the files an input is written to (the parsers read files, as
// the commands do), removed at exit.
const fs::path& Scratch() {
  static const fs::path dir = [] {
    const fs::path d = fs::temp_directory_path() / ("daylit_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(d);
    std::atexit([] { std::error_code ignored; fs::remove_all(fs::temp_directory_path() / ("daylit_fuzz_" + std::to_string(::getpid())), ignored); });
    return d;
  }();
  return dir;
}

void WriteBytes(const fs::path& path, const uint8_t* data, size_t size) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out.write(reinterpret_cast<const char*>(data), static_cast<std::streamsize>(size));
}

void WriteText(const fs::path& path, std::string_view text) {
  WriteBytes(path, reinterpret_cast<const uint8_t*>(text.data()), text.size());
}

std::string ReadBytes(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

// The small recording the scene and bake targets read against (bake/synthetic_recording.h): a
// ground plane under a uniform sky, a 64×48 camera, a 64×32 env map.
bake::testing::SyntheticRecording& Recording() {
  static bake::testing::SyntheticRecording* recording = [] {
    auto* r = new bake::testing::SyntheticRecording("fuzz");
    r->env_width = 64;
    r->Write();
    return r;
  }();
  return *recording;
}

void QuietLogs() { Log().set_level(spdlog::level::off); }

// --- scene.json: LoadScene with every check it makes, then what info does with the result.
void RunSceneJson(const uint8_t* data, size_t size) {
  const fs::path path = Recording().dir / "scene.json";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("scene_json", [&] {
    const scene::Scene scene = scene::LoadScene(path);
    if (scene.envmap) scene::ProbeEnvMap(scene.envmap->file);
    if (scene.frame_times && !scene.frame_times->frames.empty()) {
      scene::SunAt(scene, scene.frame_times->frames.front().utc);
      scene::SunAt(scene, scene.frame_times->frames.back().utc);
    }
    for (const scene::VirtualObject& o : scene.objects) {
      if (o.kind == scene::MeshKind::kFile) scene::ObjectMesh(o);
    }
  });
}

void SeedsSceneJson(const fs::path& dir) {
  WriteText(dir / "synthetic.json", Recording().scene.dump(1));
  nlohmann::json with_objects = Recording().scene;
  with_objects["objects"] = {{{"mesh", "sphere"}, {"radius", 0.3}, {"position", {0, 0, 1}}},
                             {{"mesh", "box"}, {"size", {0.5, 0.5, 0.5}}, {"position", {0.5, 0, 0.25}}}};
  WriteText(dir / "objects.json", with_objects.dump(1));
}

// --- OBJ models.
void RunObj(const uint8_t* data, size_t size) {
  const fs::path path = Scratch() / "model.obj";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("obj", [&] { scene::LoadObjModel(path); });
}

void SeedsObj(const fs::path& dir) {
  WriteText(dir / "ground.obj", Recording().obj);
  WriteText(dir / "cube.obj",
            "# a unit cube, negative indices and v/vt/vn faces\no box\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
            "v 0 0 1\nv 1 0 1\nv 1 1 1\nv 0 1 1\nvt 0 0\nvn 0 0 1\ng side\nf -8/1/1 -7/1/1 -6/1/1 -5/1/1\n"
            "f 5 6 7 8\nusemtl x\nf 1//1 2//1 6//1\nf 1 6 5\n");
}

// --- CSV: every reader of a CSV file on the same bytes (frames.csv, the response table,
// sunpos --csv input, the generic parser).
void RunCsv(const uint8_t* data, size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const fs::path path = Scratch() / "input.csv";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("csv", [&] {
    const CsvTable table = ParseCsv(text, "input.csv");
    for (size_t r = 0; r < table.rows.size(); ++r) {
      for (const std::string& field : table.rows[r]) {
        double ignored = 0.0;
        TryParseFiniteDouble(field, &ignored);
      }
    }
    sunmodel::ComputeSunposCsv(table);
  });
  ExpectOnlyInputErrors("csv", [&] { capture::LoadFrameTimes(path); });
  ExpectOnlyInputErrors("csv", [&] { capture::ReadResponseTable(path); });
}

void SeedsCsv(const fs::path& dir) {
  WriteText(dir / "frames.csv",
            "frame,time_utc,exposure\n0,2026-06-21T05:00:00Z,0.004\n1,2026-06-21T05:00:00.1+02:00,\n2,2016-12-31 23:59:60.5Z,0.002\n");
  WriteText(dir / "sunpos.csv",
            "time_utc,latitude_deg,longitude_deg,elevation_m,pressure_hpa,temperature_c\n"
            "2003-10-17T12:30:30-07:00,39.742476,-105.1786,1830.14,820,11\n");
  std::string response = "code,r,g,b\n";
  for (int code = 0; code < 256; ++code) {
    const double v = code / 255.0;
    response += std::to_string(code) + "," + std::to_string(v * v) + "," + std::to_string(v) + ",\"" +
                std::to_string(v) + "\"\n";
  }
  WriteText(dir / "response.csv", response);
}

// --- OpenEXR: the env-map and probe reader, the header probe, the bake's channel reader.
void RunExr(const uint8_t* data, size_t size) {
  const fs::path path = Scratch() / "input.exr";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("exr", [&] { scene::ProbeEnvMap(path); });
  ExpectOnlyInputErrors("exr", [&] {
    const HdrImage image = scene::ReadHdrImage(path);
    scene::CheckEnvMap(image, path.string());
  });
  ExpectOnlyInputErrors("exr", [&] { scene::ReadExrChannels(path, {"R", "G", "B"}, {}); });
  ExpectOnlyInputErrors("exr", [&] { scene::ReadExrChannels(path, {"R"}, {"surface"}); });
}

void SeedsExr(const fs::path& dir) {
  constexpr int kW = 16, kH = 8;
  std::vector<float> rgb(kW * kH * 3);
  for (size_t i = 0; i < rgb.size(); ++i) rgb[i] = 0.01f * static_cast<float>(i % 97);
  scene::WriteRgbExr(dir / "rgb_float_zip.exr", kW, kH, rgb.data());
  std::vector<uint32_t> surface(kW * kH);
  for (size_t i = 0; i < surface.size(); ++i) surface[i] = static_cast<uint32_t>(i % 3);
  scene::WriteExr(dir / "half_and_uint.exr", kW, kH,
                  {{"R", scene::ExrPixelType::kHalf, rgb.data(), nullptr},
                   {"surface", scene::ExrPixelType::kUint, nullptr, surface.data()}});
  // The other compressions OpenEXR decodes, through its RGBA interface.
  std::vector<Imf::Rgba> pixels(kW * kH);
  for (size_t i = 0; i < pixels.size(); ++i) pixels[i] = Imf::Rgba(rgb[3 * i], rgb[3 * i + 1], rgb[3 * i + 2], 1.0f);
  const std::pair<const char*, Imf::Compression> kinds[] = {
      {"none", Imf::NO_COMPRESSION}, {"rle", Imf::RLE_COMPRESSION},   {"piz", Imf::PIZ_COMPRESSION},
      {"pxr24", Imf::PXR24_COMPRESSION}, {"b44", Imf::B44_COMPRESSION}, {"dwaa", Imf::DWAA_COMPRESSION}};
  for (const auto& [name, compression] : kinds) {
    const std::string file = (dir / (std::string("rgba_") + name + ".exr")).string();
    Imf::RgbaOutputFile out(file.c_str(), Imf::Header(kW, kH, 1.0f, Imath::V2f(0, 0), 1.0f, Imf::INCREASING_Y, compression),
                            Imf::WRITE_RGBA);
    out.setFrameBuffer(pixels.data(), 1, kW);
    out.writePixels(kH);
  }
}

// --- Radiance HDR (RGBE): probes and env maps.
void RunHdr(const uint8_t* data, size_t size) {
  const fs::path path = Scratch() / "input.hdr";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("hdr", [&] { scene::ProbeEnvMap(path); });
  ExpectOnlyInputErrors("hdr", [&] {
    const HdrImage image = scene::ReadHdrImage(path);
    scene::CheckLightProbe(image, path.string());
  });
}

void SeedsHdr(const fs::path& dir) {
  // OpenCV writes run-length encoded scanlines for rows of 8 to 32767 pixels, flat ones below.
  for (const cv::Size size : {cv::Size(64, 32), cv::Size(4, 2)}) {
    cv::Mat bgr(size, CV_32FC3);
    for (int y = 0; y < size.height; ++y) {
      for (int x = 0; x < size.width; ++x) {
        const float fx = static_cast<float>(x), fy = static_cast<float>(y);
        bgr.at<cv::Vec3f>(y, x) = cv::Vec3f(0.1f * fx, 0.2f * fy, 1.0f + fx * fy);
      }
    }
    cv::imwrite((dir / ("map_" + std::to_string(size.width) + ".hdr")).string(), bgr);
  }
}

// --- glTF 2.0 objects (.gltf JSON with its buffers, or .glb).
void RunGltf(const uint8_t* data, size_t size) {
  const bool binary = size >= 4 && std::string_view(reinterpret_cast<const char*>(data), 4) == "glTF";
  scene::VirtualObject object;
  object.kind = scene::MeshKind::kFile;
  object.file = Scratch() / (binary ? "object.glb" : "object.gltf");
  object.resource_root = Scratch();  // a uri that climbs out is refused, as in a recording
  WriteBytes(object.file, data, size);
  ExpectOnlyInputErrors("gltf", [&] {
    const scene::Mesh mesh = scene::ObjectMesh(object);
    scene::IsClosedMesh(mesh.positions, mesh.indices);
  });
}

void SeedsGltf(const fs::path& dir) {
  // A tetrahedron: 4 float positions and 12 uint16 indices in one buffer (72 bytes).
  const float positions[12] = {0, 0, 0, 1, 0, 0, 0, 0, -1, 0, 2, 0};
  const uint16_t indices[12] = {0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3};
  std::string buffer(reinterpret_cast<const char*>(positions), sizeof(positions));
  buffer.append(reinterpret_cast<const char*>(indices), sizeof(indices));
  const auto gltf = [&](const std::string& uri) {
    nlohmann::json j = {
        {"asset", {{"version", "2.0"}}}, {"scene", 0}, {"scenes", {{{"nodes", {0}}}}},
        {"nodes", {{{"mesh", 0}, {"translation", {1, 0, 0}}, {"rotation", {0, 0, 0, 1}}, {"scale", {1, 1, 1}}}}},
        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"indices", 1}}}}}}},
        {"buffers", {{{"byteLength", 72}}}},
        {"bufferViews", {{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 48}}, {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 24}}}},
        {"accessors", {{{"bufferView", 0}, {"componentType", 5126}, {"count", 4}, {"type", "VEC3"}, {"min", {0, 0, -1}}, {"max", {1, 2, 0}}},
                       {{"bufferView", 1}, {"componentType", 5123}, {"count", 12}, {"type", "SCALAR"}}}}};
    if (!uri.empty()) j["buffers"][0]["uri"] = uri;
    return j.dump();
  };
  // Embedded as a data URI (base64 of the 72 bytes).
  static constexpr char kAlphabet[] = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string base64;
  for (size_t i = 0; i < buffer.size(); i += 3) {
    const uint32_t n = (static_cast<uint8_t>(buffer[i]) << 16) |
                       (i + 1 < buffer.size() ? static_cast<uint8_t>(buffer[i + 1]) << 8 : 0) |
                       (i + 2 < buffer.size() ? static_cast<uint8_t>(buffer[i + 2]) : 0);
    base64 += kAlphabet[(n >> 18) & 63], base64 += kAlphabet[(n >> 12) & 63];
    base64 += i + 1 < buffer.size() ? kAlphabet[(n >> 6) & 63] : '=';
    base64 += i + 2 < buffer.size() ? kAlphabet[n & 63] : '=';
  }
  WriteText(dir / "embedded.gltf", gltf("data:application/octet-stream;base64," + base64));
  WriteText(dir / "escaping.gltf", gltf("%2e%2e/%2E%2e/../etc/passwd"));
  // The same as .glb: header, a JSON chunk padded with spaces, a BIN chunk.
  std::string json = gltf("");
  while (json.size() % 4 != 0) json += ' ';
  const auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string glb = "glTF" + u32(2) + u32(static_cast<uint32_t>(12 + 8 + json.size() + 8 + buffer.size())) +
                          u32(static_cast<uint32_t>(json.size())) + "JSON" + json +
                          u32(static_cast<uint32_t>(buffer.size())) + std::string("BIN\0", 4) + buffer;
  WriteText(dir / "tetrahedron.glb", glb);
}

// --- The bake cache: one of its five files replaced by the input (its first byte says which),
// the others as the bake wrote them; LoadBake must use it or refuse it, never crash.
constexpr const char* kBakeFiles[] = {"bake.json", "env_maps.exr", "camera_gbuffer.exr", "gather.exr", "albedo.csv"};
struct BakeCache {
  fs::path dir;
  std::string hash;
  std::vector<std::string> pristine;  // each file's bytes as baked
};

BakeCache& Cache() {
  static BakeCache* cache = [] {
    auto* c = new BakeCache;
    const scene::Scene scene = scene::LoadScene(Recording().dir / "scene.json");
    bake::BakeOptions options;
    options.gather_directions = 64;
    c->dir = Scratch() / "bake";
    bake::SaveBake(bake::RunBake(scene, options), scene, options, c->dir);
    c->hash = bake::BakeHash(scene, options);
    for (const char* file : kBakeFiles) c->pristine.push_back(ReadBytes(c->dir / file));
    return c;
  }();
  return *cache;
}

void RunBakeCache(const uint8_t* data, size_t size) {
  if (size == 0) return;
  BakeCache& cache = Cache();
  const size_t which = data[0] % std::size(kBakeFiles);
  for (size_t i = 0; i < std::size(kBakeFiles); ++i) WriteText(cache.dir / kBakeFiles[i], cache.pristine[i]);
  WriteBytes(cache.dir / kBakeFiles[which], data + 1, size - 1);
  ExpectOnlyInputErrors("bake_cache", [&] { bake::LoadBake(cache.dir, cache.hash); });
}

void SeedsBakeCache(const fs::path& dir) {
  const BakeCache& cache = Cache();
  for (size_t i = 0; i < std::size(kBakeFiles); ++i) {
    WriteText(dir / (std::string(kBakeFiles[i]) + ".seed"), std::string(1, static_cast<char>(i)) + cache.pristine[i]);
  }
}

// A recording's video, decoded as every command reads it: opened, up to 8 frames read, a seek
// back to the first and one more read. A stream that cannot be read is an InputError; one that
// decodes in part goes on (errors counted).
void RunVideo(const uint8_t* data, size_t size) {
  const fs::path path = Scratch() / "video.mp4";
  WriteBytes(path, data, size);
  ExpectOnlyInputErrors("video", [&] {
    capture::VideoDecoder decoder(path);
    cv::Mat rgb;
    for (int i = 0; i < 8 && decoder.Next(&rgb); ++i) {
    }
    decoder.Seek(0);
    decoder.Next(&rgb);
  });
}

// Small videos as the recordings' (H.264 in MP4 and in Matroska, a few frames of a gradient).
void SeedsVideo(const fs::path& dir) {
  for (const char* name : {"tiny.mp4", "tiny.mkv"}) {
    capture::VideoEncoderOptions options;
    options.fps = 10.0;
    capture::VideoEncoder encoder(dir / name, 32, 16, options);
    for (int f = 0; f < 4; ++f) {
      cv::Mat rgb(16, 32, CV_32FC3);
      for (int y = 0; y < rgb.rows; ++y) {
        for (int x = 0; x < rgb.cols; ++x) rgb.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(x) / 32.0f, static_cast<float>(y) / 16.0f, static_cast<float>(f) / 4.0f);
      }
      encoder.Write(rgb);
    }
    encoder.Finish();
  }
}

// The bytes a client sends the lighting server, read as request heads one after another as a
// kept-alive connection would. The reader throws nothing; what it says must hold for the bytes.
void RunHttpRequest(const uint8_t* data, size_t size) {
  serve::RequestLimits limits;
  limits.max_line = 256, limits.max_fields = 8, limits.max_field_bytes = 1024;  // reachable by short inputs
  serve::RequestReader reader(limits);
  std::string input(reinterpret_cast<const char*>(data), size);
  const auto fail = [](const char* what) {
    std::fprintf(stderr, "fuzz target http_request: %s\n", what);
    std::abort();
  };
  for (;;) {
    const size_t before = input.size();
    const serve::RequestReader::State state = reader.Read(&input);
    if (input.size() > before) fail("the input grew");
    if (state == serve::RequestReader::State::kReading) {
      if (input.find('\n') != std::string::npos || input.size() > limits.max_line) fail("waits with a line to read");
      return;
    }
    if (state == serve::RequestReader::State::kRefused) {
      const int s = reader.status();
      if ((s != 400 && s != 414 && s != 431) || reader.reason().empty()) fail("a refusal without its status");
      return;
    }
    if (reader.method().empty() || reader.target().empty() || reader.method().find(' ') != std::string::npos) {
      fail("a request without a method or target");
    }
    if (input.size() == before) fail("complete without reading");
    reader.Reset();
  }
}

void SeedsHttpRequest(const fs::path& dir) {
  WriteText(dir / "get.seed", "GET /lighting?at=1,2,3 HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n");
  WriteText(dir / "pipelined.seed", "GET /scene HTTP/1.1\r\n\r\nGET /stream HTTP/1.0\r\nConnection: keep-alive\r\n\r\n");
  WriteText(dir / "body.seed", "POST / HTTP/1.1\nContent-Length: 3\n\nabc");
}

}  // namespace

void ExpectOnlyInputErrors(std::string_view target, const std::function<void()>& body) {
  try {
    body();
  } catch (const InputError&) {
    // The answer to bad input.
  } catch (const std::exception& e) {
    std::fprintf(stderr, "fuzz target %.*s: not an InputError: %s\n", static_cast<int>(target.size()), target.data(), e.what());
    std::abort();
  }
}

const std::vector<Target>& Targets() {
  static const std::vector<Target> targets = {
      {"scene_json", [] { QuietLogs(), Recording(); }, RunSceneJson, SeedsSceneJson},
      {"obj", QuietLogs, RunObj, SeedsObj},
      {"csv", QuietLogs, RunCsv, SeedsCsv},
      {"exr", QuietLogs, RunExr, SeedsExr},
      {"hdr", QuietLogs, RunHdr, SeedsHdr},
      {"gltf", QuietLogs, RunGltf, SeedsGltf},
      {"bake_cache", [] { QuietLogs(), Cache(); }, RunBakeCache, SeedsBakeCache},
      {"video", [] { QuietLogs(), capture::RouteLibavLogging(); }, RunVideo, SeedsVideo},
      {"http_request", QuietLogs, RunHttpRequest, SeedsHttpRequest},
  };
  return targets;
}

const Target& FindTarget(std::string_view name) {
  for (const Target& t : Targets()) {
    if (t.name == name) return t;
  }
  std::fprintf(stderr, "no fuzz target '%.*s'\n", static_cast<int>(name.size()), name.data());
  std::abort();
}

}  // namespace daylit::fuzz
