// Capture: decoding the bundled 960×540 H.264 recording through the FrameSource the pipeline
// uses, against the bare decoder (bars: ≥ 200 fps decoding, ≤ 1 ms per frame for capture on top),
// and writing it back as H.264 (daylit record, the replay's video). One core each.
#include <benchmark/benchmark.h>

#include <filesystem>
#include <memory>

#include "base/log.h"
#include "capture/frame_source.h"
#include "capture/video_decoder.h"
#include "capture/video_encoder.h"

namespace daylit::capture {
namespace {

const std::filesystem::path kRecording = DAYLIT_SOURCE_DIR "/recordings/courtyard-a";

void BM_DecoderNext(benchmark::State& state) {
  auto decoder = std::make_unique<VideoDecoder>(kRecording / "video.mp4");
  cv::Mat rgb;
  for (auto _ : state) {
    if (!decoder->Next(&rgb)) {
      state.PauseTiming();
      decoder = std::make_unique<VideoDecoder>(kRecording / "video.mp4");
      state.ResumeTiming();
      decoder->Next(&rgb);
    }
    benchmark::DoNotOptimize(rgb.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_DecoderNext)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_VideoSourceNext(benchmark::State& state) {
  SetLogVerbosity(0);
  const FrameTimes times = LoadFrameTimes(kRecording / "frames.csv");
  auto source = OpenVideoSource(kRecording / "video.mp4", times, 1.0);
  Frame frame;
  for (auto _ : state) {
    if (source->Next(&frame) != FrameStatus::kFrame) {
      state.PauseTiming();
      source = OpenVideoSource(kRecording / "video.mp4", times, 1.0);
      state.ResumeTiming();
      source->Next(&frame);
    }
    benchmark::DoNotOptimize(frame.rgb.data);
  }
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_VideoSourceNext)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_EncodeFrame(benchmark::State& state) {
  VideoDecoder decoder(kRecording / "video.mp4");
  cv::Mat rgb;
  decoder.Next(&rgb);
  const std::filesystem::path out = std::filesystem::temp_directory_path() / "daylit_capture_bench.mp4";
  {
    VideoEncoder encoder(out, rgb.cols, rgb.rows, VideoEncoderOptions{10.0});
    for (auto _ : state) encoder.Write(rgb);
    encoder.Finish();
  }
  std::filesystem::remove(out);
  state.SetItemsProcessed(state.iterations());
}
BENCHMARK(BM_EncodeFrame)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace daylit::capture

