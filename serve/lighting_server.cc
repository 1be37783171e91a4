#include "serve/lighting_server.h"

#include <event2/buffer.h>
#include <event2/bufferevent.h>
#include <event2/event.h>
#include <event2/http.h>
#include <event2/keyvalq_struct.h>
#include <event2/listener.h>
#include <event2/thread.h>
#include <netdb.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <deque>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <list>
#include <mutex>
#include <optional>
#include <string_view>
#include <thread>
#include <unordered_set>
#include <utility>
#include <vector>

#include <fmt/format.h>
#include <opencv2/imgcodecs.hpp>

#include "base/error.h"
#include "base/files.h"
#include "base/log.h"
#include "serve/http_request.h"

namespace daylit::serve {
namespace {

constexpr const char* kVideoBoundary = "daylitframe";
constexpr size_t kMaxLine = 8 * 1024;  // a request line or a header line

const char* Reason(int status) {
  switch (status) {
    case 200: return "OK";
    case 302: return "Found";
    case 400: return "Bad Request";
    case 404: return "Not Found";
    case 405: return "Method Not Allowed";
    case 408: return "Request Timeout";
    case 414: return "URI Too Long";
    case 431: return "Request Header Fields Too Large";
    case 500: return "Internal Server Error";
    case 503: return "Service Unavailable";
    default: return "Unknown";
  }
}

using Headers = std::vector<std::pair<std::string, std::string>>;

// A response's status line and headers. Every answer, errors and unknown paths included, may be
// read by a page served from elsewhere. `length` absent: the body ends when the connection does.
std::string ResponseHead(int status, std::string_view type, std::optional<size_t> length, const Headers& extra,
                         bool keep_alive) {
  std::string head = fmt::format("HTTP/1.1 {} {}\r\nAccess-Control-Allow-Origin: *\r\n", status, Reason(status));
  if (!type.empty()) head += fmt::format("Content-Type: {}\r\n", type);
  if (length) head += fmt::format("Content-Length: {}\r\n", *length);
  for (const auto& [name, value] : extra) head += fmt::format("{}: {}\r\n", name, value);
  head += keep_alive ? "Connection: keep-alive\r\n\r\n" : "Connection: close\r\n\r\n";
  return head;
}

timeval Millis(int ms) { return timeval{ms / 1000, (ms % 1000) * 1000}; }

std::string JsonError(const std::string& message) { return nlohmann::json{{"error", message}}.dump(); }

std::string MimeType(const std::filesystem::path& file) {
  const std::string ext = file.extension().string();
  if (ext == ".html") return "text/html";
  if (ext == ".js" || ext == ".mjs") return "text/javascript";
  if (ext == ".css") return "text/css";
  if (ext == ".json" || ext == ".map") return "application/json";
  if (ext == ".png") return "image/png";
  if (ext == ".svg") return "image/svg+xml";
  return "application/octet-stream";
}

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

// One thread runs a libevent loop over every connection. HTTP/1.1 GET requests are read from each
// connection's input by a RequestReader (the server answers nothing else), so that the limits on a
// request's time, lines and fields, and the cap on connections with its 503, are the server's own:
// libevent 2.1's evhttp has no connection cap and times a request only by its silences.
class LightingServer::Loop {
 public:
  Loop(const ServerOptions& options, std::string scene_json);
  ~Loop();
  int Bind();  // the port bound; InputError naming HOST:PORT if it cannot be
  void Start();
  void Publish(std::shared_ptr<const FrameLighting> lighting);
  ServerStats stats() const {
    const std::lock_guard<std::mutex> lock(mutex_);
    return stats_;
  }
  bool viewer() const { return viewer_; }

