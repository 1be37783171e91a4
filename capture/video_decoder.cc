#include "capture/video_decoder.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/imgutils.h>
}

#include <algorithm>

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

  ~State() {
    av_frame_free(&frame);
    av_packet_free(&packet);
    avcodec_free_context(&codec);
    avformat_close_input(&format);
  }
};

VideoDecoder::VideoDecoder(const std::filesystem::path& path) : state_(std::make_unique<State>()) {
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
    ThrowInputError("{}: pixel format {} is not supported (expected yuv420p)", path.string(),
                    av_get_pix_fmt_name(s.codec->pix_fmt));
  }
  s.packet = av_packet_alloc();
  s.frame = av_frame_alloc();
}

VideoDecoder::~VideoDecoder() = default;

int VideoDecoder::width() const { return state_->codec->width; }
int VideoDecoder::height() const { return state_->codec->height; }
int VideoDecoder::frames_read() const { return state_->frames; }
int VideoDecoder::errors() const { return state_->errors; }
const char* VideoDecoder::matrix() const { return state_->codec->colorspace == AVCOL_SPC_BT709 ? "BT.709" : "BT.601"; }

bool VideoDecoder::Next(cv::Mat* rgb) {
  State& s = *state_;
  for (;;) {
    const int received = avcodec_receive_frame(s.codec, s.frame);
    if (received == 0) {
      if (s.frame->color_range == AVCOL_RANGE_JPEG || s.codec->pix_fmt == AV_PIX_FMT_YUVJ420P) {
        ThrowInputError("{}: full-range YUV is not supported (expected limited range)", s.path.string());
      }
      Yuv420ToRgb(s.frame->data[0], s.frame->linesize[0], s.frame->data[1], s.frame->linesize[1], s.frame->data[2],
                  s.frame->linesize[2], s.frame->width, s.frame->height, s.frame->colorspace == AVCOL_SPC_BT709, rgb);
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
  // Chroma upsampled to full resolution first (bilinear; left-sited horizontally, centred
  // vertically), then the matrix per pixel.
  std::vector<float> cb(static_cast<size_t>(width) * height), cr(cb.size());
  for (int row = 0; row < height; ++row) {
    const float cy = std::clamp((static_cast<float>(row) - 0.5f) * 0.5f, 0.0f, static_cast<float>(ch - 1));
    const int y0 = static_cast<int>(cy), y1 = std::min(y0 + 1, ch - 1);
    const float fy = cy - static_cast<float>(y0);
    for (int col = 0; col < width; ++col) {
      const float cx = std::min(static_cast<float>(col) * 0.5f, static_cast<float>(cw - 1));
      const int x0 = static_cast<int>(cx), x1 = std::min(x0 + 1, cw - 1);
      const float fx = cx - static_cast<float>(x0);
      const auto sample = [&](const uint8_t* plane, int stride) {
        const float top = (1 - fx) * plane[y0 * stride + x0] + fx * plane[y0 * stride + x1];
        const float bottom = (1 - fx) * plane[y1 * stride + x0] + fx * plane[y1 * stride + x1];
        return ((1 - fy) * top + fy * bottom - 128.0f) / 224.0f;
      };
      const size_t i = static_cast<size_t>(row) * width + col;
      cb[i] = sample(u, u_stride);
      cr[i] = sample(v, v_stride);
    }
  }
  for (int row = 0; row < height; ++row) {
    cv::Vec3f* out = rgb->ptr<cv::Vec3f>(row);
    for (int col = 0; col < width; ++col) {
      const size_t i = static_cast<size_t>(row) * width + col;
      const float luma = (static_cast<float>(y[row * y_stride + col]) - 16.0f) / 219.0f;
      out[col][0] = std::clamp(luma + r_cr * cr[i], 0.0f, 1.0f);
      out[col][1] = std::clamp(luma + g_cb * cb[i] + g_cr * cr[i], 0.0f, 1.0f);
      out[col][2] = std::clamp(luma + b_cb * cb[i], 0.0f, 1.0f);
    }
  }
}

}  // namespace daylit::capture
