// The lighting server over real loopback connections (cpp-httplib's client, and a raw socket for
// a client that never reads).
#include "serve/lighting_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <httplib.h>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include <opencv2/imgcodecs.hpp>

#include "base/csv.h"
#include "base/error.h"
#include "scene/hdr_image.h"
#include "serve/load_clients.h"

namespace daylit::serve {
namespace {

std::shared_ptr<FrameLighting> Frame(int index) {
  auto l = std::make_shared<FrameLighting>();
  l->row.frame = index;
  l->row.light.sun_rgb = glm::dvec3(80.0 + index, 60.0, 40.0);
  l->row.light.sky_rgb = glm::dvec3(10.0, 11.0, 12.0 + index);
  l->row.confidence = 0.75;
  l->row.interval.known = l->row.interval.sun_observed = true;
  l->row.interval.sun = glm::dvec3(0.05);
  l->row.interval.sky = glm::dvec3(0.1);
  l->row.sun_up = true;
  l->row.status = estimation::FrameStatus::kConverged;
  l->sun_scene = glm::normalize(glm::vec3(0.3f, -0.4f, 0.8f));
  l->sun_camera = glm::normalize(glm::vec3(0.1f, -0.9f, 0.2f));
  return l;
}

// Waits up to 5 s for `ready`.
template <typename F>
bool Eventually(F ready) {
  for (int i = 0; i < 500; ++i) {
    if (ready()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  return ready();
}

// A stream client on its own thread: the frame numbers of the `data:` messages, until it has
// `want` of them or has seen frame `last`.
struct StreamClient {
  std::vector<int> frames;
  std::thread thread;
  StreamClient(int port, size_t want, int last = -1) {
    thread = std::thread([this, port, want, last] {
      httplib::Client client("127.0.0.1", port);
      client.set_read_timeout(5, 0);
      std::string buffer;
      client.Get("/stream", [&](const char* data, size_t size) {
        buffer.append(data, size);
        for (size_t end; (end = buffer.find("\n\n")) != std::string::npos; buffer.erase(0, end + 2)) {
          const std::string event = buffer.substr(0, end);
          if (event.rfind("data: ", 0) == 0) frames.push_back(nlohmann::json::parse(event.substr(6))["frame"].get<int>());
        }
        return frames.size() < want && (frames.empty() || frames.back() != last);
      });
    });
  }
  ~StreamClient() {
    if (thread.joinable()) thread.join();
  }
};

TEST(ParseHostPortTest, PortAloneIsLoopbackAndBadTextNamesTheOption) {
  const ServerOptions a = ParseHostPort("8080", "--serve");
  EXPECT_EQ(a.host, "127.0.0.1");
  EXPECT_EQ(a.port, 8080);
  const ServerOptions b = ParseHostPort("0.0.0.0:9000", "--serve");
  EXPECT_EQ(b.host, "0.0.0.0");
  EXPECT_EQ(b.port, 9000);
  EXPECT_EQ(ParseHostPort("[::1]:9001", "--serve").host, "::1");
  EXPECT_EQ(ParseHostPort("0", "--serve").port, 0);  // any free port
  for (const char* bad : {"abc", "70000", "-1", ":80", "host:", "80x"}) {
    try {
      ParseHostPort(bad, "--serve");
      ADD_FAILURE() << bad << " was taken";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("--serve"), std::string::npos) << e.what();
    }
  }
}

TEST(LightingServerTest, LightingIs503BeforeTheFirstFrameThenTheLatestWithWebXrNames) {
  LightingServer server({}, R"({"units": "m"})");
  httplib::Client client("127.0.0.1", server.port());
  auto res = client.Get("/lighting");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 503);
  server.Publish(Frame(6));
  server.Publish(Frame(7));
  res = client.Get("/lighting");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Access-Control-Allow-Origin"), "*");
  const nlohmann::json j = nlohmann::json::parse(res->body);
  EXPECT_EQ(j["version"], kLightingSchema);
  EXPECT_EQ(j["frame"], 7);
  EXPECT_DOUBLE_EQ(j["primaryLightIntensity"]["x"].get<double>(), 87.0);
  EXPECT_DOUBLE_EQ(j["skyIrradiance"]["z"].get<double>(), 19.0);
  EXPECT_DOUBLE_EQ(j["primaryLightIntensityInterval90"]["hi"]["x"].get<double>(), 87.0 * 1.05);
  EXPECT_DOUBLE_EQ(j["skyIrradianceInterval90"]["lo"]["z"].get<double>(), 19.0 * 0.9);
  EXPECT_TRUE(j["primaryLightObserved"].get<bool>());
  EXPECT_EQ(j["status"], "converged");
  const glm::vec3 sun = Frame(0)->sun_scene;
  EXPECT_NEAR(j["primaryLightDirection"]["y"].get<double>(), sun.y, 1e-6);
  EXPECT_TRUE(j["sphericalHarmonicsCoefficients"].is_null());  // no volume
  // Every field the published schema requires is there.
  const nlohmann::json schema = nlohmann::json::parse(ReadTextFile(DAYLIT_SOURCE_DIR "/docs/lighting.schema.json"));
  EXPECT_EQ(schema["properties"]["version"]["const"], kLightingSchema);
  for (const auto& key : schema["required"]) EXPECT_TRUE(j.contains(key.get<std::string>())) << key;
  EXPECT_EQ(j.size(), schema["properties"].size());
  res = client.Get("/scene");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->body, R"({"units": "m"})");
}

// GET /scene's text for a bundled recording: the camera as scene.json gives it (rows of
// world_to_camera, its centre -R^T t), north, and the objects and volume a renderer places.
TEST(SceneJsonTest, TheCameraObjectsAndVolumeOfTheScene) {
  const scene::Scene scene = scene::LoadScene(DAYLIT_SOURCE_DIR "/recordings/courtyard-a");
  const nlohmann::json j = nlohmann::json::parse(SceneJson(scene));
  EXPECT_EQ(j["version"], kLightingSchema);
  EXPECT_EQ(j["units"], "m");
  EXPECT_DOUBLE_EQ(j["camera"]["fx"].get<double>(), scene.intrinsics.fx);
  EXPECT_EQ(j["camera"]["width"], scene.intrinsics.width);
  const glm::dmat3& r = scene.cam_from_world.rotation;
  const glm::dvec3 t = scene.cam_from_world.translation;
  for (int row = 0; row < 3; ++row) {
    for (int col = 0; col < 3; ++col) {
      EXPECT_DOUBLE_EQ(j["camera"]["world_to_camera"]["rotation"][row][col].get<double>(), r[col][row]);
    }
  }
  const glm::dvec3 center = -glm::transpose(r) * t;
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(j["camera"]["center"][i].get<double>(), center[i], 1e-9);
  EXPECT_DOUBLE_EQ(j["north_azimuth_deg"].get<double>(), scene.north_azimuth_deg);
  ASSERT_EQ(j["objects"].size(), scene.objects.size());
  ASSERT_FALSE(scene.objects.empty());
  EXPECT_DOUBLE_EQ(j["objects"][0]["position"][0].get<double>(), scene.objects[0].position.x);
  ASSERT_TRUE(scene.volume.has_value());
  EXPECT_DOUBLE_EQ(j["volume"]["max"][2].get<double>(), scene.volume->max.z);
}

TEST(LightingServerTest, ShCoefficientsAreTheVolumesRadianceCoefficientsAtThePointAsked) {
  LightingServer server({}, "{}");
  auto l = Frame(3);
  // Two probes along x (0 m and 2 m); the band-0 irradiance coefficient is 1 and 3 in red there.
  l->volume.min = glm::vec3(0.0f), l->volume.max = glm::vec3(2.0f, 1.0f, 1.0f);
  l->volume.resolution = glm::ivec3(2, 1, 1);
  l->volume.coefficients.assign(2 * 27, 0.0f);
  l->volume.coefficients[0] = 1.0f, l->volume.coefficients[27] = 3.0f;
  l->volume.coefficients[3 * 2 + 1] = 2.0f;  // coefficient 2 (l = 1), green, at the first probe
  server.Publish(l);
  httplib::Client client("127.0.0.1", server.port());
  auto res = client.Get("/lighting");
  ASSERT_TRUE(res && res->status == 200);
  nlohmann::json j = nlohmann::json::parse(res->body);
  ASSERT_EQ(j["sphericalHarmonicsCoefficients"].size(), 27u);
  // Radiance L_00 = E_00 / π: halfway between the probes, (1 + 3)/2 / π.
  EXPECT_NEAR(j["sphericalHarmonicsCoefficients"][0].get<double>(), 2.0 / glm::pi<double>(), 1e-6);
  res = client.Get("/lighting?at=0,0.5,0.5");
  ASSERT_TRUE(res && res->status == 200);
  j = nlohmann::json::parse(res->body);
  EXPECT_NEAR(j["sphericalHarmonicsCoefficients"][0].get<double>(), 1.0 / glm::pi<double>(), 1e-6);
  EXPECT_NEAR(j["sphericalHarmonicsCoefficients"][7].get<double>(), 2.0 / (2.0 * glm::pi<double>() / 3.0), 1e-6);
  EXPECT_EQ(j["sphericalHarmonicsAt"][0], 0.0);
  // Far outside the volume: the nearest probe's light, and the point it was taken at (issue 43:
  // it echoed 1e30).
  res = client.Get("/lighting?at=1e30,0.5,-7");
  ASSERT_TRUE(res && res->status == 200);
  j = nlohmann::json::parse(res->body);
  EXPECT_NEAR(j["sphericalHarmonicsCoefficients"][0].get<double>(), 3.0 / glm::pi<double>(), 1e-6);
  EXPECT_EQ(j["sphericalHarmonicsAt"], nlohmann::json({2.0, 0.5, 0.0}));
  res = client.Get("/lighting?at=1,2");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 400);
  EXPECT_NE(res->body.find("x,y,z"), std::string::npos) << res->body;
}