 private:
  // A stream client's messages not yet handed to its socket: filled by Publish, emptied by the
  // loop when the socket has taken what it had.
  struct Client {
    std::deque<std::shared_ptr<const std::string>> queue;
    uint64_t dropped_unsaid = 0;  // lost since the last `event: dropped`
    std::optional<std::chrono::steady_clock::time_point> full_since;  // behind since, until it takes
    bool closed = false;  // behind for too long: the loop closes it
  };
  // kClosing: its last answer is being written; then its sending side is shut and what it still
  // sends is read and dropped until it closes or a second passes (a close with unread input would
  // reset the connection, and the client could lose the answer: an error's above all).
  enum class State { kRequest, kStream, kVideo, kClosing };
  struct Connection {
    Loop* loop = nullptr;
    bufferevent* bev = nullptr;
    event* deadline = nullptr;  // the request's whole time
    State state = State::kRequest;
    RequestReader reader;
    std::string input;  // received, not yet read as a request
    std::shared_ptr<Client> client;                         // a /stream
    std::shared_ptr<const FrameLighting> video_sent;        // a /video.mjpg: the frame last sent
    std::chrono::steady_clock::time_point last_sent;
  };

  static void OnAccept(evconnlistener*, evutil_socket_t fd, sockaddr*, int, void* self);
  static void OnRead(bufferevent*, void* c) { static_cast<Connection*>(c)->loop->Read(static_cast<Connection*>(c)); }
  static void OnWritten(bufferevent*, void* c) { static_cast<Connection*>(c)->loop->Written(static_cast<Connection*>(c)); }
  static void OnEvent(bufferevent*, short what, void* c) {
    static_cast<Connection*>(c)->loop->Event(static_cast<Connection*>(c), what);
  }
  static void OnDeadline(evutil_socket_t, short, void* c) {
    auto* conn = static_cast<Connection*>(c);
    if (conn->state == State::kClosing) return conn->loop->Close(conn);  // its linger is over
    conn->loop->TimedOut(conn);
  }
  static void OnNotify(evutil_socket_t, short, void* self) { static_cast<Loop*>(self)->Deliver(false); }
  static void OnTick(evutil_socket_t, short, void* self) { static_cast<Loop*>(self)->Deliver(true); }
  static void OnStop(evutil_socket_t, short, void* self) { event_base_loopbreak(static_cast<Loop*>(self)->base_); }

  void Accept(evutil_socket_t fd);
  void Read(Connection* c);
  void Written(Connection* c);
  void Event(Connection* c, short what);
  void TimedOut(Connection* c);
  void Close(Connection* c);
  void AwaitRequest(Connection* c);
  void Dispatch(Connection* c);
  // A whole answer; the connection waits for its next request, or closes once it is written.
  void Answer(Connection* c, int status, std::string_view type, const std::string& body, const Headers& extra = {},
              bool close = false);
  void AnswerJsonError(Connection* c, int status, const std::string& message, bool close = false) {
    Answer(c, status, "application/json", JsonError(message), {}, close);
  }
  void Lighting(Connection* c, const std::string& query);
  void Stream(Connection* c);
  // A stream or video answer: its head, no length (it ends with the connection), no read timeout.
  void StartPushing(Connection* c, State state, const std::string& type);
  void Video(Connection* c);
  void StaticFile(Connection* c, const std::filesystem::path& root, std::string_view rest);
  // New messages and frames to every stream and video client whose socket has taken the last;
  // `tick`: once a second, a comment to idle stream clients and the last frame again to viewers.
  void Deliver(bool tick);
  void SendStream(Connection* c, bool tick);
  void SendVideo(Connection* c, bool tick);
  bool Admit(Connection* c);  // a stream or video client under the cap, or 503 said
  std::shared_ptr<const std::string> Jpeg(const std::shared_ptr<const FrameLighting>& lighting);

  ServerOptions options_;
  std::string scene_json_;
  std::filesystem::path web_;
  bool viewer_ = false;
  event_base* base_ = nullptr;
  evconnlistener* listener_ = nullptr;
  event* notify_ = nullptr;
  event* tick_ = nullptr;
  event* stop_ = nullptr;  // activated from another thread: a loopbreak before the loop runs is lost
  std::thread thread_;
  std::unordered_set<Connection*> connections_;  // the loop's own

