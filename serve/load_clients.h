// Clients that misbehave, for the lighting server's tests and benchmarks: raw loopback sockets
// (daylit_serve_load, linked by lighting_server_test and serve_bench; never by daylit).
#pragma once

#include <atomic>
#include <thread>

namespace daylit::serve {

// A plain TCP connection to 127.0.0.1:`port`; -1 if it fails.
int ConnectTo(int port);

// `count` clients that send their requests a byte every 0.4 s, slower than any request may take
// (a header that never ends): the server closes each when its request's time is up, and another
// connects in its place, so that `count` are always there, as in a slow-loris attack.
class SlowClients {
 public:
  SlowClients(int port, int count);
  ~SlowClients();
  SlowClients(const SlowClients&) = delete;
  SlowClients& operator=(const SlowClients&) = delete;
  int connects() const { return connects_; }

 private:
  std::atomic<bool> stop_{false};
  std::atomic<int> connects_{0};
  std::thread thread_;
};

}  // namespace daylit::serve