TEST(LightingServerTest, ManyStreamClientsEachGetEveryFrameInOrder) {
  LightingServer server({}, "{}");
  constexpr int kClients = 6, kFrames = 40;
  std::vector<std::unique_ptr<StreamClient>> clients;
  for (int c = 0; c < kClients; ++c) clients.push_back(std::make_unique<StreamClient>(server.port(), kFrames));
  ASSERT_TRUE(Eventually([&] { return server.stats().clients_seen == kClients; }));
  for (int f = 0; f < kFrames; ++f) server.Publish(Frame(f));
  for (auto& c : clients) {
    c->thread.join();
    ASSERT_EQ(c->frames.size(), static_cast<size_t>(kFrames));
    for (int f = 0; f < kFrames; ++f) EXPECT_EQ(c->frames[static_cast<size_t>(f)], f);
  }
  EXPECT_EQ(server.stats().dropped, 0u);
}

// A client that connects and never reads: Publish never waits for it, it loses its oldest
// messages once the socket's buffers are full (counted), and a client reading beside it gets the
// frames in order, up to the last.
TEST(LightingServerTest, AClientThatReadsNothingLosesMessagesAndSlowsNoOne) {
  ServerOptions options;
  options.queued_per_client = 64;
  LightingServer server(options, "{}");
  const int fd = ConnectTo(server.port());
  ASSERT_GE(fd, 0);
  const std::string request = "GET /stream HTTP/1.1\r\nHost: 127.0.0.1\r\n\r\n";
  ASSERT_EQ(write(fd, request.data(), request.size()), static_cast<ssize_t>(request.size()));
  ASSERT_TRUE(Eventually([&] { return server.stats().clients_seen == 1; }));
  constexpr int kFrames = 40000;  // some 20 MB: more than a socket's buffers hold
  StreamClient reader(server.port(), kFrames, kFrames - 1);
  ASSERT_TRUE(Eventually([&] { return server.stats().clients_seen == 2; }));
  for (int f = 0; f < kFrames; ++f) server.Publish(Frame(f));
  reader.thread.join();
  ASSERT_FALSE(reader.frames.empty());
  EXPECT_EQ(reader.frames.back(), kFrames - 1);
  EXPECT_TRUE(std::is_sorted(reader.frames.begin(), reader.frames.end()));
  EXPECT_GT(server.stats().dropped, 0u);
  EXPECT_EQ(server.stats().published, static_cast<uint64_t>(kFrames));
  close(fd);
}

