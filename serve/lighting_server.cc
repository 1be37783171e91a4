#include "serve/lighting_server.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include <filesystem>

#include <fmt/format.h>
#include <httplib.h>
#include <opencv2/imgcodecs.hpp>

#include "base/error.h"
#include "base/log.h"

namespace daylit::serve {
namespace {

// Why binding `host`:`port` fails, from the system ("Address already in use"), or empty if it
// would not: httplib only says that it failed.
std::string WhyCannotBind(const std::string& host, int port) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(host.c_str(), std::to_string(port).c_str(), &hints, &found); rc != 0) {
    return gai_strerror(rc);
  }
  std::string why;
  const int fd = socket(found->ai_family, found->ai_socktype, found->ai_protocol);
  if (fd < 0) {
    why = std::strerror(errno);
  } else {
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));  // as httplib binds
    if (bind(fd, found->ai_addr, found->ai_addrlen) != 0) why = std::strerror(errno);
    close(fd);
  }
  freeaddrinfo(found);
  return why;
}

void NoFrameYet(httplib::Response* res, const char* what) {
  res->status = 503;
  res->set_content(fmt::format(R"({{"error": "no {} yet"}})", what), "application/json");
}

constexpr const char* kVideoBoundary = "daylitframe";

}  // namespace

ServerOptions ParseHostPort(const std::string& text, const char* where) {
  ServerOptions o;
  std::string port = text;
  if (const size_t colon = text.rfind(':'); colon != std::string::npos) {
    o.host = text.substr(0, colon);
    port = text.substr(colon + 1);
    if (o.host.size() >= 2 && o.host.front() == '[' && o.host.back() == ']') o.host = o.host.substr(1, o.host.size() - 2);
    if (o.host.empty()) ThrowInputError("{}: '{}' has no host before the ':' ([HOST:]PORT)", where, text);
  }
  size_t used = 0;
  int value = -1;
  try {
    value = std::stoi(port, &used);
  } catch (const std::exception&) {
    used = 0;
  }
  if (used == 0 || used != port.size() || value < 0 || value > 65535) {
    ThrowInputError("{}: '{}' is not [HOST:]PORT with a port in 0..65535 (0: any free one)", where, text);
  }
  o.port = value;
  return o;
}