  mutable std::mutex mutex_;  // what Publish and stats() share with the loop
  std::shared_ptr<const FrameLighting> latest_;
  std::shared_ptr<const std::string> latest_json_;
  std::list<std::shared_ptr<Client>> clients_;
  int video_clients_ = 0;
  ServerStats stats_;
  // The last frame's JPEG, encoded once, on the loop.
  std::shared_ptr<const FrameLighting> jpeg_of_;
  std::shared_ptr<const std::string> jpeg_;
};

LightingServer::Loop::Loop(const ServerOptions& options, std::string scene_json)
    : options_(options), scene_json_(std::move(scene_json)), web_(options.web_dir) {
  static std::once_flag threads;
  std::call_once(threads, [] { evthread_use_pthreads(); });  // Publish wakes the loop from another thread
  base_ = event_base_new();
  if (base_ == nullptr) ThrowSystemError("--serve: cannot make an event loop");
  notify_ = event_new(base_, -1, 0, &Loop::OnNotify, this);
  tick_ = event_new(base_, -1, EV_PERSIST, &Loop::OnTick, this);
  stop_ = event_new(base_, -1, 0, &Loop::OnStop, this);
  viewer_ = std::filesystem::is_regular_file(web_ / "viewer" / "index.html") &&
            std::filesystem::is_regular_file(web_ / "node_modules" / "three" / "build" / "three.module.js");
}

int LightingServer::Loop::Bind() {
  const std::string where = fmt::format("{}:{}", options_.host, options_.port);
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = SOCK_STREAM;
  hints.ai_flags = AI_PASSIVE;
  addrinfo* found = nullptr;
  if (const int rc = getaddrinfo(options_.host.c_str(), std::to_string(options_.port).c_str(), &hints, &found); rc != 0) {
    ThrowInputError("--serve: cannot listen on {}: {}", where, gai_strerror(rc));
  }
  const int fd = socket(found->ai_family, found->ai_socktype | SOCK_NONBLOCK | SOCK_CLOEXEC, found->ai_protocol);
  std::string why;
  if (fd < 0) {
    why = std::strerror(errno);
  } else {
    const int yes = 1;
    setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof(yes));
    if (bind(fd, found->ai_addr, found->ai_addrlen) != 0) why = std::strerror(errno);
  }
  freeaddrinfo(found);
  if (!why.empty()) {
    if (fd >= 0) close(fd);
    ThrowInputError("--serve: cannot listen on {}: {}", where, why);
  }
  listener_ = evconnlistener_new(base_, &Loop::OnAccept, this, LEV_OPT_CLOSE_ON_FREE | LEV_OPT_CLOSE_ON_EXEC, -1, fd);
  if (listener_ == nullptr) {
    close(fd);
    ThrowInputError("--serve: cannot listen on {}: {}", where, std::strerror(errno));
  }
  sockaddr_storage bound{};
  socklen_t size = sizeof(bound);
  getsockname(fd, reinterpret_cast<sockaddr*>(&bound), &size);
  return ntohs(bound.ss_family == AF_INET6 ? reinterpret_cast<const sockaddr_in6*>(&bound)->sin6_port
                                           : reinterpret_cast<const sockaddr_in*>(&bound)->sin_port);
}

void LightingServer::Loop::Start() {
  const timeval second{1, 0};
  event_add(tick_, &second);
  thread_ = std::thread([this] { event_base_dispatch(base_); });
}

LightingServer::Loop::~Loop() {
  if (thread_.joinable()) {
    event_active(stop_, 0, 0);
    thread_.join();
  }
  for (Connection* c : std::vector<Connection*>(connections_.begin(), connections_.end())) Close(c);
  if (listener_ != nullptr) evconnlistener_free(listener_);
  event_free(notify_);
  event_free(tick_);
  event_free(stop_);
  event_base_free(base_);
}

void LightingServer::Loop::OnAccept(evconnlistener*, evutil_socket_t fd, sockaddr*, int, void* self) {
  static_cast<Loop*>(self)->Accept(fd);
}

void LightingServer::Loop::Accept(evutil_socket_t fd) {
  if (connections_.size() >= static_cast<size_t>(options_.max_connections)) {
    // At the cap: said at once, in one small write the fresh socket's buffer takes whole.
    const std::string body = JsonError(fmt::format("{} connections already (at most {})", connections_.size(),
                                                   options_.max_connections));
    const std::string answer = ResponseHead(503, "application/json", body.size(), {}, false) + body;
    (void)send(fd, answer.data(), answer.size(), MSG_NOSIGNAL | MSG_DONTWAIT);
    close(fd);
    const std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.refused;
    return;
  }
  auto* c = new Connection;
  c->loop = this;
  c->bev = bufferevent_socket_new(base_, fd, BEV_OPT_CLOSE_ON_FREE);
  c->deadline = evtimer_new(base_, &Loop::OnDeadline, c);
  if (c->bev == nullptr || c->deadline == nullptr) {
    if (c->bev == nullptr) close(fd);
    Close(c);
    return;
  }
  connections_.insert(c);
  bufferevent_setcb(c->bev, &Loop::OnRead, &Loop::OnWritten, &Loop::OnEvent, c);
  const timeval read_stall = Millis(options_.read_stall_ms), write_stall = Millis(options_.write_stall_ms);
  bufferevent_set_timeouts(c->bev, &read_stall, &write_stall);
  bufferevent_enable(c->bev, EV_READ | EV_WRITE);
  AwaitRequest(c);
}

void LightingServer::Loop::AwaitRequest(Connection* c) {
  c->state = State::kRequest;
  c->reader = RequestReader(RequestLimits{kMaxLine, options_.max_header_fields, options_.max_header_bytes});
  const timeval whole = Millis(options_.request_ms);
  evtimer_add(c->deadline, &whole);
}

void LightingServer::Loop::Close(Connection* c) {
  connections_.erase(c);
  if (c->client || c->state == State::kVideo) {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (c->client) c->client->closed = true, clients_.remove(c->client);
    if (c->state == State::kVideo) --video_clients_;
  }
  if (c->deadline != nullptr) event_free(c->deadline);
  if (c->bev != nullptr) bufferevent_free(c->bev);
  delete c;
}

void LightingServer::Loop::TimedOut(Connection* c) {
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.timed_out;
  }
  Close(c);
}

