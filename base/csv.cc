#include "base/csv.h"

#include <charconv>
#include <cmath>
#include <fstream>
#include <sstream>

#include "base/error.h"

namespace daylit {
namespace {

std::string_view Trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t')) s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t')) s.remove_suffix(1);
  return s;
}

// Reads one record starting at content[*pos]; advances *pos past its line end and *line by the
// number of line breaks consumed. Returns false at the end of the input.
bool ReadRecord(std::string_view content, size_t* pos, int* line, const std::string& source,
                std::vector<std::string>* fields) {
  fields->clear();
  if (*pos >= content.size()) return false;
  std::string field;
  bool quoted = false;
  const int start_line = *line;
  size_t i = *pos;
  for (; i < content.size(); ++i) {
    const char c = content[i];
    if (quoted) {
      if (c == '"') {
        if (i + 1 < content.size() && content[i + 1] == '"') {
          field.push_back('"');
          ++i;
        } else {
          quoted = false;
        }
      } else {
        if (c == '\n') ++*line;
        field.push_back(c);
      }
    } else if (c == '"') {
      quoted = true;
    } else if (c == ',') {
      fields->emplace_back(Trim(field));
      field.clear();
    } else if (c == '\n' || c == '\r') {
      if (c == '\r' && i + 1 < content.size() && content[i + 1] == '\n') ++i;
      ++i;
      break;
    } else {
      field.push_back(c);
    }
  }
  if (quoted) {
    ThrowInputError("{}:{}: unterminated quoted field", source, start_line);
  }
  ++*line;
  *pos = i;
  fields->emplace_back(Trim(field));
  return true;
}

bool IsBlank(const std::vector<std::string>& fields) {
  return fields.size() == 1 && fields[0].empty();
}

}  // namespace

int CsvTable::Column(std::string_view name) const {
  for (size_t i = 0; i < header.size(); ++i) {
    if (header[i] == name) return static_cast<int>(i);
  }
  return -1;
}

int CsvTable::RequireColumn(std::string_view name) const {
  const int column = Column(name);
  if (column < 0) ThrowInputError("{}: missing column '{}'", source, name);
  return column;
}

std::string CsvTable::Where(size_t row) const {
  return fmt::format("{}:{}", source, line_numbers.at(row));
}

CsvTable ParseCsv(std::string_view content, std::string source) {
  CsvTable table;
  table.source = std::move(source);
  if (content.size() >= 3 && content.substr(0, 3) == "\xEF\xBB\xBF") content.remove_prefix(3);
  size_t pos = 0;
  int line = 1;
  std::vector<std::string> fields;
  while (ReadRecord(content, &pos, &line, table.source, &fields) && IsBlank(fields)) {
  }
  if (fields.empty() || IsBlank(fields)) ThrowInputError("{}: empty file (no header)", table.source);
  table.header = fields;
  for (;;) {
    const int record_line = line;
    if (!ReadRecord(content, &pos, &line, table.source, &fields)) break;
    if (IsBlank(fields)) continue;
    if (fields.size() != table.header.size()) {
      ThrowInputError("{}:{}: {} fields, but the header has {}", table.source, record_line,
                      fields.size(), table.header.size());
    }
    table.rows.push_back(fields);
    table.line_numbers.push_back(record_line);
  }
  return table;
}

std::string ReadTextFile(const std::filesystem::path& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) ThrowInputError("{}: cannot open", path.string());
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) ThrowInputError("{}: read error", path.string());
  return buffer.str();
}

CsvTable ReadCsvFile(const std::filesystem::path& path) {
  return ParseCsv(ReadTextFile(path), path.string());
}

std::string CsvField(std::string_view field) {
  if (field.find_first_of(",\"\r\n") == std::string_view::npos) return std::string(field);
  std::string out = "\"";
  for (const char c : field) {
    if (c == '"') out.push_back('"');
    out.push_back(c);
  }
  out.push_back('"');
  return out;
}

bool TryParseFiniteDouble(std::string_view text, double* value) {
  text = Trim(text);
  const char* begin = text.data();
  const char* end = text.data() + text.size();
  if (begin != end && *begin == '+') ++begin;
  const auto [ptr, ec] = std::from_chars(begin, end, *value);
  return begin != end && ec == std::errc() && ptr == end && std::isfinite(*value);
}

double ParseFiniteDouble(std::string_view text, std::string_view where) {
  double value = 0.0;
  if (!TryParseFiniteDouble(text, &value)) {
    ThrowInputError("{}: '{}' is not a finite number", where, Excerpt(Trim(text)));
  }
  return value;
}

int64_t ParseCount(std::string_view text, std::string_view where, int64_t most) {
  double value = 0.0;
  if (!TryParseFiniteDouble(text, &value) || value < 0.0 || value > static_cast<double>(most) ||
      value != std::floor(value)) {
    ThrowInputError("{}: '{}' is not a whole number from 0 to {}", where, Excerpt(Trim(text)), most);
  }
  return static_cast<int64_t>(value);
}

}  // namespace daylit
