#include "scene/hdr_image.h"
#include "scene/radiance_hdr.h"

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>
#include <ImfStdIO.h>
#include <half.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <fstream>


#include "base/atomic_file.h"
#include "base/error.h"
#include "base/files.h"

namespace daylit::scene {
namespace {

Imf::PixelType ToImf(ExrPixelType type) {
  switch (type) {
    case ExrPixelType::kHalf: return Imf::HALF;
    case ExrPixelType::kFloat: return Imf::FLOAT;
    case ExrPixelType::kUint: return Imf::UINT;
  }
  return Imf::FLOAT;
}

// Reads `names` as floats and `uint_names` as UINT in one pass (missing channels: error).
ExrChannels ReadPlanes(const std::filesystem::path& path, const std::vector<std::string>& names,
                       const std::vector<std::string>& uint_names) {
  ExrChannels out;
  // Half floats at least (2 bytes) for each channel asked for.
  CheckExrClaimedSize(path, 2 * static_cast<int64_t>(names.size() + uint_names.size()));
  Imf::InputFile file(path.c_str());
  const Imath::Box2i window = file.header().dataWindow();
  const int64_t width = int64_t{window.max.x} - window.min.x + 1, height = int64_t{window.max.y} - window.min.y + 1;
  CheckClaimedSize(path, width, height, 2 * static_cast<int64_t>(names.size() + uint_names.size()));
  out.width = static_cast<int>(width);
  out.height = static_cast<int>(height);
  const size_t count = static_cast<size_t>(out.width) * out.height;
  // Slices are addressed in data-window coordinates, so offset each base by the window's origin.
  const ptrdiff_t origin = static_cast<ptrdiff_t>(window.min.y) * out.width + window.min.x;
  const auto require = [&](const std::string& name) {
    if (file.header().channels().findChannel(name) == nullptr) ThrowInputError("{}: no channel '{}'", path.string(), name);
  };
  Imf::FrameBuffer frame;
  out.planes.resize(names.size());
  for (size_t i = 0; i < names.size(); ++i) {
    require(names[i]);
    out.planes[i].resize(count);
    char* base = reinterpret_cast<char*>(out.planes[i].data() - origin);
    frame.insert(names[i], Imf::Slice(Imf::FLOAT, base, sizeof(float), sizeof(float) * static_cast<size_t>(out.width)));
  }
  out.uints.resize(uint_names.size());
  for (size_t i = 0; i < uint_names.size(); ++i) {
    require(uint_names[i]);
    out.uints[i].resize(count);
    char* base = reinterpret_cast<char*>(out.uints[i].data() - origin);
    frame.insert(uint_names[i], Imf::Slice(Imf::UINT, base, sizeof(uint32_t), sizeof(uint32_t) * static_cast<size_t>(out.width)));
  }
  file.setFrameBuffer(frame);
  file.readPixels(window.min.y, window.max.y);
  return out;
}

HdrImage ReadExrRgb(const std::filesystem::path& path) {
  std::vector<std::string> names;
  {
    Imf::InputFile probe(path.c_str());
    const Imf::ChannelList& channels = probe.header().channels();
    if (channels.findChannel("R") && channels.findChannel("G") && channels.findChannel("B")) {
      names = {"R", "G", "B"};
    } else if (channels.findChannel("Y")) {
      names = {"Y"};
    } else {
      ThrowInputError("{}: no R, G, B or Y channels", path.string());
    }
  }
  const ExrChannels planes = ReadPlanes(path, names, {});
  HdrImage image{planes.width, planes.height, {}};
  image.rgb.resize(static_cast<size_t>(image.width) * image.height * 3);
  for (size_t i = 0; i < static_cast<size_t>(image.width) * image.height; ++i) {
    for (size_t c = 0; c < 3; ++c) image.rgb[i * 3 + c] = planes.planes[names.size() == 3 ? c : 0][i];
  }
  return image;
}

}  // namespace

void CheckExrClaimedSize(const std::filesystem::path& path, int64_t bytes_per_pixel) {
  // The header as OpenEXR 2.0 lays it out: magic 76 2f 31 01, a version word (bit 9: tiled,
  // 11: deep, 12: multi-part), then attributes "name\0type\0" + int32 size + value, up to an
  // empty name. The data window is a box2i (four int32: x min, y min, x max, y max). Read here,
  // before OpenEXR builds anything from it.
  std::ifstream in(path, std::ios::binary);
  char head[8];
  if (!in.read(head, 8) || static_cast<unsigned char>(head[0]) != 0x76 || head[1] != 0x2f || head[2] != 0x31 || head[3] != 0x01) {
    return;  // not an OpenEXR file: OpenEXR says so
  }
  const uint32_t flags = static_cast<uint8_t>(head[5]) | (static_cast<uint32_t>(static_cast<uint8_t>(head[6])) << 8);
  const bool plain_scanlines = (flags & ((1u << 1) | (1u << 3) | (1u << 4))) == 0;  // bits 9, 11, 12
  std::error_code ec;
  const auto file_bytes = static_cast<int64_t>(std::filesystem::file_size(path, ec));
  if (ec) return;
  int32_t box[4] = {0, 0, -1, -1};
  int compression = -1;
  bool header_read = false;
  for (int attributes = 0; attributes < 1000; ++attributes) {
    std::string name, type;
    if (!std::getline(in, name, '\0') || name.size() > 255) return;
    if (name.empty()) {
      header_read = true;
      break;
    }
    if (!std::getline(in, type, '\0') || type.size() > 255) return;
    int32_t size = 0;
    if (!in.read(reinterpret_cast<char*>(&size), 4)) return;
    if (size < 0 || static_cast<int64_t>(in.tellg()) + size > file_bytes) {
      // OpenEXR would allocate it (up to 2 GB) before it finds the file short.
      ThrowInputError("{}: its header's attribute '{}' claims {} bytes past the end of the file: truncated or damaged",
                      path.string(), Excerpt(name), size);
    }
    if (name == "dataWindow" && type == "box2i" && size == 16) {
      if (!in.read(reinterpret_cast<char*>(box), 16)) return;
      CheckClaimedSize(path, int64_t{box[2]} - box[0] + 1, int64_t{box[3]} - box[1] + 1, bytes_per_pixel);
      continue;
    }
    if (name == "compression" && type == "compression" && size == 1) {
      char c = 0;
      if (!in.read(&c, 1)) return;
      compression = static_cast<uint8_t>(c);
      continue;
    }
    in.seekg(size, std::ios::cur);
  }
  // A plain scan-line file: its offset table, then chunks of "int32 y, int32 size, data". A
  // chunk that claims more bytes than the file holds would have OpenEXR allocate them (up to
  // 2 GB) before it finds the file short.
  constexpr int kLinesPerChunk[] = {1, 1, 1, 16, 32, 16, 32, 32, 32, 256};  // NONE ... DWAB
  if (!header_read || !plain_scanlines || compression < 0 || compression >= static_cast<int>(std::size(kLinesPerChunk)) ||
      box[3] < box[1]) {
    return;
  }
  const int64_t rows = int64_t{box[3]} - box[1] + 1;
  const int64_t chunks = (rows + kLinesPerChunk[compression] - 1) / kLinesPerChunk[compression];
  std::vector<uint64_t> offsets(static_cast<size_t>(chunks));
  if (!in.read(reinterpret_cast<char*>(offsets.data()), static_cast<std::streamsize>(chunks * 8))) {
    ThrowInputError("{}: truncated (its table of {} chunks ends early)", path.string(), chunks);
  }
  for (const uint64_t offset : offsets) {
    // OpenEXR rebuilds a damaged table by itself; only chunks it points into the file are read.
    if (offset == 0 || offset > static_cast<uint64_t>(file_bytes) - 8) continue;
    int32_t chunk[2];
    in.seekg(static_cast<std::streamoff>(offset));
    if (!in.read(reinterpret_cast<char*>(chunk), 8)) return;
    if (chunk[1] < 0 || static_cast<int64_t>(offset) + 8 + chunk[1] > file_bytes) {
      ThrowInputError("{}: a chunk claims {} bytes past the end of the file: truncated or damaged", path.string(), chunk[1]);
    }
  }
}

void CheckClaimedSize(const std::filesystem::path& path, int64_t width, int64_t height, int64_t bytes_per_pixel) {
  if (width <= 0 || height <= 0) ThrowInputError("{}: its header gives an empty image ({}x{})", path.string(), width, height);
  if (width > kMostImagePixels / height) {
    ThrowInputError("{}: its header claims {}x{} pixels, over daylit's limit of 16384x8192", path.string(), width, height);
  }
  constexpr int64_t kMostCompression = 1032;
  std::error_code ec;
  const auto bytes = std::filesystem::file_size(path, ec);
  const int64_t least = width * height * bytes_per_pixel / kMostCompression;
  if (!ec && static_cast<int64_t>(bytes) < least) {
    ThrowInputError("{}: its header claims {}x{} pixels, which no compression fits in its {} bytes: truncated or damaged",
                    path.string(), width, height, bytes);
  }
}

void ReadRadianceSize(const std::filesystem::path& path, int* width, int* height) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError("{}: cannot be opened", path.string());
  // Header lines ("#?RADIANCE", "FORMAT=...", ...) up to a blank one, then the resolution line.
  std::string line;
  bool blank = false;
  for (int lines = 0; lines < 64 && std::getline(in, line); ++lines) {
    if (line.size() > 512) break;
    if (blank) {
      int h = 0, w = 0;
      char y_sign = 0, x_sign = 0;
      if (std::sscanf(line.c_str(), "%cY %d %cX %d", &y_sign, &h, &x_sign, &w) == 4 && (y_sign == '-' || y_sign == '+') &&
          (x_sign == '-' || x_sign == '+')) {
        *width = w, *height = h;
        return;
      }
      break;
    }
    blank = line.empty();
  }
  ThrowInputError("{}: not a Radiance HDR file (no resolution line after its header)", path.string());
}