// A client that sends half a request line and stalls is closed after about a second, not held for
// five (issue 52), and /lighting answers beside it.
TEST(LightingServerTest, AClientThatStallsInItsRequestIsClosedSoon) {
  LightingServer server({}, "{}");
  server.Publish(Frame(1));
  const int fd = ConnectTo(server.port());
  ASSERT_GE(fd, 0);
  const std::string half = "GET /lighting HT";
  ASSERT_EQ(write(fd, half.data(), half.size()), static_cast<ssize_t>(half.size()));
  const auto start = std::chrono::steady_clock::now();
  httplib::Client client("127.0.0.1", server.port());
  const httplib::Result res = client.Get("/lighting");
  ASSERT_TRUE(res);
  EXPECT_EQ(res->status, 200);
  // The server closes the stalled connection: read() returns 0 (or an error), well before 5 s.
  timeval limit{4, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof(limit));
  char byte = 0;
  const ssize_t got = read(fd, &byte, 1);
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_LE(got, 0);
  EXPECT_LT(waited, 3.5) << "the stalled client was held " << waited << " s";
  close(fd);
}

// A request with thousands of header fields (119 KB were accepted) is refused with 431, its
// answer readable from any origin; a browser's few are not.
TEST(LightingServerTest, ARequestWithTooManyHeaderFieldsIsRefused) {
  LightingServer server({}, "{}");
  server.Publish(Frame(1));
  httplib::Client client("127.0.0.1", server.port());
  httplib::Headers many, few;
  for (int i = 0; i < 1000; ++i) many.emplace("X-Filler-" + std::to_string(i), "0123456789");
  for (int i = 0; i < 20; ++i) few.emplace("X-Filler-" + std::to_string(i), "0123456789");
  const httplib::Result refused = client.Get("/lighting", many);
  ASSERT_TRUE(refused);
  EXPECT_EQ(refused->status, 431);
  EXPECT_EQ(refused->get_header_value("Access-Control-Allow-Origin"), "*");
  EXPECT_NE(refused->body.find("at most 100"), std::string::npos) << refused->body;
  const httplib::Result answered = client.Get("/lighting", few);
  ASSERT_TRUE(answered);
  EXPECT_EQ(answered->status, 200);
}