void LightingServer::Loop::Event(Connection* c, short what) {
  if ((what & BEV_EVENT_TIMEOUT) != 0 && c->state != State::kClosing) {
    const bool writing = (what & BEV_EVENT_WRITING) != 0;
    if (writing && (c->state == State::kStream || c->state == State::kVideo)) {
      const std::lock_guard<std::mutex> lock(mutex_);
      ++stats_.clients_closed;
    }
    if (writing || c->state == State::kRequest) return TimedOut(c);
    // A stream or video client that sends nothing is what it should be: read on.
    bufferevent_enable(c->bev, EV_READ);
    return;
  }
  Close(c);  // the client has gone, or its socket failed
}

void LightingServer::Loop::Written(Connection* c) {
  switch (c->state) {
    case State::kClosing: {
      // Written: no more to send; read what comes until the client closes, a second at most.
      shutdown(bufferevent_getfd(c->bev), SHUT_WR);
      const timeval linger{1, 0};
      evtimer_add(c->deadline, &linger);
      return;
    }
    case State::kStream: return SendStream(c, false);
    case State::kVideo: return SendVideo(c, false);
    default: return;
  }
}

void LightingServer::Loop::Read(Connection* c) {
  evbuffer* in = bufferevent_get_input(c->bev);
  const size_t received = evbuffer_get_length(in);
  if (c->state != State::kRequest) {
    evbuffer_drain(in, received);  // a stream, video or closing client's further bytes mean nothing
    return;
  }
  const size_t had = c->input.size();
  c->input.resize(had + received);
  evbuffer_remove(in, c->input.data() + had, received);
  while (c->state == State::kRequest) {
    switch (c->reader.Read(&c->input)) {
      case RequestReader::State::kReading:
        return;
      case RequestReader::State::kRefused:
        return AnswerJsonError(c, c->reader.status(), c->reader.reason(), true);
      case RequestReader::State::kComplete:
        evtimer_del(c->deadline);
        Dispatch(c);  // a kept-alive connection then reads its next request, if it came along
        break;
    }
  }
  c->input.clear();
}