HdrImage ReadHdrImage(const std::filesystem::path& path) {
  RequireRegularFile(path);
  if (path.extension() == ".exr") {
    CheckExrClaimedSize(path, 2);
    try {
      return ReadExrRgb(path);
    } catch (const InputError&) {
      throw;
    } catch (const std::exception& e) {
      ThrowInputError("{}: not a readable OpenEXR file ({})", path.string(), e.what());
    }
  }
  int width = 0, height = 0;
  ReadRadianceSize(path, &width, &height);
  CheckClaimedSize(path, width, height, 4);  // RGBE: 4 bytes a pixel
  HdrImage image{0, 0, {}};
  std::string why;
  if (!DecodeRadianceHdr(path, &image.width, &image.height, &image.rgb, &why)) {
    ThrowInputError("{}: not a readable Radiance HDR (or OpenEXR) image ({})", path.string(), why);
  }
  return image;
}

void CheckEnvMap(const HdrImage& image, const std::string& name) {
  if (image.width != 2 * image.height) {
    ThrowInputError("{}: {}x{} is not a 2:1 latitude-longitude map", name, image.width, image.height);
  }
  CheckLightProbe(image, name);
}

void CheckLightProbe(const HdrImage& image, const std::string& name) {
  if (image.width < kMinProbeWidth || image.height < kMinProbeWidth / 2) {
    ThrowInputError("{}: {}x{} is too small for a light probe (at least {} texels across: each under 6°)", name,
                    image.width, image.height, kMinProbeWidth);
  }
  CheckRadianceValues(image, name);
  if (std::none_of(image.rgb.begin(), image.rgb.end(), [](float v) { return v > 0.0f; })) {
    ThrowInputError("{}: every texel is black: a light probe with no light (estimates would be 0 and errors NaN)", name);
  }
}