// Issue 52's bar: /lighting answers within 50 ms while 100 clients send their requests a byte at a
// time and 50 stream clients read every frame at 30 fps (it answered 0 of 20 within 5 s when each
// connection held one of the server's threads). Every stream client gets the frames.
TEST(LightingServerTest, LightingAnswersBesideAHundredSlowClientsAndFiftyStreams) {
  LightingServer server({}, "{}");
  server.Publish(Frame(0));
  constexpr int kStreams = 50, kFrames = 90;  // 3 s at 30 fps
  SlowClients slow(server.port(), 100);
  std::vector<std::unique_ptr<StreamClient>> streams;
  for (int c = 0; c < kStreams; ++c) streams.push_back(std::make_unique<StreamClient>(server.port(), kFrames + 1, kFrames));
  ASSERT_TRUE(Eventually([&] { return server.stats().clients_seen == kStreams; }));
  std::vector<double> ms;
  for (int f = 1; f <= kFrames; ++f) {
    server.Publish(Frame(f));
    if (f % 4 == 0) {  // 22 requests, each on its own connection, as a renderer polling would
      const auto start = std::chrono::steady_clock::now();
      httplib::Client client("127.0.0.1", server.port());
      client.set_read_timeout(5, 0);
      const httplib::Result res = client.Get("/lighting");
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count());
      ASSERT_TRUE(res);
      EXPECT_EQ(res->status, 200);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(33));
  }
  for (auto& c : streams) {
    c->thread.join();
    ASSERT_FALSE(c->frames.empty());
    EXPECT_EQ(c->frames.back(), kFrames);
    EXPECT_TRUE(std::is_sorted(c->frames.begin(), c->frames.end()));
  }
  EXPECT_GE(slow.connects(), 100);
  EXPECT_GT(server.stats().timed_out, 0u) << "the slow clients were never closed";
  std::sort(ms.begin(), ms.end());
  std::printf("/lighting beside 100 slow clients and %d streams: median %.2f ms, worst %.2f ms of %zu\n", kStreams,
              ms[ms.size() / 2], ms.back(), ms.size());
  // The bar is 50 ms; a machine busy with other tests may delay one answer, never most of them.
  EXPECT_LE(ms[ms.size() / 2], 50.0) << "median of " << ms.size();
  EXPECT_LE(ms.back(), 1000.0) << "worst";
}

