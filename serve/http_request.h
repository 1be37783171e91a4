// The head of an HTTP/1.x request (RFC 9112: a request line, header fields, a blank line), read
// from the bytes a connection has received so far, within limits on its lines and fields. No I/O:
// the lighting server feeds it each connection's input, the tests and the fuzzer feed it bytes.
#pragma once

#include <cstddef>
#include <string>

namespace daylit::serve {

struct RequestLimits {
  size_t max_line = 8 * 1024;          // a request line or one header line
  size_t max_fields = 100;             // header fields
  size_t max_field_bytes = 32 * 1024;  // their bytes, CRLFs included
};

class RequestReader {
 public:
  enum class State { kReading, kComplete, kRefused };

  explicit RequestReader(const RequestLimits& limits = {}) : limits_(limits) {}

  // Takes what belongs to this request's head from the front of `input` (a pipelined next request
  // stays there). kComplete: the head is read; kRefused: status() and reason() say why, and the
  // connection should be answered and closed; kReading: more bytes are needed.
  State Read(std::string* input);
  // For the next request on a kept-alive connection.
  void Reset() { *this = RequestReader(limits_); }

  State state() const { return state_; }
  bool started() const { return !method_.empty(); }  // its request line has been read
  const std::string& method() const { return method_; }
  const std::string& target() const { return target_; }
  // Whether the connection may carry the next request after this one is answered: HTTP/1.1 unless
  // it asks to close, HTTP/1.0 only if it asks to keep alive; never after a request with a body
  // (the server reads none).
  bool keep_alive() const { return !has_body_ && !close_asked_ && (!http10_ || keep_alive_asked_); }
  int status() const { return status_; }  // of a refusal: 400, 414 or 431
  const std::string& reason() const { return reason_; }

 private:
  State Refuse(int status, std::string reason);
  State Line(const std::string& line);

  RequestLimits limits_;
  State state_ = State::kReading;
  std::string method_, target_;
  bool http10_ = false, close_asked_ = false, keep_alive_asked_ = false, has_body_ = false;
  size_t fields_ = 0, field_bytes_ = 0;
  int status_ = 0;
  std::string reason_;
};

}  // namespace daylit::serve
