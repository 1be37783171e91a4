// The text report of a run (report.txt beside daylit replay's video): each line printed on
// stdout as it is said, and the whole written atomically at the end.
#pragma once

#include <filesystem>
#include <string>

namespace daylit::evaluation {

class RunReport {
 public:
  void Say(const std::string& line);
  const std::string& text() const { return text_; }
  void Write(const std::filesystem::path& file) const;

 private:
  std::string text_;
};

}  // namespace daylit::evaluation