// At the cap on connections the next one is answered 503 at once, readable from any origin, and
// closed; one that has gone makes room.
TEST(LightingServerTest, BeyondTheCapOnConnectionsA503AtOnce) {
  ServerOptions options;
  options.max_connections = 8;
  LightingServer server(options, "{}");
  server.Publish(Frame(1));
  std::vector<int> idle;
  for (int i = 0; i < 8; ++i) idle.push_back(ConnectTo(server.port()));
  for (const int fd : idle) ASSERT_GE(fd, 0);
  const int extra = ConnectTo(server.port());
  ASSERT_GE(extra, 0);
  timeval limit{2, 0};
  setsockopt(extra, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof(limit));
  std::string answer(512, '\0');
  const ssize_t got = read(extra, answer.data(), answer.size());
  ASSERT_GT(got, 0);
  answer.resize(static_cast<size_t>(got));
  EXPECT_EQ(answer.rfind("HTTP/1.1 503", 0), 0u) << answer;
  EXPECT_NE(answer.find("Access-Control-Allow-Origin: *"), std::string::npos) << answer;
  EXPECT_NE(answer.find("at most 8"), std::string::npos) << answer;
  close(extra);
  EXPECT_EQ(server.stats().refused, 1u);
  close(idle.back());
  idle.pop_back();
  httplib::Client client("127.0.0.1", server.port());
  ASSERT_TRUE(Eventually([&] {
    const httplib::Result res = client.Get("/lighting");
    return res && res->status == 200;
  }));
  for (const int fd : idle) close(fd);
}

// A request line of 100 KB is answered 414 as soon as it passes 8 KiB; the rest it sends is read
// and dropped, so the client reads the whole answer and then the server's close, not a reset
// that could lose the answer.
TEST(LightingServerTest, AnOverlongRequestLineGets414AndAnOrderlyClose) {
  LightingServer server({}, "{}");
  const int fd = ConnectTo(server.port());
  ASSERT_GE(fd, 0);
  const std::string request = "GET /" + std::string(100000, 'a') + " HTTP/1.1\r\n\r\n";
  size_t sent = 0;
  while (sent < request.size()) {
    const ssize_t n = send(fd, request.data() + sent, request.size() - sent, MSG_NOSIGNAL);
    ASSERT_GT(n, 0) << "the server stopped reading after " << sent << " bytes: " << std::strerror(errno);
    sent += static_cast<size_t>(n);
  }
  timeval limit{3, 0};
  setsockopt(fd, SOL_SOCKET, SO_RCVTIMEO, &limit, sizeof(limit));
  std::string answer;
  char buffer[4096];
  ssize_t got = 0;
  while ((got = read(fd, buffer, sizeof(buffer))) > 0) answer.append(buffer, static_cast<size_t>(got));
  EXPECT_EQ(got, 0) << "not an orderly close: " << std::strerror(errno);
  EXPECT_EQ(answer.rfind("HTTP/1.1 414", 0), 0u) << answer;
  EXPECT_NE(answer.find("Access-Control-Allow-Origin: *"), std::string::npos) << answer;
  close(fd);
}

TEST(LightingServerTest, APortTakenIsAnInputErrorNamingItAndWhy) {
  LightingServer first({}, "{}");
  ServerOptions options;
  options.port = first.port();
  try {
    LightingServer second(options, "{}");
    ADD_FAILURE() << "a second server on port " << first.port();
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find(fmt::format("127.0.0.1:{}", first.port())), std::string::npos) << what;
    EXPECT_NE(what.find("in use"), std::string::npos) << what;
  }
}