LightingServer::LightingServer(const ServerOptions& options, std::string scene_json)
    : options_(options), scene_json_(std::move(scene_json)), server_(std::make_unique<httplib::Server>()) {
  httplib::Server& s = *server_;
  const size_t threads = static_cast<size_t>(options_.max_clients) + 4;
  s.new_task_queue = [threads] { return new httplib::ThreadPool(threads); };
  s.set_write_timeout(2, 0);  // a client that cannot be written to for 2 s is closed
  // A client that sends its request slower than that, or idles between requests, frees its worker
  // after a second (it held one for 5 s).
  s.set_read_timeout(1, 0);
  s.set_keep_alive_timeout(1);
  s.set_keep_alive_max_count(1000);
  // Every answer, errors and unknown paths included, may be read by a page served from elsewhere.
  s.set_default_headers({{"Access-Control-Allow-Origin", "*"}});
  // Too many header fields, or too many bytes of them: refused before any route runs.
  s.set_pre_routing_handler([this](const httplib::Request& req, httplib::Response& res) {
    size_t bytes = 0;
    for (const auto& [name, value] : req.headers) bytes += name.size() + value.size() + 4;  // ": " and CRLF
    if (req.headers.size() <= options_.max_header_fields && bytes <= options_.max_header_bytes) {
      return httplib::Server::HandlerResponse::Unhandled;
    }
    res.status = 431;
    res.set_content(nlohmann::json{{"error", fmt::format("{} header fields, {} bytes: at most {} and {}", req.headers.size(),
                                                         bytes, options_.max_header_fields, options_.max_header_bytes)}}
                        .dump(),
                    "application/json");
    return httplib::Server::HandlerResponse::Handled;
  });

  s.Get("/lighting", [this](const httplib::Request& req, httplib::Response& res) {
    std::shared_ptr<const FrameLighting> latest;
    std::shared_ptr<const std::string> json;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      latest = latest_, json = latest_json_;
    }
    if (latest == nullptr) {
      NoFrameYet(&res, "frame");
      return;
    }
    if (!req.has_param("at")) {
      res.set_content(*json, "application/json");
      return;
    }
    glm::vec3 at;
    char tail = 0;
    const std::string text = req.get_param_value("at");
    if (std::sscanf(text.c_str(), "%f,%f,%f%c", &at.x, &at.y, &at.z, &tail) != 3 || !std::isfinite(at.x) ||
        !std::isfinite(at.y) || !std::isfinite(at.z)) {
      res.status = 400;
      res.set_content(nlohmann::json{{"error", fmt::format("at: '{}' is not x,y,z in scene coordinates (m)", text)}}.dump(),
                      "application/json");
      return;
    }
    res.set_content(LightingJson(*latest, at).dump(), "application/json");
  });

  s.Get("/scene", [this](const httplib::Request&, httplib::Response& res) {
    res.set_content(scene_json_, "application/json");
  });

  s.Get("/stream", [this](const httplib::Request&, httplib::Response& res) {
    auto client = std::make_shared<Client>();
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!AdmitClient(&res)) return;
      if (latest_json_) client->queue.push_back(latest_json_);  // the newest frame first
      clients_.push_back(client);
      ++stats_.clients_seen;
    }
    res.set_header("Cache-Control", "no-cache");
    res.set_chunked_content_provider(
        "text/event-stream",
        [this, client](size_t, httplib::DataSink& sink) {
          std::unique_lock<std::mutex> lock(mutex_);
          changed_.wait_for(lock, std::chrono::seconds(1),
                            [&] { return stopping_ || client->closed || !client->queue.empty(); });
          if (stopping_ || client->closed) return false;
          std::string out;
          if (client->queue.empty()) {
            out = ": waiting\n\n";  // a comment: finds a vanished client within a second
          } else {
            if (client->dropped_unsaid > 0) {
              out += fmt::format("event: dropped\ndata: {}\n\n", client->dropped_unsaid);
              client->dropped_unsaid = 0;
            }
            for (const auto& message : client->queue) out += "data: " + *message + "\n\n";
            client->queue.clear();
            client->full_since.reset();
          }
          lock.unlock();
          if (!sink.write(out.data(), out.size())) {
            const std::lock_guard<std::mutex> relock(mutex_);
            if (!client->closed && !stopping_) client->closed = true, ++stats_.clients_closed;
            return false;
          }
          return true;
        },
        [this, client](bool) {
          const std::lock_guard<std::mutex> lock(mutex_);
          client->closed = true;
          clients_.remove(client);
        });
  });

  s.Get("/envmap", [this](const httplib::Request&, httplib::Response& res) {
    std::shared_ptr<const FrameLighting> latest;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      latest = latest_;
    }
    if (latest == nullptr || latest->envmap == nullptr) return NoFrameYet(&res, "relit environment map");
    res.set_header("X-Daylit-Frame", std::to_string(latest->row.frame));
    res.set_content(EnvMapExr(*latest->envmap, latest->row.light, latest->overcast_share), "image/x-exr");
  });

  s.Get("/frame.jpg", [this](const httplib::Request&, httplib::Response& res) {
    std::shared_ptr<const FrameLighting> latest;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      latest = latest_;
    }
    const std::shared_ptr<const std::string> jpeg = latest ? Jpeg(latest) : nullptr;
    if (jpeg == nullptr) return NoFrameYet(&res, "camera frame");
    res.set_header("X-Daylit-Frame", std::to_string(latest->row.frame));
    res.set_header("Cache-Control", "no-store");
    res.set_content(*jpeg, "image/jpeg");
  });

  s.Get("/video.mjpg", [this](const httplib::Request&, httplib::Response& res) {
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (!AdmitClient(&res)) return;
      ++video_clients_;
      ++stats_.clients_seen;
    }
    res.set_header("Cache-Control", "no-cache");
    auto sent = std::make_shared<std::shared_ptr<const FrameLighting>>();
    res.set_chunked_content_provider(
        std::string("multipart/x-mixed-replace; boundary=") + kVideoBoundary,
        [this, sent](size_t, httplib::DataSink& sink) {
          std::shared_ptr<const FrameLighting> next;
          {
            std::unique_lock<std::mutex> lock(mutex_);
            // A new frame, or the same again after a second: a vanished viewer is found, and one
            // that joins after the run's end still gets its picture.
            changed_.wait_for(lock, std::chrono::seconds(1), [&] { return stopping_ || (latest_ && latest_ != *sent); });
            if (stopping_) return false;
            next = latest_;
          }
          if (next == nullptr) return true;
          *sent = next;
          const std::shared_ptr<const std::string> jpeg = Jpeg(next);
          if (jpeg == nullptr) return true;
          const std::string head = fmt::format("--{}\r\nContent-Type: image/jpeg\r\nContent-Length: {}\r\nX-Daylit-Frame: {}\r\n\r\n",
                                               kVideoBoundary, jpeg->size(), next->row.frame);
          if (!sink.write(head.data(), head.size()) || !sink.write(jpeg->data(), jpeg->size()) || !sink.write("\r\n", 2)) {
            const std::lock_guard<std::mutex> lock(mutex_);
            if (!stopping_) ++stats_.clients_closed;
            return false;
          }
          return true;
        },
        [this](bool) {
          const std::lock_guard<std::mutex> lock(mutex_);
          --video_clients_;
        });
  });

  const std::filesystem::path web(options_.web_dir);
  viewer_ = std::filesystem::is_regular_file(web / "viewer" / "index.html") &&
            std::filesystem::is_regular_file(web / "node_modules" / "three" / "build" / "three.module.js") &&
            s.set_mount_point("/viewer", (web / "viewer").string()) &&
            s.set_mount_point("/three", (web / "node_modules" / "three" / "build").string());
  s.set_file_extension_and_mimetype_mapping("mjs", "text/javascript");
  s.Get("/", [this, web](const httplib::Request&, httplib::Response& res) {
    if (viewer_) {
      res.set_redirect("/viewer/index.html");
      return;
    }
    res.set_content(fmt::format("daylit lighting server: GET /lighting[?at=x,y,z], /stream (Server-Sent Events), /scene, "
                                "/envmap, /frame.jpg, /video.mjpg.\nThe browser viewer is not installed ({} has no viewer/ "
                                "or node_modules/three): run scripts/setup.sh.\n",
                                web.string()),
                    "text/plain");
  });

  const std::string where = fmt::format("{}:{}", options_.host, options_.port);
  if (options_.port == 0) {
    port_ = s.bind_to_any_port(options_.host);
    if (port_ < 0) ThrowInputError("--serve: cannot listen on {}: {}", where, WhyCannotBind(options_.host, 0));
  } else {
    const std::string why = WhyCannotBind(options_.host, options_.port);
    if (!why.empty() || !s.bind_to_port(options_.host, options_.port)) {
      ThrowInputError("--serve: cannot listen on {}: {}", where, why.empty() ? "the port could not be bound" : why);
    }
    port_ = options_.port;
  }
  listener_ = std::thread([this] { server_->listen_after_bind(); });
  // stop() does nothing to a server not yet listening: a stop that came first would leave the
  // listener running and the join hanging.
  for (int waited_ms = 0; !server_->is_running() && waited_ms < 10000; ++waited_ms) {
    std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  if (!server_->is_running()) {
    Stop();
    ThrowSystemError("--serve: the server on {} did not start", where);
  }
  Log().info("serving the lighting on http://{}:{}/ (/lighting, /stream, /scene, /envmap, /frame.jpg, /video.mjpg{})",
             options_.host, port_, viewer_ ? "; the viewer at /" : "; no viewer: run scripts/setup.sh");
}