void CheckRadianceValues(const HdrImage& image, const std::string& name) {
  size_t non_finite = 0, negative = 0, first = SIZE_MAX;
  for (size_t i = 0; i < image.rgb.size(); ++i) {
    const float v = image.rgb[i];
    const bool bad_value = !std::isfinite(v);
    const bool below_zero = std::isfinite(v) && v < 0.0f;
    non_finite += bad_value;
    negative += below_zero;
    if ((bad_value || below_zero) && first == SIZE_MAX) first = i / 3;
  }
  if (non_finite + negative > 0) {
    ThrowInputError("{}: {} texel values are NaN or infinite and {} are negative, first at (u {}, v {})", name,
                    non_finite, negative, first % static_cast<size_t>(image.width), first / static_cast<size_t>(image.width));
  }
}

namespace {

// The channels written into `stream` (ZIP compressed); what Imf throws is left to the caller.
void WriteExrTo(Imf::OStream& stream, int width, int height, const std::vector<ExrChannel>& channels) {
  const size_t count = static_cast<size_t>(width) * height;
  Imf::Header header(width, height);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::FrameBuffer frame;
  std::vector<std::vector<half>> halves;  // kHalf channels, converted
  halves.reserve(channels.size());
  for (const ExrChannel& c : channels) {
    header.channels().insert(c.name, Imf::Channel(ToImf(c.type)));
    if (c.type == ExrPixelType::kUint) {
      frame.insert(c.name, Imf::Slice(Imf::UINT, reinterpret_cast<char*>(const_cast<uint32_t*>(c.uints)),
                                      sizeof(uint32_t), sizeof(uint32_t) * static_cast<size_t>(width)));
    } else if (c.type == ExrPixelType::kHalf) {
      halves.emplace_back(count);
      for (size_t i = 0; i < count; ++i) halves.back()[i] = half(c.floats[i]);
      frame.insert(c.name, Imf::Slice(Imf::HALF, reinterpret_cast<char*>(halves.back().data()), sizeof(half),
                                      sizeof(half) * static_cast<size_t>(width)));
    } else {
      frame.insert(c.name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(const_cast<float*>(c.floats)),
                                      sizeof(float), sizeof(float) * static_cast<size_t>(width)));
    }
  }
  Imf::OutputFile file(stream, header);
  file.setFrameBuffer(frame);
  file.writePixels(height);
}

}  // namespace