void LightingServer::Loop::Answer(Connection* c, int status, std::string_view type, const std::string& body,
                                  const Headers& extra, bool close) {
  const bool keep_alive = !close && c->reader.keep_alive();
  const std::string head = ResponseHead(status, type, body.size(), extra, keep_alive);
  bufferevent_write(c->bev, head.data(), head.size());
  bufferevent_write(c->bev, body.data(), body.size());
  if (keep_alive) {
    AwaitRequest(c);
  } else {
    c->state = State::kClosing;  // shut once written (Written), closed at the client's EOF
    evtimer_del(c->deadline);
  }
}

void LightingServer::Loop::Dispatch(Connection* c) {
  if (c->reader.method() != "GET") return Answer(c, 405, "application/json", JsonError("only GET"), {{"Allow", "GET"}});
  const std::string target = c->reader.target();
  const size_t q = target.find('?');
  const std::string path = target.substr(0, q);
  const std::string query = q == std::string::npos ? "" : target.substr(q + 1);
  if (path == "/lighting") return Lighting(c, query);
  if (path == "/scene") return Answer(c, 200, "application/json", scene_json_);
  if (path == "/stream") return Stream(c);
  if (path == "/video.mjpg") return Video(c);
  std::shared_ptr<const FrameLighting> latest;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    latest = latest_;
  }
  if (path == "/envmap") {
    if (latest == nullptr || latest->envmap == nullptr) return AnswerJsonError(c, 503, "no relit environment map yet");
    return Answer(c, 200, "image/x-exr", EnvMapExr(*latest->envmap, latest->row.light, latest->overcast_share),
                  {{"X-Daylit-Frame", std::to_string(latest->row.frame)}});
  }
  if (path == "/frame.jpg") {
    const std::shared_ptr<const std::string> jpeg = latest ? Jpeg(latest) : nullptr;
    if (jpeg == nullptr) return AnswerJsonError(c, 503, "no camera frame yet");
    return Answer(c, 200, "image/jpeg", *jpeg,
                  {{"X-Daylit-Frame", std::to_string(latest->row.frame)}, {"Cache-Control", "no-store"}});
  }
  if (path == "/") {
    if (viewer_) return Answer(c, 302, "text/plain", "", {{"Location", "/viewer/index.html"}});
    return Answer(c, 200, "text/plain",
                  fmt::format("daylit lighting server: GET /lighting[?at=x,y,z], /stream (Server-Sent Events), /scene, "
                              "/envmap, /frame.jpg, /video.mjpg.\nThe browser viewer is not installed ({} has no viewer/ "
                              "or node_modules/three): run scripts/setup.sh.\n",
                              web_.string()));
  }
  if (viewer_ && path.rfind("/viewer/", 0) == 0) return StaticFile(c, web_ / "viewer", path.substr(8));
  if (viewer_ && path.rfind("/three/", 0) == 0) {
    return StaticFile(c, web_ / "node_modules" / "three" / "build", path.substr(7));
  }
  AnswerJsonError(c, 404, fmt::format("no {} here", path));
}