LightingServer::~LightingServer() { Stop(); }

void LightingServer::Stop() {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    stopping_ = true;
  }
  changed_.notify_all();
  server_->stop();
  if (listener_.joinable()) listener_.join();
}

void LightingServer::Publish(std::shared_ptr<const FrameLighting> lighting) {
  auto json = std::make_shared<const std::string>(LightingJson(*lighting).dump());
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    latest_ = std::move(lighting);
    latest_json_ = json;
    ++stats_.published;
    for (const std::shared_ptr<Client>& client : clients_) {
      if (client->closed) continue;
      if (client->queue.size() >= options_.queued_per_client) {
        client->queue.pop_front();
        ++client->dropped_unsaid;
        ++stats_.dropped;
        const auto now = std::chrono::steady_clock::now();
        if (!client->full_since) client->full_since = now;
        if (now - *client->full_since > std::chrono::seconds(options_.idle_close_s)) {
          client->closed = true;  // its thread sees it and ends the response
          ++stats_.clients_closed;
          continue;
        }
      }
      client->queue.push_back(json);
    }
  }
  changed_.notify_all();
}

bool LightingServer::AdmitClient(httplib::Response* res) {
  const size_t clients = clients_.size() + static_cast<size_t>(video_clients_);
  if (!stopping_ && clients < static_cast<size_t>(options_.max_clients)) return true;
  res->status = 503;
  res->set_content(fmt::format(R"({{"error": "{} stream and video clients already"}})", clients), "application/json");
  return false;
}

std::shared_ptr<const std::string> LightingServer::Jpeg(const std::shared_ptr<const FrameLighting>& lighting) {
  if (lighting->image.empty()) return nullptr;
  const std::lock_guard<std::mutex> lock(jpeg_mutex_);
  if (jpeg_of_ != lighting) {
    const cv::Mat& rgb = lighting->image;
    const cv::Mat continuous = rgb.isContinuous() ? rgb : rgb.clone();
    const cv::Mat bgr = capture::EncodeToBgr8(continuous.ptr<float>(), rgb.cols, rgb.rows, 1.0, lighting->linear_response.get());
    std::vector<uchar> bytes;
    cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
    jpeg_ = std::make_shared<const std::string>(bytes.begin(), bytes.end());
    jpeg_of_ = lighting;
    const std::lock_guard<std::mutex> stats_lock(mutex_);
    ++stats_.jpegs;
  }
  return jpeg_;
}

ServerStats LightingServer::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace daylit::serve
