// The request head reader on bytes alone: split anywhere, pipelined, and at each limit.
#include "serve/http_request.h"

#include <string>

#include <gtest/gtest.h>

namespace daylit::serve {
namespace {

using State = RequestReader::State;

TEST(RequestReaderTest, AHeadSplitAtEveryByteIsReadOnceWholeAndTheNextRequestStays) {
  const std::string two = "GET /lighting?at=1,2,3 HTTP/1.1\r\nHost: a\r\nX-A:  b \r\n\r\nGET /scene HTTP/1.1\r\n\r\n";
  RequestReader reader;
  std::string input;
  size_t fed = 0;
  while (reader.state() == State::kReading && fed < two.size()) {
    input += two[fed++];
    reader.Read(&input);
  }
  ASSERT_EQ(reader.state(), State::kComplete);
  EXPECT_EQ(fed, two.find("GET /scene"));  // complete at the blank line, not before
  EXPECT_EQ(reader.method(), "GET");
  EXPECT_EQ(reader.target(), "/lighting?at=1,2,3");
  EXPECT_TRUE(reader.keep_alive());
  input += two.substr(fed);
  reader.Reset();
  ASSERT_EQ(reader.Read(&input), State::kComplete);
  EXPECT_EQ(reader.target(), "/scene");
  EXPECT_TRUE(input.empty());
}

TEST(RequestReaderTest, BareLineFeedsAndLeadingBlankLinesAreRead) {
  RequestReader reader;
  std::string input = "\r\n\nGET / HTTP/1.1\nHost: a\n\n";
  ASSERT_EQ(reader.Read(&input), State::kComplete);
  EXPECT_EQ(reader.target(), "/");
}

TEST(RequestReaderTest, WhetherTheConnectionStaysOpenAfterTheAnswer) {
  const auto keep = [](const std::string& head) {
    RequestReader reader;
    std::string input = head + "\r\n";
    EXPECT_EQ(reader.Read(&input), State::kComplete) << head;
    return reader.keep_alive();
  };
  EXPECT_TRUE(keep("GET / HTTP/1.1\r\n"));
  EXPECT_FALSE(keep("GET / HTTP/1.1\r\nConnection: Close\r\n"));
  EXPECT_FALSE(keep("GET / HTTP/1.0\r\n"));
  EXPECT_TRUE(keep("GET / HTTP/1.0\r\nConnection: keep-alive\r\n"));
  EXPECT_FALSE(keep("GET / HTTP/1.1\r\nContent-Length: 5\r\n"));  // a body it will not read
  EXPECT_TRUE(keep("GET / HTTP/1.1\r\nContent-Length: 0\r\n"));
  EXPECT_FALSE(keep("GET / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n"));
}

TEST(RequestReaderTest, EachLimitIsRefusedWithItsStatusAsSoonAsItIsPassed) {
  RequestLimits limits;
  limits.max_line = 64, limits.max_fields = 3, limits.max_field_bytes = 100;
  // A request line longer than the limit: 414 before its end has come.
  RequestReader reader(limits);
  std::string input = "GET /" + std::string(100, 'a');
  EXPECT_EQ(reader.Read(&input), State::kRefused);
  EXPECT_EQ(reader.status(), 414);
  // A header line: 400.
  reader = RequestReader(limits);
  input = "GET / HTTP/1.1\r\nX: " + std::string(100, 'a');
  EXPECT_EQ(reader.Read(&input), State::kRefused);
  EXPECT_EQ(reader.status(), 400);
  // A fourth field, or 100 bytes of them: 431.
  reader = RequestReader(limits);
  input = "GET / HTTP/1.1\r\nA: 1\r\nB: 2\r\nC: 3\r\nD: 4\r\n\r\n";
  EXPECT_EQ(reader.Read(&input), State::kRefused);
  EXPECT_EQ(reader.status(), 431);
  EXPECT_NE(reader.reason().find("at most 3"), std::string::npos) << reader.reason();
  reader = RequestReader(limits);
  input = "GET / HTTP/1.1\r\nA: " + std::string(50, 'a') + "\r\nB: " + std::string(50, 'b') + "\r\n\r\n";
  EXPECT_EQ(reader.Read(&input), State::kRefused);
  EXPECT_EQ(reader.status(), 431);
  // Not a request line, or a field without a name: 400.
  for (const char* bad : {"GET /\r\n", "GET / HTTP/2\r\n", " / HTTP/1.1\r\n", "GET  HTTP/1.1\r\n",
                          "GET / HTTP/1.1\r\nno colon\r\n", "GET / HTTP/1.1\r\n: empty\r\n"}) {
    reader = RequestReader(limits);
    input = bad;
    EXPECT_EQ(reader.Read(&input), State::kRefused) << bad;
    EXPECT_EQ(reader.status(), 400) << bad;
  }
}

}  // namespace
}  // namespace daylit::serve