void LightingServer::Loop::Lighting(Connection* c, const std::string& query) {
  std::shared_ptr<const FrameLighting> latest;
  std::shared_ptr<const std::string> json;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    latest = latest_, json = latest_json_;
  }
  if (latest == nullptr) return AnswerJsonError(c, 503, "no frame yet");
  evkeyvalq params{};
  std::optional<std::string> at;
  if (evhttp_parse_query_str(query.c_str(), &params) == 0) {
    if (const char* value = evhttp_find_header(&params, "at")) at = value;
  }
  evhttp_clear_headers(&params);
  if (!at) return Answer(c, 200, "application/json", *json);
  glm::vec3 p;
  char tail = 0;
  if (std::sscanf(at->c_str(), "%f,%f,%f%c", &p.x, &p.y, &p.z, &tail) != 3 || !std::isfinite(p.x) ||
      !std::isfinite(p.y) || !std::isfinite(p.z)) {
    return AnswerJsonError(c, 400, fmt::format("at: '{}' is not x,y,z in scene coordinates (m)", *at));
  }
  Answer(c, 200, "application/json", LightingJson(*latest, p).dump());
}

void LightingServer::Loop::StaticFile(Connection* c, const std::filesystem::path& root, std::string_view rest) {
  size_t size = 0;
  char* decoded = evhttp_uridecode(std::string(rest).c_str(), 0, &size);
  const std::string name = decoded != nullptr ? std::string(decoded, size) : "";
  free(decoded);
  const std::filesystem::path file = root / name;
  // Only a file under the folder, where its links lead too: no '..', no way out.
  if (name.empty() || name.find('\0') != std::string::npos || !IsWithin(ResolvedPath(file), ResolvedPath(root)) ||
      !std::filesystem::is_regular_file(file)) {
    return AnswerJsonError(c, 404, fmt::format("no {} here", c->reader.target()));
  }
  std::ifstream in(file, std::ios::binary);
  std::string body((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (!in && !in.eof()) return AnswerJsonError(c, 500, fmt::format("{} cannot be read", c->reader.target()));
  Answer(c, 200, MimeType(file), body);
}

bool LightingServer::Loop::Admit(Connection* c) {
  size_t clients = 0;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    clients = clients_.size() + static_cast<size_t>(video_clients_);
  }
  if (clients < static_cast<size_t>(options_.max_clients)) return true;
  AnswerJsonError(c, 503, fmt::format("{} stream and video clients already", clients));
  return false;
}

void LightingServer::Loop::StartPushing(Connection* c, State state, const std::string& type) {
  c->state = state;
  const timeval write_stall = Millis(options_.write_stall_ms);
  bufferevent_set_timeouts(c->bev, nullptr, &write_stall);  // it owes no request: only writes are timed
  const std::string head = ResponseHead(200, type, std::nullopt, {{"Cache-Control", "no-cache"}}, false);
  bufferevent_write(c->bev, head.data(), head.size());
}

void LightingServer::Loop::Stream(Connection* c) {
  if (!Admit(c)) return;
  c->client = std::make_shared<Client>();
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    if (latest_json_) c->client->queue.push_back(latest_json_);  // the newest frame first
    clients_.push_back(c->client);
    ++stats_.clients_seen;
  }
  StartPushing(c, State::kStream, "text/event-stream");
  SendStream(c, false);
}

void LightingServer::Loop::Video(Connection* c) {
  if (!Admit(c)) return;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    ++video_clients_;
    ++stats_.clients_seen;
  }
  StartPushing(c, State::kVideo, std::string("multipart/x-mixed-replace; boundary=") + kVideoBoundary);
  SendVideo(c, false);
}

void LightingServer::Loop::SendStream(Connection* c, bool tick) {
  if (evbuffer_get_length(bufferevent_get_output(c->bev)) > 0) return;  // it has not taken the last yet
  std::string out;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    Client& client = *c->client;
    if (client.queue.empty()) {
      if (!tick) return;
      out = ": waiting\n\n";  // a comment: finds a vanished client within a second
    } else {
      if (client.dropped_unsaid > 0) {
        out += fmt::format("event: dropped\ndata: {}\n\n", client.dropped_unsaid);
        client.dropped_unsaid = 0;
      }
      for (const auto& message : client.queue) out += "data: " + *message + "\n\n";
      client.queue.clear();
      client.full_since.reset();
    }
  }
  bufferevent_write(c->bev, out.data(), out.size());
  c->last_sent = std::chrono::steady_clock::now();
}

