// The lighting server over real loopback connections (cpp-httplib's client, and a raw socket for
// a client that never reads).
#include "serve/lighting_server.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <httplib.h>
#include <glm/gtc/constants.hpp>
#include <nlohmann/json.hpp>

#include "base/csv.h"
#include "base/error.h"

namespace daylit::serve {
namespace {

std::shared_ptr<FrameLighting> Frame(int index) {
  auto l = std::make_shared<FrameLighting>();
  l->row.frame = index;
  l->row.light.sun_rgb = glm::dvec3(80.0 + index, 60.0, 40.0);
  l->row.light.sky_rgb = glm::dvec3(10.0, 11.0, 12.0 + index);
  l->row.confidence = 0.75;
  l->row.sun_up = true;
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
  for (const char* bad : {"abc", "70000", "0", ":80", "host:", "80x"}) {
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
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(server.port()));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ASSERT_EQ(connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)), 0);
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

}  // namespace
}  // namespace daylit::serve
