#include "serve/load_clients.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <string>
#include <utility>
#include <vector>

namespace daylit::serve {

int ConnectTo(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return -1;
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (connect(fd, reinterpret_cast<const sockaddr*>(&addr), sizeof(addr)) != 0) {
    close(fd);
    return -1;
  }
  return fd;
}

SlowClients::SlowClients(int port, int count) {
  thread_ = std::thread([this, port, count] {
    const std::string request = "GET /lighting HTTP/1.1\r\nHost: 127.0.0.1\r\nX-Slow: " + std::string(4000, 'a');
    std::vector<std::pair<int, size_t>> sockets;  // fd, bytes sent
    while (!stop_) {
      while (static_cast<int>(sockets.size()) < count) {
        const int fd = ConnectTo(port);
        if (fd < 0) break;
        sockets.emplace_back(fd, 0);
        ++connects_;
      }
      for (auto& [fd, sent] : sockets) {
        const char byte = request[sent % request.size()];
        // Closed by the server: EOF waiting to be read, or a reset. Then another in its place.
        char peek = 0;
        const ssize_t peeked = recv(fd, &peek, 1, MSG_DONTWAIT | MSG_PEEK);
        const bool gone = peeked == 0 || (peeked < 0 && errno != EAGAIN && errno != EWOULDBLOCK) ||
                          send(fd, &byte, 1, MSG_NOSIGNAL | MSG_DONTWAIT) != 1;
        if (gone) {
          close(fd);
          fd = -1;
        } else {
          ++sent;
        }
      }
      sockets.erase(std::remove_if(sockets.begin(), sockets.end(), [](const auto& s) { return s.first < 0; }),
                    sockets.end());
      std::this_thread::sleep_for(std::chrono::milliseconds(400));
    }
    for (const auto& socket : sockets) close(socket.first);
  });
}

SlowClients::~SlowClients() {
  stop_ = true;
  thread_.join();
}

}  // namespace daylit::serve
