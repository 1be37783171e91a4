// The lighting server's cost to the pipeline and its delay (issue 23's figures), with stream
// clients reading over real loopback connections on their own threads:
//  - BM_ServeFrame/N: what the replay's sink does per frame on the pipeline's thread with N
//    clients connected: a copy of courtyard-a's irradiance volume (10 × 8 × 4 probes), the frame
//    shared, the message made (SH at the volume's centre) and handed to every client;
//  - BM_ServeLatency/4: frames published every 10 ms; how long after its Publish each client
//    has a frame's message (median and worst over every frame and client);
//  - BM_LightingUnderLoad: issue 52's bar: 100 slow-loris clients (a byte every 0.4 s, replaced
//    when closed) and 50 stream clients while frames come at 30 fps; how long a GET /lighting on
//    a new connection takes (median, 99th percentile and worst of 150).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <httplib.h>
#include <nlohmann/json.hpp>

#include "base/log.h"
#include "base/statistics.h"
#include "serve/lighting_server.h"
#include "serve/load_clients.h"

namespace daylit::serve {
namespace {

using Clock = std::chrono::steady_clock;

// Stream clients that read until the server stops; each message's arrival per frame.
class Readers {
 public:
  Readers(int port, int count, size_t frames) : arrived_(static_cast<size_t>(count)) {
    for (int c = 0; c < count; ++c) {
      arrived_[static_cast<size_t>(c)].assign(frames, Clock::time_point{});
      threads_.emplace_back([this, port, c] {
        httplib::Client client("127.0.0.1", port);
        client.set_read_timeout(30, 0);
        std::string buffer;
        connected_.fetch_add(1);
        client.Get("/stream", [&](const char* data, size_t size) {
          buffer.append(data, size);
          for (size_t end; (end = buffer.find("\n\n")) != std::string::npos; buffer.erase(0, end + 2)) {
            if (buffer.rfind("data: ", 0) != 0) continue;
            const size_t at = buffer.find("\"frame\":");
            const size_t frame = at == std::string::npos ? 0 : std::stoul(buffer.substr(at + 8));
            std::vector<Clock::time_point>& mine = arrived_[static_cast<size_t>(c)];
            if (frame < mine.size()) mine[frame] = Clock::now();
          }
          return true;
        });
      });
    }
  }
  ~Readers() {
    for (std::thread& t : threads_) t.join();  // the server's stop ends their streams
  }
  bool AllConnected(const LightingServer& server) const {
    return server.stats().clients_seen >= threads_.size();
  }
  const std::vector<std::vector<Clock::time_point>>& arrived() const { return arrived_; }

