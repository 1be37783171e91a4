#include "serve/lighting_server.h"

#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstring>

#include <fmt/format.h>
#include <httplib.h>

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

void AllowAnyOrigin(httplib::Response* res) { res->set_header("Access-Control-Allow-Origin", "*"); }

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
  if (used == 0 || used != port.size() || value < 1 || value > 65535) {
    ThrowInputError("{}: '{}' is not [HOST:]PORT with a port in 1..65535", where, text);
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
  s.set_keep_alive_max_count(1000);

  s.Get("/lighting", [this](const httplib::Request& req, httplib::Response& res) {
    AllowAnyOrigin(&res);
    std::shared_ptr<const FrameLighting> latest;
    std::shared_ptr<const std::string> json;
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      latest = latest_, json = latest_json_;
    }
    if (latest == nullptr) {
      res.status = 503;
      res.set_content(R"({"error": "no frame yet"})", "application/json");
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
    AllowAnyOrigin(&res);
    res.set_content(scene_json_, "application/json");
  });

  s.Get("/stream", [this](const httplib::Request&, httplib::Response& res) {
    AllowAnyOrigin(&res);
    auto client = std::make_shared<Client>();
    {
      const std::lock_guard<std::mutex> lock(mutex_);
      if (stopping_ || clients_.size() >= static_cast<size_t>(options_.max_clients)) {
        res.status = 503;
        res.set_content(fmt::format(R"({{"error": "{} stream clients already"}})", clients_.size()), "application/json");
        return;
      }
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

  s.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content("daylit lighting server: GET /lighting[?at=x,y,z], /stream (Server-Sent Events), /scene\n",
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
  Log().info("serving the lighting on http://{}:{}/ (/lighting, /stream, /scene)", options_.host, port_);
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

ServerStats LightingServer::stats() const {
  const std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

}  // namespace daylit::serve