// A relit map's parts at twice the served size: each served texel is the mean of the 2 × 2 it
// covers, and the EXR holds E_sun·sun + E_clear·clear + E_overcast·overcast in half floats.
TEST(LightingServerTest, EnvMapIsTheRelitMapShrunkAsHalfFloatExr) {
  const int w = 2 * kEnvMapWidth, h = 2 * kEnvMapHeight;
  std::vector<glm::vec3> sun(2 * w * h), clear(2 * w * h), overcast(2 * w * h);  // stacked: map, then sky layer
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      sun[i] = ((x + y) % 2 == 0) ? glm::vec3(2.0f, 0.0f, 1.0f) : glm::vec3(0.0f);  // a checkerboard: means 1, 0, 0.5
      clear[i] = glm::vec3(0.01f * static_cast<float>(y / 2), 0.5f, 0.25f);
      overcast[i] = glm::vec3(1.0f / glm::pi<float>());
      sun[w * h + i] = glm::vec3(1e6f);  // the sky layer is not the map
    }
  }
  const std::shared_ptr<const EnvMapParts> parts = ShrinkEnvMapParts(w, h, sun, clear, overcast);
  ASSERT_NE(parts, nullptr);
  ASSERT_EQ(parts->width, kEnvMapWidth);
  ASSERT_EQ(parts->height, kEnvMapHeight);
  for (const glm::vec3& t : parts->sun) ASSERT_NEAR(glm::distance(t, glm::vec3(1.0f, 0.0f, 0.5f)), 0.0f, 1e-5f);

  LightingServer server(ServerOptions{}, "{}");
  auto frame = Frame(5);
  frame->overcast_share = 0.25;
  frame->envmap = parts;
  server.Publish(frame);
  httplib::Client client("127.0.0.1", server.port());
  const httplib::Result res = client.Get("/envmap");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("Content-Type"), "image/x-exr");
  EXPECT_EQ(res->get_header_value("X-Daylit-Frame"), "5");
  const std::filesystem::path file = std::filesystem::temp_directory_path() / fmt::format("envmap_{}.exr", ::getpid());
  std::ofstream(file, std::ios::binary) << res->body;
  const scene::ExrChannels read = scene::ReadExrChannels(file, {"R", "G", "B"}, {});
  std::filesystem::remove(file);
  ASSERT_EQ(read.width, kEnvMapWidth);
  ASSERT_EQ(read.height, kEnvMapHeight);
  const std::vector<float> relit = RelitEnvMap(*parts, frame->row.light, frame->overcast_share);
  const estimation::LightParts e = estimation::SplitLight(frame->row.light, frame->overcast_share);
  for (size_t i = 0; i < relit.size() / 3; ++i) {
    const glm::vec3 want = e.sun * parts->sun[i] + e.clear * parts->clear[i] + e.overcast * parts->overcast[i];
    for (int c = 0; c < 3; ++c) {
      ASSERT_NEAR(relit[3 * i + c], want[c], 1e-4f * want[c]);
      ASSERT_NEAR(read.planes[static_cast<size_t>(c)][i], want[c], 1e-3f * want[c]) << "texel " << i << " channel " << c;  // half: 11 bits
    }
  }
}

