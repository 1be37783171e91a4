// daylit's lighting server (replay/live --serve [HOST:]PORT): while the pipeline runs, other
// programs read each frame's lighting over HTTP on loopback (or any host given):
//   GET /lighting[?at=x,y,z]  the latest frame's message (serve/lighting_message.h); 503 before
//                             the first frame
//   GET /stream               Server-Sent Events: one `data:` message per frame, in order
//   GET /scene                what a renderer needs to place the camera (intrinsics, pose, up,
//                             north, units) and the virtual objects
//   GET /envmap               the relit environment map, 128 × 64 half-float OpenEXR
//   GET /frame.jpg            the latest camera frame as a JPEG
//   GET /video.mjpg           the camera frames as MJPEG (multipart/x-mixed-replace), one per frame
//   GET /                     the browser viewer (web/viewer: three.js, served from this server,
//                             nothing fetched from elsewhere)
// The pipeline only hands messages over (a copy under a lock); the network is the server's own
// thread's: one event loop (libevent) for every connection, so a client that sends its request a
// byte a second, or reads nothing, holds a socket and no worker, and /lighting answers beside a
// hundred of them. A client that falls behind loses its oldest messages (counted, and said in
// the stream as an `event: dropped`); one that takes nothing for a while, or cannot be written to
// for two seconds, is closed.
#pragma once

#include <cstdint>
#include <memory>
#include <string>

#include "serve/lighting_message.h"

namespace daylit::serve {

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 0;                   // 0: any free port (tests)
  size_t queued_per_client = 64;  // messages a stream client may fall behind before losing them
  int idle_close_s = 10;          // a stream client whose queue stayed full this long is closed
  int max_clients = 128;          // stream and video clients at once; more are answered 503
  int max_connections = 512;      // connections at once; the next is answered 503 and closed
  int read_stall_ms = 1000;       // a client silent this long while it owes a request is closed
  int request_ms = 2000;          // a request's line and headers must all arrive within this
  int write_stall_ms = 2000;      // a client that cannot be written to this long is closed
  int jpeg_quality = 90;
  // A request with more header fields, or more bytes of them, is answered 431; a request line
  // over 8 KiB 414, a header line over 8 KiB 400. A browser sends about 20 fields, 2 KiB.
  size_t max_header_fields = 100;
  size_t max_header_bytes = 32 * 1024;
  // The viewer's files: viewer/ (index.html, viewer.js) and node_modules/three (scripts/setup.sh
  // installs it from npm). Without them / says so and the rest is served as ever.
  std::string web_dir = DAYLIT_WEB_DIR;
};

// "[HOST:]PORT" → host and port; InputError naming `where` otherwise.
ServerOptions ParseHostPort(const std::string& text, const char* where);

struct ServerStats {
  uint64_t published = 0;      // messages handed over
  uint64_t dropped = 0;        // messages stream clients lost by falling behind
  uint64_t clients_seen = 0;   // stream clients that connected
  uint64_t clients_closed = 0; // closed by the server (behind, or not writable)
  uint64_t jpegs = 0;          // frames encoded as JPEG (once per frame, however many viewers)
  uint64_t refused = 0;        // connections answered 503 at the cap
  uint64_t timed_out = 0;      // connections closed for a request too slow or a stall
};

class LightingServer {
 public:
  // Binds and starts listening; throws InputError naming HOST:PORT if it cannot (taken, not
  // allowed, no such address) before any of the pipeline's work.
  LightingServer(const ServerOptions& options, std::string scene_json);
  ~LightingServer();  // stops: every connection closed, threads joined
  LightingServer(const LightingServer&) = delete;
  LightingServer& operator=(const LightingServer&) = delete;

  int port() const { return port_; }
  // The frame's lighting to /lighting and every stream client. Never blocks on the network.
  void Publish(std::shared_ptr<const FrameLighting> lighting);
  ServerStats stats() const;

 private:
  class Loop;  // the event loop and its connections (lighting_server.cc)
  std::unique_ptr<Loop> loop_;
  int port_ = 0;
};

}  // namespace daylit::serve
