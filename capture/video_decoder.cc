#include "capture/video_decoder.h"

#include <cstring>

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
}

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdarg>
#include <string>

#include <opencv2/core/hal/hal.hpp>

#include "base/error.h"
#include "base/log.h"

namespace daylit::capture {

struct VideoDecoder::State {
  std::filesystem::path path;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVPacket* packet = nullptr;
  AVFrame* frame = nullptr;
  int stream = -1;
  bool draining = false;
  int frames = 0;
  int errors = 0;
  AVRational time_base{1, 1};
  double fps = 0.0;        // frames per second of the stream
  int64_t start_pts = 0;   // presentation time of frame 0
  int last_index = -1;
  int skip_until = -1;     // after Seek: frames before this are decoded and dropped

  int IndexOf(int64_t pts) const {
    if (pts == AV_NOPTS_VALUE || fps <= 0.0) return last_index + 1;
    return static_cast<int>(std::llround(static_cast<double>(pts - start_pts) * av_q2d(time_base) * fps));
  }

  ~State() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

namespace {

// libav's own messages ("Packet corrupt", "partial file") go to daylit's logger as debug lines;
// the decoder reports what matters for the user itself (a frame skipped, the stream ending).
void LogLibav(void* context, int level, const char* format, va_list args) {
  if (level > av_log_get_level()) return;
  char line[1024];
  int print_prefix = 1;
  av_log_format_line(context, level, format, args, line, sizeof(line), &print_prefix);
  std::string text(line);
  while (!text.empty() && text.back() == '\n') text.pop_back();
  Log().debug("libav: {}", text);
}

// libav keeps a stream's colour fields as they are coded (H.264's VUI allows any byte), which may
// be no value of their enum at all (134 as an AVColorSpace: undefined behaviour to load, found by
// fuzz_video under UBSan): read as the integer they are stored as.
template <typename Enum>
int RawValue(const Enum& field) {
  static_assert(sizeof(Enum) == sizeof(int));
  int value = 0;
  std::memcpy(&value, &field, sizeof(value));
  return value;
}

}  // namespace

void RouteLibavLogging() {
  static const bool routed = (av_log_set_callback(LogLibav), true);
  (void)routed;
}

VideoDecoder::VideoDecoder(const std::filesystem::path& path) : state_(std::make_unique<State>()) {
  RouteLibavLogging();
  State& s = *state_;
  s.path = path;
  if (avformat_open_input(&s.format, path.c_str(), nullptr, nullptr) < 0) {
    ThrowInputError("{}: cannot open as a video", path.string());
  }
  if (avformat_find_stream_info(s.format, nullptr) < 0) ThrowInputError("{}: no stream information", path.string());
  const AVCodec* decoder = nullptr;
  s.stream = av_find_best_stream(s.format, AVMEDIA_TYPE_VIDEO, -1, -1, &decoder, 0);
  if (s.stream < 0 || decoder == nullptr) ThrowInputError("{}: no decodable video stream", path.string());
  s.codec = avcodec_alloc_context3(decoder);
  avcodec_parameters_to_context(s.codec, s.format->streams[s.stream]->codecpar);
  s.codec->thread_count = 1;  // the pipeline runs frames on its own threads
  if (avcodec_open2(s.codec, decoder, nullptr) < 0) ThrowInputError("{}: cannot open the decoder", path.string());
  if (s.codec->pix_fmt != AV_PIX_FMT_YUV420P && s.codec->pix_fmt != AV_PIX_FMT_YUVJ420P) {
    // An undetermined format (AV_PIX_FMT_NONE) has no name: a null that fmt refuses with an
    // exception of its own (exit 3; found by fuzz_video).
    const char* name = av_get_pix_fmt_name(s.codec->pix_fmt);
    ThrowInputError("{}: pixel format {} is not supported (expected yuv420p)", path.string(),
                    name != nullptr ? name : "unknown");
  }
  s.packet = av_packet_alloc();
  s.frame = av_frame_alloc();
  const AVStream* stream = s.format->streams[s.stream];
  s.time_base = stream->time_base;
  // r_frame_rate: the rate every timestamp is a multiple of (the true rate of a constant-rate
  // stream even when frames are missing, where avg_frame_rate would be lower).
  const AVRational rate = stream->r_frame_rate.num > 0 ? stream->r_frame_rate : stream->avg_frame_rate;
  s.fps = rate.den > 0 ? av_q2d(rate) : 0.0;
  s.start_pts = stream->start_time == AV_NOPTS_VALUE ? 0 : stream->start_time;
}

int VideoDecoder::last_index() const { return state_->last_index; }

void VideoDecoder::Seek(int index) {
  State& s = *state_;
  if (s.fps <= 0.0) ThrowInputError("{}: the stream has no frame rate; it cannot be sought", s.path.string());
  const int64_t ts = s.start_pts + static_cast<int64_t>(std::llround(index / s.fps / av_q2d(s.time_base)));
  if (av_seek_frame(s.format, s.stream, ts, AVSEEK_FLAG_BACKWARD) < 0) {
    ThrowInputError("{}: cannot seek to frame {}", s.path.string(), index);
  }
  avcodec_flush_buffers(s.codec);
  s.draining = false;
  s.skip_until = index;
  s.last_index = index - 1;
}

VideoDecoder::~VideoDecoder() = default;

int VideoDecoder::width() const { return state_->codec->width; }
int VideoDecoder::height() const { return state_->codec->height; }
int VideoDecoder::frames_read() const { return state_->frames; }
int VideoDecoder::errors() const { return state_->errors; }
const char* VideoDecoder::matrix() const {
  return RawValue(state_->codec->colorspace) == AVCOL_SPC_BT709 ? "BT.709" : "BT.601";
}

bool VideoDecoder::Next(cv::Mat* rgb) {
  State& s = *state_;
  for (;;) {
    const int received = avcodec_receive_frame(s.codec, s.frame);
    if (received == 0 && s.IndexOf(s.frame->best_effort_timestamp) < s.skip_until) continue;  // before a Seek's target
    if (received == 0) {
      s.last_index = s.IndexOf(s.frame->best_effort_timestamp);
      if (RawValue(s.frame->color_range) == AVCOL_RANGE_JPEG || s.codec->pix_fmt == AV_PIX_FMT_YUVJ420P) {
        ThrowInputError("{}: full-range YUV is not supported (expected limited range)", s.path.string());
      }
      Yuv420ToRgb(s.frame->data[0], s.frame->linesize[0], s.frame->data[1], s.frame->linesize[1], s.frame->data[2],
                  s.frame->linesize[2], s.frame->width, s.frame->height, RawValue(s.frame->colorspace) == AVCOL_SPC_BT709, rgb);
      ++s.frames;
      return true;
    }
    if (received == AVERROR_EOF) return false;
    if (s.draining) return false;
    // Needs more input.
    const int read = av_read_frame(s.format, s.packet);
    if (read < 0) {
      s.draining = true;
      avcodec_send_packet(s.codec, nullptr);
      continue;
    }
    if (s.packet->stream_index == s.stream && avcodec_send_packet(s.codec, s.packet) < 0) {
      ++s.errors;
      Log().warn("{}: a packet near frame {} cannot be decoded; skipped", s.path.string(), s.frames);
    }
    av_packet_unref(s.packet);
  }
}

void Yuv420ToRgb(const uint8_t* y, int y_stride, const uint8_t* u, int u_stride, const uint8_t* v, int v_stride,
                 int width, int height, bool bt709, cv::Mat* rgb) {
  rgb->create(height, width, CV_32FC3);
  // Limited range: Y' = (Y − 16)/219, Cb, Cr = (C − 128)/224; then the matrix (ITU-R BT.601 /
  // BT.709, Kr, Kb = 0.299, 0.114 / 0.2126, 0.0722).
  const float kr = bt709 ? 0.2126f : 0.299f, kb = bt709 ? 0.0722f : 0.114f, kg = 1.0f - kr - kb;
  const float r_cr = 2.0f * (1.0f - kr), b_cb = 2.0f * (1.0f - kb);
  const float g_cb = -b_cb * kb / kg, g_cr = -r_cr * kr / kg;
  const int cw = (width + 1) / 2, ch = (height + 1) / 2;
  // Chroma is upsampled bilinearly (left-sited horizontally, centred vertically). The matrix is
  // linear in Cb and Cr, so each row first gets the three chroma terms of the matrix at the
  // chroma columns (interpolated vertically), then at every column (an even column sits on a
  // chroma sample, an odd one halfway), then adds its luma per channel into planar rows, which
  // OpenCV interleaves: every loop but the last runs on contiguous floats, which the compiler
  // vectorises (a loop storing R, G, B in turn did not: 1.1 ms a 960×540 frame, a quarter of the
  // decoder's time).
  const size_t n = static_cast<size_t>(width), nc = static_cast<size_t>(cw);
  std::vector<float> buffer(3 * (nc + 1) + 4 * n);
  float* const term[3] = {buffer.data(), buffer.data() + nc + 1, buffer.data() + 2 * (nc + 1)};
  float* const plane[3] = {buffer.data() + 3 * (nc + 1), buffer.data() + 3 * (nc + 1) + n, buffer.data() + 3 * (nc + 1) + 2 * n};
  float* const luma = buffer.data() + 3 * (nc + 1) + 3 * n;
  for (int row = 0; row < height; ++row) {
    const float cy = std::clamp((static_cast<float>(row) - 0.5f) * 0.5f, 0.0f, static_cast<float>(ch - 1));
    const int y0 = static_cast<int>(cy), y1 = std::min(y0 + 1, ch - 1);
    const float fy = cy - static_cast<float>(y0);
    const uint8_t *u0 = u + y0 * u_stride, *u1 = u + y1 * u_stride, *v0 = v + y0 * v_stride, *v1 = v + y1 * v_stride;
    for (size_t x = 0; x < nc; ++x) {
      const float cb = ((1.0f - fy) * u0[x] + fy * u1[x] - 128.0f) / 224.0f;
      const float cr = ((1.0f - fy) * v0[x] + fy * v1[x] - 128.0f) / 224.0f;
      term[0][x] = r_cr * cr;
      term[1][x] = g_cb * cb + g_cr * cr;
      term[2][x] = b_cb * cb;
    }
    const uint8_t* codes = y + row * y_stride;
    for (size_t col = 0; col < n; ++col) luma[col] = (static_cast<float>(codes[col]) - 16.0f) / 219.0f;
    for (int c = 0; c < 3; ++c) {
      float* t = term[c];
      float* out = plane[c];
      t[nc] = t[nc - 1];  // past the last chroma column the last one repeats
      for (size_t x = 0; 2 * x < n; ++x) out[2 * x] = std::clamp(luma[2 * x] + t[x], 0.0f, 1.0f);
      for (size_t x = 0; 2 * x + 1 < n; ++x) {
        out[2 * x + 1] = std::clamp(luma[2 * x + 1] + 0.5f * (t[x] + t[x + 1]), 0.0f, 1.0f);
      }
    }
    const int* planes[3] = {reinterpret_cast<const int*>(plane[0]), reinterpret_cast<const int*>(plane[1]),
                            reinterpret_cast<const int*>(plane[2])};
    cv::hal::merge32s(planes, rgb->ptr<int>(row), width, 3);  // floats moved as 32-bit words
  }
}

}  // namespace daylit::capture