// The camera frame as /frame.jpg and /video.mjpg: a smooth picture comes back within JPEG's
// error, and the video sends each new frame as its own part, numbered.
TEST(LightingServerTest, FrameAndVideoAreTheLatestCameraFrameAsJpeg) {
  LightingServer server(ServerOptions{}, "{}");
  httplib::Client client("127.0.0.1", server.port());
  EXPECT_EQ(client.Get("/frame.jpg")->status, 503);
  const auto picture = [](float shift) {
    cv::Mat rgb(48, 64, CV_32FC3);
    for (int y = 0; y < rgb.rows; ++y) {
      for (int x = 0; x < rgb.cols; ++x) rgb.at<cv::Vec3f>(y, x) = cv::Vec3f(static_cast<float>(x) / 64.0f, static_cast<float>(y) / 48.0f, shift);
    }
    return rgb;
  };
  auto first = Frame(7);
  first->image = picture(0.5f);
  server.Publish(first);
  const httplib::Result res = client.Get("/frame.jpg");
  ASSERT_TRUE(res);
  ASSERT_EQ(res->status, 200);
  EXPECT_EQ(res->get_header_value("X-Daylit-Frame"), "7");
  const cv::Mat bgr = cv::imdecode(std::vector<uchar>(res->body.begin(), res->body.end()), cv::IMREAD_COLOR);
  ASSERT_EQ(bgr.cols, 64);
  ASSERT_EQ(bgr.rows, 48);
  double worst = 0.0;
  for (int y = 0; y < bgr.rows; ++y) {
    for (int x = 0; x < bgr.cols; ++x) {
      const cv::Vec3b got = bgr.at<cv::Vec3b>(y, x);
      const cv::Vec3f want = first->image.at<cv::Vec3f>(y, x) * 255.0f;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(got[2 - c] - static_cast<double>(want[c])));
    }
  }
  EXPECT_LT(worst, 6.0) << "codes";  // quality 90 on a smooth gradient

  std::vector<int> parts;
  std::thread reader([&] {
    httplib::Client video("127.0.0.1", server.port());
    video.set_read_timeout(5, 0);
    std::string buffer;
    video.Get("/video.mjpg", [&](const char* data, size_t size) {
      buffer.append(data, size);
      for (;;) {
        const size_t head_end = buffer.find("\r\n\r\n");
        if (head_end == std::string::npos) return true;
        const std::string head = buffer.substr(0, head_end);
        const size_t length_at = head.find("Content-Length: "), frame_at = head.find("X-Daylit-Frame: ");
        EXPECT_EQ(head.rfind("--daylitframe\r\nContent-Type: image/jpeg", 0), 0u) << head;
        if (length_at == std::string::npos || frame_at == std::string::npos) return false;
        const size_t length = std::stoul(head.substr(length_at + 16));
        if (buffer.size() < head_end + 4 + length + 2) return true;
        const std::vector<uchar> jpeg(buffer.begin() + static_cast<long>(head_end + 4),
                                      buffer.begin() + static_cast<long>(head_end + 4 + length));
        EXPECT_FALSE(cv::imdecode(jpeg, cv::IMREAD_COLOR).empty());
        parts.push_back(std::stoi(head.substr(frame_at + 16)));
        buffer.erase(0, head_end + 4 + length + 2);
        if (parts.back() == 8) return false;
      }
    });
  });
  ASSERT_TRUE(Eventually([&] { return server.stats().clients_seen == 1; }));
  auto second = Frame(8);
  second->image = picture(0.25f);
  // Published until the reader has seen it: it may have joined after the first publish.
  ASSERT_TRUE(Eventually([&] {
    server.Publish(second);
    return server.stats().jpegs >= 2;
  }));
  reader.join();
  ASSERT_FALSE(parts.empty());
  EXPECT_EQ(parts.back(), 8);
  EXPECT_TRUE(std::is_sorted(parts.begin(), parts.end()));
  EXPECT_EQ(server.stats().jpegs, 2u) << "one JPEG per frame";
}

// The viewer at /: index.html and three.js from web/ (scripts/setup.sh); without those files,
// / says how to install them and everything else is served as ever.
TEST(LightingServerTest, TheViewerIsServedFromWebOrItsAbsenceSaid) {
  LightingServer server(ServerOptions{}, "{}");
  httplib::Client client("127.0.0.1", server.port());
  const httplib::Result root = client.Get("/");
  ASSERT_TRUE(root);
  EXPECT_EQ(root->status, 302);
  EXPECT_EQ(root->get_header_value("Location"), "/viewer/index.html");
  const httplib::Result index = client.Get("/viewer/index.html");
  ASSERT_TRUE(index);
  EXPECT_NE(index->body.find("/three/three.module.js"), std::string::npos);
  const httplib::Result three = client.Get("/three/three.module.js");
  ASSERT_TRUE(three);
  EXPECT_EQ(three->status, 200);
  EXPECT_GT(three->body.size(), 100000u);
  EXPECT_EQ(client.Get("/three/../../package.json")->status, 404);  // nothing outside the mounts
  EXPECT_EQ(client.Get("/three/%2e%2e/%2e%2e/package.json")->status, 404);
  // Every answer carries the CORS header once, an unknown path's 404 too (issue 52: it had none).
  const httplib::Result missing = client.Get("/no-such-path");
  ASSERT_TRUE(missing);
  EXPECT_EQ(missing->status, 404);
  EXPECT_EQ(missing->get_header_value("Access-Control-Allow-Origin"), "*");
  EXPECT_EQ(missing->get_header_value_count("Access-Control-Allow-Origin"), 1u);
  EXPECT_EQ(three->get_header_value_count("Access-Control-Allow-Origin"), 1u);

  ServerOptions bare;
  bare.web_dir = (std::filesystem::temp_directory_path() / "no-such-web-dir").string();
  LightingServer without(bare, "{}");
  httplib::Client other("127.0.0.1", without.port());
  const httplib::Result said = other.Get("/");
  ASSERT_TRUE(said);
  EXPECT_NE(said->body.find("run scripts/setup.sh"), std::string::npos) << said->body;
  EXPECT_EQ(other.Get("/viewer/index.html")->status, 404);
}

}  // namespace
}  // namespace daylit::serve