void WriteExr(const std::filesystem::path& path, int width, int height, const std::vector<ExrChannel>& channels) {
  const std::filesystem::path tmp = TemporarySibling(path);
  try {
    Imf::StdOFStream stream(tmp.c_str());
    WriteExrTo(stream, width, height, channels);
  } catch (const std::exception& e) {
    std::error_code ec;
    std::filesystem::remove(tmp, ec);
    ThrowInputError("{}: cannot write OpenEXR ({})", path.string(), e.what());
  }
  CommitTemporary(tmp, path);
}

std::string EncodeExr(int width, int height, const std::vector<ExrChannel>& channels) {
  Imf::StdOSStream stream;
  WriteExrTo(stream, width, height, channels);
  return stream.str();
}

void WriteRgbExr(const std::filesystem::path& path, int width, int height, const float* rgb) {
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  std::vector<float> r(n), g(n), b(n);
  for (size_t i = 0; i < n; ++i) r[i] = rgb[3 * i], g[i] = rgb[3 * i + 1], b[i] = rgb[3 * i + 2];
  WriteExr(path, width, height, {{"R", ExrPixelType::kFloat, r.data(), nullptr},
                                 {"G", ExrPixelType::kFloat, g.data(), nullptr},
                                 {"B", ExrPixelType::kFloat, b.data(), nullptr}});
}

ExrChannels ReadExrChannels(const std::filesystem::path& path, const std::vector<std::string>& names,
                            const std::vector<std::string>& uint_names) {
  try {
    return ReadPlanes(path, names, uint_names);
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    ThrowInputError("{}: not a readable OpenEXR file ({})", path.string(), e.what());
  }
}

}  // namespace daylit::scene