void LightingServer::Loop::SendVideo(Connection* c, bool tick) {
  if (evbuffer_get_length(bufferevent_get_output(c->bev)) > 0) return;
  std::shared_ptr<const FrameLighting> next;
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    next = latest_;
  }
  // A new frame, or the same again after a second: a vanished viewer is found, and one that joins
  // after the run's end still gets its picture.
  if (next == nullptr || (next == c->video_sent && !tick)) return;
  const std::shared_ptr<const std::string> jpeg = Jpeg(next);
  if (jpeg == nullptr) return;
  const std::string head = fmt::format("--{}\r\nContent-Type: image/jpeg\r\nContent-Length: {}\r\nX-Daylit-Frame: {}\r\n\r\n",
                                       kVideoBoundary, jpeg->size(), next->row.frame);
  bufferevent_write(c->bev, head.data(), head.size());
  bufferevent_write(c->bev, jpeg->data(), jpeg->size());
  bufferevent_write(c->bev, "\r\n", 2);
  c->video_sent = next;
  c->last_sent = std::chrono::steady_clock::now();
}

void LightingServer::Loop::Deliver(bool tick) {
  const auto now = std::chrono::steady_clock::now();
  for (Connection* c : std::vector<Connection*>(connections_.begin(), connections_.end())) {
    if (c->state == State::kStream) {
      bool behind_too_long = false;
      {
        const std::lock_guard<std::mutex> lock(mutex_);
        behind_too_long = c->client->closed;
      }
      if (behind_too_long) {
        Close(c);
        continue;
      }
      SendStream(c, tick && now - c->last_sent >= std::chrono::milliseconds(900));
    } else if (c->state == State::kVideo) {
      SendVideo(c, tick && now - c->last_sent >= std::chrono::milliseconds(900));
    }
  }
}

void LightingServer::Loop::Publish(std::shared_ptr<const FrameLighting> lighting) {
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
          client->closed = true;  // the loop closes it
          ++stats_.clients_closed;
          continue;
        }
      }
      client->queue.push_back(json);
    }
  }
  event_active(notify_, 0, 0);  // thread-safe: the loop delivers
}

std::shared_ptr<const std::string> LightingServer::Loop::Jpeg(const std::shared_ptr<const FrameLighting>& lighting) {
  if (lighting->image.empty()) return nullptr;
  if (jpeg_of_ != lighting) {
    const cv::Mat& rgb = lighting->image;
    const cv::Mat continuous = rgb.isContinuous() ? rgb : rgb.clone();
    const cv::Mat bgr = capture::EncodeToBgr8(continuous.ptr<float>(), rgb.cols, rgb.rows, 1.0, lighting->linear_response.get());
    std::vector<uchar> bytes;
    cv::imencode(".jpg", bgr, bytes, {cv::IMWRITE_JPEG_QUALITY, options_.jpeg_quality});
    jpeg_ = std::make_shared<const std::string>(bytes.begin(), bytes.end());
    jpeg_of_ = lighting;
    const std::lock_guard<std::mutex> lock(mutex_);
    ++stats_.jpegs;
  }
  return jpeg_;
}

LightingServer::LightingServer(const ServerOptions& options, std::string scene_json)
    : loop_(std::make_unique<Loop>(options, std::move(scene_json))) {
  port_ = loop_->Bind();
  loop_->Start();
  Log().info("serving the lighting on http://{}:{}/ (/lighting, /stream, /scene, /envmap, /frame.jpg, /video.mjpg{})",
             options.host, port_, loop_->viewer() ? "; the viewer at /" : "; no viewer: run scripts/setup.sh");
}

LightingServer::~LightingServer() = default;

void LightingServer::Publish(std::shared_ptr<const FrameLighting> lighting) { loop_->Publish(std::move(lighting)); }

ServerStats LightingServer::stats() const { return loop_->stats(); }

}  // namespace daylit::serve
