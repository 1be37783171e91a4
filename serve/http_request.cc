#include "serve/http_request.h"

#include <algorithm>
#include <cctype>
#include <string_view>

#include <fmt/format.h>

namespace daylit::serve {
namespace {

bool EqualsNoCase(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

bool ContainsNoCase(std::string_view text, std::string_view word) {
  for (size_t i = 0; i + word.size() <= text.size(); ++i) {
    if (EqualsNoCase(text.substr(i, word.size()), word)) return true;
  }
  return false;
}

std::string_view Trimmed(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

}  // namespace

RequestReader::State RequestReader::Refuse(int status, std::string reason) {
  status_ = status;
  reason_ = std::move(reason);
  return state_ = State::kRefused;
}

RequestReader::State RequestReader::Read(std::string* input) {
  while (state_ == State::kReading) {
    // A line ends at LF, with or without the CR before it (RFC 9112 2.2 allows a bare LF).
    const size_t end = input->find('\n');
    const size_t length = end == std::string::npos ? input->size() : end;
    if (length > limits_.max_line) {
      return started() ? Refuse(400, fmt::format("a header line over {} bytes", limits_.max_line))
                       : Refuse(414, fmt::format("a request line over {} bytes", limits_.max_line));
    }
    if (end == std::string::npos) return state_;  // the rest of the line is still to come
    std::string line = input->substr(0, end);
    input->erase(0, end + 1);
    if (!line.empty() && line.back() == '\r') line.pop_back();
    Line(line);
  }
  return state_;
}

RequestReader::State RequestReader::Line(const std::string& line) {
  if (!started()) {
    if (line.empty()) return state_;  // a blank line before a request may be ignored (RFC 9112 2.2)
    const size_t a = line.find(' '), b = line.rfind(' ');
    const std::string version = b == std::string::npos ? "" : line.substr(b + 1);
    if (a == std::string::npos || a == 0 || b <= a + 1 || (version != "HTTP/1.1" && version != "HTTP/1.0")) {
      return Refuse(400, "not an HTTP/1.x request line");
    }
    method_ = line.substr(0, a);
    target_ = line.substr(a + 1, b - a - 1);
    http10_ = version == "HTTP/1.0";
    return state_;
  }
  if (line.empty()) return state_ = State::kComplete;
  ++fields_;
  field_bytes_ += line.size() + 2;
  if (fields_ > limits_.max_fields || field_bytes_ > limits_.max_field_bytes) {
    return Refuse(431, fmt::format("more than {} header fields or {} bytes of them: at most {} and {}",
                                   limits_.max_fields, limits_.max_field_bytes, limits_.max_fields,
                                   limits_.max_field_bytes));
  }
  const size_t colon = line.find(':');
  if (colon == std::string::npos || colon == 0) return Refuse(400, "a header line without a name and ':'");
  const std::string_view name = Trimmed(std::string_view(line).substr(0, colon));
  const std::string_view value = Trimmed(std::string_view(line).substr(colon + 1));
  if (EqualsNoCase(name, "connection")) {
    if (ContainsNoCase(value, "close")) close_asked_ = true;
    if (ContainsNoCase(value, "keep-alive")) keep_alive_asked_ = true;
  } else if (EqualsNoCase(name, "transfer-encoding") || (EqualsNoCase(name, "content-length") && value != "0")) {
    has_body_ = true;
  }
  return state_;
}

}  // namespace daylit::serve
