#include "capture/video_encoder.h"

#include "base/options_check.h"

extern "C" {
#include <libavcodec/avcodec.h>
#include <libavformat/avformat.h>
#include <libavutil/opt.h>
}

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/imgproc.hpp>

#include "base/error.h"
#include "capture/video_decoder.h"

namespace daylit::capture {
namespace {

// libav's words for an error code.
std::string AvError(int error) {
  char text[AV_ERROR_MAX_STRING_SIZE] = {};
  av_strerror(error, text, sizeof(text));
  return text;
}

}  // namespace

struct VideoEncoder::State {
  std::filesystem::path path;
  AVFormatContext* format = nullptr;
  AVCodecContext* codec = nullptr;
  AVStream* stream = nullptr;
  AVFrame* frame = nullptr;
  AVPacket* packet = nullptr;
  int64_t next_pts = 0;
  bool finished = false;

  ~State() {
    av_packet_free(&packet);
    av_frame_free(&frame);
    avcodec_free_context(&codec);
    if (format != nullptr) {
      if (format->pb != nullptr) avio_closep(&format->pb);
      avformat_free_context(format);
    }
  }

  // Moves every packet the encoder has ready into the file.
  void Drain() {
    while (avcodec_receive_packet(codec, packet) == 0) {
      av_packet_rescale_ts(packet, codec->time_base, stream->time_base);
      packet->stream_index = stream->index;
      if (const int error = av_interleaved_write_frame(format, packet); error < 0) {
        ThrowSystemError("{}: cannot write video data: {}", path.string(), AvError(error));
      }
    }
  }
};

VideoEncoder::VideoEncoder(const std::filesystem::path& path, int width, int height, const VideoEncoderOptions& options)
    : state_(std::make_unique<State>()) {
  RouteLibavLogging();
  State& s = *state_;
  s.path = path;
  if (const std::string why = options.Check(); !why.empty()) ThrowInputError("{}: {}", path.string(), why);
  if (width % 2 != 0 || height % 2 != 0) ThrowInputError("{}: {}x{}: H.264 4:2:0 needs even sizes", path.string(), width, height);
  if (avformat_alloc_output_context2(&s.format, nullptr, nullptr, path.c_str()) < 0 || s.format == nullptr) {
    ThrowInputError("{}: no video container for this file name (use .mp4 or .mkv)", path.string());
  }
  const AVCodec* encoder = avcodec_find_encoder_by_name("libx264");
  if (encoder == nullptr) ThrowSystemError("{}: this FFmpeg has no libx264 encoder (Debian's libavcodec has it: scripts/setup.sh)", path.string());
  s.stream = avformat_new_stream(s.format, nullptr);
  s.codec = avcodec_alloc_context3(encoder);
  const AVRational rate = av_d2q(options.fps, 100000);
  s.codec->width = width, s.codec->height = height;
  s.codec->pix_fmt = AV_PIX_FMT_YUV420P;
  s.codec->time_base = av_inv_q(rate);
  s.codec->framerate = rate;
  s.codec->color_range = AVCOL_RANGE_MPEG;
  s.codec->colorspace = AVCOL_SPC_SMPTE170M;  // BT.601
  s.codec->color_primaries = AVCOL_PRI_BT709;
  s.codec->color_trc = AVCOL_TRC_IEC61966_2_1;
  s.codec->thread_count = 1;  // the pipeline keeps the other core busy
  if (s.format->oformat->flags & AVFMT_GLOBALHEADER) s.codec->flags |= AV_CODEC_FLAG_GLOBAL_HEADER;
  av_opt_set(s.codec->priv_data, "preset", options.preset, 0);
  av_opt_set_int(s.codec->priv_data, "crf", options.crf, 0);
  if (const int error = avcodec_open2(s.codec, encoder, nullptr); error < 0) {
    ThrowSystemError("{}: cannot open the H.264 encoder: {}", path.string(), AvError(error));
  }
  avcodec_parameters_from_context(s.stream->codecpar, s.codec);
  s.stream->time_base = s.codec->time_base;
  s.stream->avg_frame_rate = rate;
  s.stream->r_frame_rate = rate;
  if (const int error = avio_open(&s.format->pb, path.c_str(), AVIO_FLAG_WRITE); error < 0) {
    ThrowInputError("{}: cannot open for writing: {}", path.string(), AvError(error));
  }
  if (const int error = avformat_write_header(s.format, nullptr); error < 0) {
    ThrowSystemError("{}: cannot write the video header: {}", path.string(), AvError(error));
  }
  s.frame = av_frame_alloc();
  s.frame->format = AV_PIX_FMT_YUV420P;
  s.frame->width = width, s.frame->height = height;
  if (av_frame_get_buffer(s.frame, 0) < 0) ThrowSystemError("{}: out of memory for a frame", path.string());
  s.packet = av_packet_alloc();
}

VideoEncoder::~VideoEncoder() {
  try {
    Finish();
  } catch (const std::exception&) {
    // Destructors do not throw; a caller that cares calls Finish() itself.
  }
}

void VideoEncoder::Write(const cv::Mat& frame) {
  State& s = *state_;
  cv::Mat rgb = frame;
  if (frame.type() == CV_8UC3) {
    cv::cvtColor(frame, rgb, cv::COLOR_BGR2RGB);
    rgb.convertTo(rgb, CV_32FC3, 1.0 / 255.0);
  }
  if (rgb.type() != CV_32FC3 || rgb.cols != s.codec->width || rgb.rows != s.codec->height) {
    ThrowInputError("{}: a {}x{} frame for a {}x{} video", s.path.string(), frame.cols, frame.rows, s.codec->width,
                    s.codec->height);
  }
  av_frame_make_writable(s.frame);
  RgbToYuv420(rgb, s.frame->data[0], s.frame->linesize[0], s.frame->data[1], s.frame->linesize[1], s.frame->data[2],
              s.frame->linesize[2]);
  s.frame->pts = s.next_pts++;
  if (const int error = avcodec_send_frame(s.codec, s.frame); error < 0) {
    ThrowSystemError("{}: the encoder refused a frame: {}", s.path.string(), AvError(error));
  }
  s.Drain();
}

void VideoEncoder::Finish() {
  State& s = *state_;
  if (s.finished) return;
  s.finished = true;
  avcodec_send_frame(s.codec, nullptr);
  s.Drain();
  if (const int error = av_write_trailer(s.format); error < 0) {
    ThrowSystemError("{}: cannot finish the video: {}", s.path.string(), AvError(error));
  }
  // The last buffered bytes go out on close: a full disk shows here.
  if (const int error = avio_closep(&s.format->pb); error < 0) {
    ThrowSystemError("{}: cannot finish the video: {}", s.path.string(), AvError(error));
  }
}

void RgbToYuv420(const cv::Mat& rgb, uint8_t* y, int y_stride, uint8_t* u, int u_stride, uint8_t* v, int v_stride) {
  constexpr float kr = 0.299f, kb = 0.114f, kg = 1.0f - kr - kb;
  const int w = rgb.cols, h = rgb.rows;
  // Rounded half away from zero, as std::lround, without its libm call: x is clamped to [0, 255]
  // first, so truncating x + 0.5 is the same.
  const auto code = [](float x) { return static_cast<uint8_t>(std::clamp(x, 0.0f, 255.0f) + 0.5f); };
  // Luma per pixel; Cb, Cr per pixel as floats, then sited: a chroma sample (i, j) sits at luma
  // column 2i (a [1 2 1]/4 filter across it) between rows 2j and 2j + 1 (their mean), as the
  // decoder's bilinear upsampling assumes. The planes are kept per thread: no 4 MB of fresh
  // pages every frame.
  thread_local cv::Mat cb, cr;
  cb.create(h, w, CV_32F), cr.create(h, w, CV_32F);
  for (int row = 0; row < h; ++row) {
    const auto* p = rgb.ptr<cv::Vec3f>(row);
    uint8_t* luma = y + static_cast<ptrdiff_t>(row) * y_stride;
    float* b_row = cb.ptr<float>(row);
    float* r_row = cr.ptr<float>(row);
    for (int x = 0; x < w; ++x) {
      const float r = std::clamp(p[x][0], 0.0f, 1.0f), g = std::clamp(p[x][1], 0.0f, 1.0f), b = std::clamp(p[x][2], 0.0f, 1.0f);
      const float yy = kr * r + kg * g + kb * b;
      luma[x] = code(16.0f + 219.0f * yy);
      b_row[x] = (b - yy) / (2.0f * (1.0f - kb));
      r_row[x] = (r - yy) / (2.0f * (1.0f - kr));
    }
  }
  for (int j = 0; j < h / 2; ++j) {
    const float *b0 = cb.ptr<float>(2 * j), *b1 = cb.ptr<float>(2 * j + 1);
    const float *r0 = cr.ptr<float>(2 * j), *r1 = cr.ptr<float>(2 * j + 1);
    uint8_t* uu = u + static_cast<ptrdiff_t>(j) * u_stride;
    uint8_t* vv = v + static_cast<ptrdiff_t>(j) * v_stride;
    for (int i = 0; i < w / 2; ++i) {
      const int c = 2 * i, l = std::max(c - 1, 0), r = std::min(c + 1, w - 1);
      const float bsum = 0.25f * (b0[l] + b1[l]) * 0.5f + 0.5f * (b0[c] + b1[c]) * 0.5f + 0.25f * (b0[r] + b1[r]) * 0.5f;
      const float rsum = 0.25f * (r0[l] + r1[l]) * 0.5f + 0.5f * (r0[c] + r1[c]) * 0.5f + 0.25f * (r0[r] + r1[r]) * 0.5f;
      uu[i] = code(128.0f + 224.0f * bsum);
      vv[i] = code(128.0f + 224.0f * rsum);
    }
  }
}

std::string VideoEncoderOptions::Check() const {
  if (preset == nullptr || *preset == '\0') return "preset: none given";
  return FirstProblem({InOpenClosed("fps", fps, 0.0, 1000.0), InClosed("crf", crf, 0, 51)});
}

}  // namespace daylit::capture