 private:
  std::vector<std::vector<Clock::time_point>> arrived_;
  std::vector<std::thread> threads_;
  std::atomic<int> connected_{0};
};

// What the replay's sink hands over for one frame (apps/daylit/replay_command.cc, ServeSink).
std::shared_ptr<FrameLighting> SinkFrame(int index, const sh::Sh9Snapshot& volume, const std::shared_ptr<const EnvMapParts>& envmap,
                                         const cv::Mat& image) {
  auto l = std::make_shared<FrameLighting>();
  l->row.frame = index;
  l->row.light.sun_rgb = glm::dvec3(86.9, 64.4, 37.9);
  l->row.light.sky_rgb = glm::dvec3(9.5, 9.3, 9.6);
  l->row.confidence = 0.74;
  l->row.sun_up = true;
  l->exposure = 0.198;
  l->sun_scene = glm::normalize(glm::vec3(0.957f, -0.039f, 0.287f));
  l->sun_camera = glm::normalize(glm::vec3(-0.955f, -0.296f, 0.033f));
  l->volume = volume;  // the sink's Snapshot: a copy of the coefficients
  l->envmap = envmap;
  l->image = image;
  return l;
}

sh::Sh9Snapshot CourtyardVolume() {
  sh::Sh9Snapshot v;
  v.min = glm::vec3(-2.3f, -3.7f, 0.0f);
  v.max = glm::vec3(2.9f, 0.6f, 2.0f);
  v.resolution = glm::ivec3(10, 8, 4);
  v.coefficients.resize(static_cast<size_t>(10 * 8 * 4) * 27);
  for (size_t i = 0; i < v.coefficients.size(); ++i) v.coefficients[i] = 1.0f + 0.001f * static_cast<float>(i % 97);
  return v;
}

void WaitFor(const Readers& readers, const LightingServer& server) {
  for (int i = 0; i < 5000 && !readers.AllConnected(server); ++i) std::this_thread::sleep_for(std::chrono::milliseconds(1));
}

void BM_ServeFrame(benchmark::State& state) {
  SetLogVerbosity(0);
  const sh::Sh9Snapshot volume = CourtyardVolume();
  const cv::Mat image(540, 960, CV_32FC3, cv::Scalar(0.5f, 0.4f, 0.3f));
  auto server = std::make_unique<LightingServer>(ServerOptions{}, "{}");
  int frame = 0;
  Readers readers(server->port(), static_cast<int>(state.range(0)), 1);
  WaitFor(readers, *server);
  for (auto _ : state) server->Publish(SinkFrame(frame++, volume, nullptr, image));
  state.SetItemsProcessed(state.iterations());
  state.counters["dropped"] = static_cast<double>(server->stats().dropped);
  server.reset();  // ends the readers' streams before they are joined
}
BENCHMARK(BM_ServeFrame)->Arg(0)->Arg(4)->Unit(benchmark::kMicrosecond)->UseRealTime();

void BM_ServeLatency(benchmark::State& state) {
  SetLogVerbosity(0);
  const sh::Sh9Snapshot volume = CourtyardVolume();
  const cv::Mat image(540, 960, CV_32FC3, cv::Scalar(0.5f, 0.4f, 0.3f));
  const int clients = static_cast<int>(state.range(0));
  constexpr int kFrames = 300;
  std::vector<double> latency_ms;
  for (auto _ : state) {
    auto server = std::make_unique<LightingServer>(ServerOptions{}, "{}");
    std::vector<Clock::time_point> published(kFrames);
    std::vector<std::vector<Clock::time_point>> arrived;
    {
      Readers readers(server->port(), clients, kFrames);
      WaitFor(readers, *server);
      const Clock::time_point start = Clock::now();
      for (int f = 0; f < kFrames; ++f) {
        std::this_thread::sleep_until(start + std::chrono::milliseconds(10 * f));
        published[static_cast<size_t>(f)] = Clock::now();
        server->Publish(SinkFrame(f, volume, nullptr, image));
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
      server.reset();
      arrived = readers.arrived();
    }
    for (const auto& client : arrived) {
      for (size_t f = 0; f < client.size(); ++f) {
        latency_ms.push_back(client[f] == Clock::time_point{} ? 1e9
                                                              : std::chrono::duration<double, std::milli>(client[f] - published[f]).count());
      }
    }
  }
  state.counters["latency_median_ms"] = PercentileInPlace(latency_ms, 0.5, 0.0);
  state.counters["latency_p99_ms"] = PercentileInPlace(latency_ms, 0.99, 0.0);
  state.counters["latency_worst_ms"] = PercentileInPlace(latency_ms, 1.0, 0.0);
}
BENCHMARK(BM_ServeLatency)->Arg(4)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_LightingUnderLoad(benchmark::State& state) {
  SetLogVerbosity(0);
  const sh::Sh9Snapshot volume = CourtyardVolume();
  const cv::Mat image(540, 960, CV_32FC3, cv::Scalar(0.5f, 0.4f, 0.3f));
  constexpr int kFrames = 300, kStreams = 50;  // 10 s at 30 fps
  std::vector<double> answer_ms;
  uint64_t refused = 0, timed_out = 0;
  for (auto _ : state) {
    auto server = std::make_unique<LightingServer>(ServerOptions{}, "{}");
    server->Publish(SinkFrame(0, volume, nullptr, image));
    {
      SlowClients slow(server->port(), 100);
      Readers readers(server->port(), kStreams, kFrames);
      WaitFor(readers, *server);
      const Clock::time_point start = Clock::now();
      for (int f = 1; f < kFrames; ++f) {
        std::this_thread::sleep_until(start + std::chrono::microseconds(33333 * f));
        server->Publish(SinkFrame(f, volume, nullptr, image));
        if (f % 2 != 0) continue;
        const Clock::time_point asked = Clock::now();
        httplib::Client client("127.0.0.1", server->port());
        client.set_read_timeout(5, 0);
        const httplib::Result res = client.Get("/lighting");
        answer_ms.push_back(res && res->status == 200 ? std::chrono::duration<double, std::milli>(Clock::now() - asked).count()
                                                      : 1e9);
      }
      refused = server->stats().refused;
      timed_out = server->stats().timed_out;
      server.reset();  // ends the readers' streams before they are joined
    }
  }
  state.counters["answer_median_ms"] = PercentileInPlace(answer_ms, 0.5, 0.0);
  state.counters["answer_p99_ms"] = PercentileInPlace(answer_ms, 0.99, 0.0);
  state.counters["answer_worst_ms"] = PercentileInPlace(answer_ms, 1.0, 0.0);
  state.counters["slow_closed"] = static_cast<double>(timed_out);
  state.counters["refused"] = static_cast<double>(refused);
}
BENCHMARK(BM_LightingUnderLoad)->Iterations(1)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
}  // namespace daylit::serve
