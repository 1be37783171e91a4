#include "bake/texture_detail.h"

#include "base/options_check.h"

#include <algorithm>
#include <array>
#include <cmath>

#include <glm/gtc/constants.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "base/log.h"
#include "capture/frame_reader.h"
#include "scene/hdr_image.h"

namespace daylit::bake {
namespace {

// Box sizes the per-pixel footprint is rounded to.
constexpr std::array<int, 11> kBoxSizes = {1, 3, 5, 7, 9, 11, 13, 15, 17, 21, 25};
constexpr int kMinSamples = 3;  // usable frames needed for a pixel's median

// Linear float BGR of a decoded frame: 8-bit through the camera response; EXR is linear already.
// Saturated or nearly black codes are marked NaN: their ratio says nothing.
cv::Mat Linearize(const cv::Mat& frame, const capture::CameraResponse& response) {
  cv::Mat out(frame.size(), CV_32FC3);
  if (frame.depth() == CV_32F) return frame;
  // BGR: channel c of the image is response channel 2 − c.
  const std::array<std::array<float, 256>, 3> lut = {response.LinearLut8(2), response.LinearLut8(1), response.LinearLut8(0)};
  for (int y = 0; y < frame.rows; ++y) {
    const cv::Vec3b* in = frame.ptr<cv::Vec3b>(y);
    cv::Vec3f* o = out.ptr<cv::Vec3f>(y);
    for (int x = 0; x < frame.cols; ++x) {
      for (int c = 0; c < 3; ++c) o[x][c] = in[x][c] >= 250 || in[x][c] <= 3 ? NAN : lut[static_cast<size_t>(c)][in[x][c]];
    }
  }
  return out;
}

std::vector<cv::Mat> ReadFrames(const scene::Scene& scene, const std::vector<int>& indices) {
  if (scene.frames.kind == scene::FrameSourceKind::kVideo) return capture::ReadVideoFrames(scene.frames.video, indices);
  std::vector<cv::Mat> frames;
  for (const int i : indices) {
    const std::filesystem::path path = scene.frames.ImagePath(i);
    if (path.extension() == ".exr") {
      HdrImage image = scene::ReadHdrImage(path);
      cv::Mat rgb(image.height, image.width, CV_32FC3, image.rgb.data());
      cv::Mat bgr;
      cv::cvtColor(rgb, bgr, cv::COLOR_RGB2BGR);
      frames.push_back(bgr);
    } else {
      frames.push_back(cv::imread(path.string(), cv::IMREAD_COLOR));
    }
  }
  return frames;
}

// Which box each pixel uses (an index into kBoxSizes; −1: no point): an env texel (π/H rad
// seen from the capture point) in camera pixels.
std::vector<int8_t> BoxPerPixel(const scene::Scene& scene, const std::vector<glm::vec3>& points,
                                const std::vector<uint8_t>& has_point, int env_height, float footprint_scale) {
  const glm::vec3 capture(scene.envmap->position);
  const glm::vec3 center(scene.Camera().CenterInWorld());
  const float texel_rad = glm::pi<float>() / static_cast<float>(env_height);
  const float focal = static_cast<float>(0.5 * (scene.intrinsics.fx + scene.intrinsics.fy));
  std::vector<int8_t> box(points.size(), -1);
  for (size_t i = 0; i < points.size(); ++i) {
    if (!has_point[i]) continue;
    const float pixels = footprint_scale * glm::length(points[i] - capture) * texel_rad * focal /
                         glm::length(points[i] - center);
    size_t b = 0;
    while (b + 1 < kBoxSizes.size() && static_cast<float>(kBoxSizes[b + 1]) <= pixels + 1.0f) ++b;
    box[i] = static_cast<int8_t>(b);
  }
  return box;
}

// The pixels of one surface, the boxes they use, and the rectangle they and their boxes cover.
struct SurfacePixels {
  uint32_t surface = 0;
  std::array<bool, kBoxSizes.size()> used{};
  cv::Rect rect;  // the surface's pixels' bounding box grown by its largest box's half width
};

std::vector<SurfacePixels> GroupBySurface(const std::vector<uint32_t>& surface, const std::vector<int8_t>& box, int w, int h) {
  std::vector<SurfacePixels> groups;
  std::vector<int> group_of;  // surface id → index into groups, −1: none yet
  for (size_t i = 0; i < box.size(); ++i) {
    if (box[i] < 0) continue;
    if (surface[i] >= group_of.size()) group_of.resize(surface[i] + 1, -1);
    int& g = group_of[surface[i]];
    const cv::Rect pixel(static_cast<int>(i % static_cast<size_t>(w)), static_cast<int>(i / static_cast<size_t>(w)), 1, 1);
    if (g < 0) g = static_cast<int>(groups.size()), groups.push_back({surface[i], {}, pixel});
    SurfacePixels& group = groups[static_cast<size_t>(g)];
    group.used[static_cast<size_t>(box[i])] = true;
    group.rect |= pixel;
  }
  for (SurfacePixels& group : groups) {
    int reach = 0;
    for (size_t b = 0; b < kBoxSizes.size(); ++b) {
      if (group.used[b]) reach = kBoxSizes[b] / 2;
    }
    const cv::Rect& r = group.rect;
    group.rect = cv::Rect(r.x - reach, r.y - reach, r.width + 2 * reach, r.height + 2 * reach) & cv::Rect(0, 0, w, h);
  }
  return groups;
}

// One linear frame's I / blur(I) per pixel and channel, with the pixel's own box over its own
// surface's pixels, added to `samples` (channels in BGR order, as OpenCV's). Masked box means:
// the values blurred with NaN and other surfaces as 0, divided by the blurred mask.
void AddFrameDetail(const cv::Mat& linear, const std::vector<uint32_t>& surface, const std::vector<int8_t>& box,
                    const std::vector<SurfacePixels>& groups, std::vector<std::array<std::vector<float>, 3>>* samples) {
  const int w = linear.cols;
  for (const SurfacePixels& group : groups) {
    const cv::Rect& r = group.rect;
    cv::Mat values(r.size(), CV_32FC3), valid(r.size(), CV_32FC3);
    for (int y = 0; y < r.height; ++y) {
      const cv::Vec3f* l = linear.ptr<cv::Vec3f>(r.y + y) + r.x;
      cv::Vec3f* v = values.ptr<cv::Vec3f>(y);
      cv::Vec3f* m = valid.ptr<cv::Vec3f>(y);
      for (int x = 0; x < r.width; ++x) {
        const size_t i = static_cast<size_t>(r.y + y) * w + static_cast<size_t>(r.x + x);
        const bool own = box[i] >= 0 && surface[i] == group.surface;
        for (int c = 0; c < 3; ++c) {
          const bool ok = own && !std::isnan(l[x][c]);
          m[x][c] = ok ? 1.0f : 0.0f;
          v[x][c] = ok ? l[x][c] : 0.0f;
        }
      }
    }
    for (size_t b = 0; b < kBoxSizes.size(); ++b) {
      if (!group.used[b]) continue;
      cv::Mat sum, weight;
      const cv::Size size(kBoxSizes[b], kBoxSizes[b]);
      cv::blur(values, sum, size, cv::Point(-1, -1), cv::BORDER_CONSTANT);
      cv::blur(valid, weight, size, cv::Point(-1, -1), cv::BORDER_CONSTANT);
      for (int y = 0; y < r.height; ++y) {
        const cv::Vec3f* l = linear.ptr<cv::Vec3f>(r.y + y) + r.x;
        const cv::Vec3f* s = sum.ptr<cv::Vec3f>(y);
        const cv::Vec3f* wt = weight.ptr<cv::Vec3f>(y);
        for (int x = 0; x < r.width; ++x) {
          const size_t i = static_cast<size_t>(r.y + y) * w + static_cast<size_t>(r.x + x);
          if (box[i] != static_cast<int8_t>(b) || surface[i] != group.surface) continue;
          for (int c = 0; c < 3; ++c) {
            if (std::isnan(l[x][c]) || !(wt[x][c] > 0.0f)) continue;
            const float mean = s[x][c] / wt[x][c];
            if (mean > 1e-4f) (*samples)[i][static_cast<size_t>(2 - c)].push_back(l[x][c] / mean);
          }
        }
      }
    }
  }
}

}  // namespace

std::vector<glm::vec3> CameraTextureDetail(const scene::Scene& scene, const std::vector<glm::vec3>& points,
                                           const std::vector<uint32_t>& surface, const std::vector<uint8_t>& has_point,
                                           int env_height, const DetailOptions& options) {
  const int w = scene.intrinsics.width, h = scene.intrinsics.height;
  std::vector<glm::vec3> detail(static_cast<size_t>(w) * h, glm::vec3(1.0f));
  if (!scene.frame_times || scene.frame_times->frames.empty() || options.frames <= 0) return detail;
  const int count = static_cast<int>(scene.frame_times->frames.size());
  std::vector<int> indices;
  for (int k = 0; k < options.frames; ++k) {
    const int i = static_cast<int>((k + 0.5) * count / options.frames);
    if (indices.empty() || i > indices.back()) indices.push_back(std::min(i, count - 1));
  }
  const std::vector<cv::Mat> frames = ReadFrames(scene, indices);
  const std::vector<int8_t> box = BoxPerPixel(scene, points, has_point, env_height, options.footprint_scale);
  const std::vector<SurfacePixels> groups = GroupBySurface(surface, box, w, h);
  std::vector<std::array<std::vector<float>, 3>> samples(detail.size());
  size_t decoded = 0;
  for (const cv::Mat& frame : frames) {
    if (frame.empty() || frame.cols != w || frame.rows != h) continue;
    ++decoded;
    AddFrameDetail(Linearize(frame, scene.response), surface, box, groups, &samples);
  }
  if (decoded == 0) {
    Log().warn("{}: no frame could be read: camera albedo keeps the env map's resolution", scene.file.string());
    return detail;
  }
  for (size_t i = 0; i < detail.size(); ++i) {
    for (size_t c = 0; c < 3; ++c) {
      std::vector<float>& s = samples[i][c];
      if (static_cast<int>(s.size()) < std::min(kMinSamples, static_cast<int>(decoded))) continue;
      std::nth_element(s.begin(), s.begin() + static_cast<ptrdiff_t>(s.size() / 2), s.end());
      detail[i][static_cast<int>(c)] = std::clamp(s[s.size() / 2], 0.2f, 5.0f);
    }
  }
  return detail;
}

std::string DetailOptions::Check() const {
  return FirstProblem({InClosed("frames", frames, 1, 1000), InOpenClosed("footprint_scale", footprint_scale, 0.0f, 16.0f)});
}

}  // namespace daylit::bake
