// A small RFC 4180 CSV reader/writer (quoted fields, "" escapes, CRLF), for the project's
// stable CSV interfaces: frames.csv, groundtruth.csv, `daylit sunpos --csv`.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>
#include <vector>

namespace daylit {

struct CsvTable {
  std::string source;                          // file name, for error messages
  std::vector<std::string> header;             // column names, trimmed
  std::vector<std::vector<std::string>> rows;  // every row has header.size() fields
  std::vector<int> line_numbers;               // 1-based line of each row in the source

  // Index of column `name`, or -1.
  int Column(std::string_view name) const;
  // Index of column `name`; throws InputError "<source>: missing column '<name>'".
  int RequireColumn(std::string_view name) const;
  // "<source>:<line>" of row `row`, for error messages.
  std::string Where(size_t row) const;
};

// Parses CSV text whose first record is a header. Blank lines are skipped. Throws InputError
// naming `source` and the line on an unterminated quote or a row with the wrong field count.
CsvTable ParseCsv(std::string_view content, std::string source);

// Reads and parses a CSV file; throws InputError naming the file if it cannot be read.
CsvTable ReadCsvFile(const std::filesystem::path& path);

// Reads a whole file into a string; throws InputError naming it if it cannot be read.
std::string ReadTextFile(const std::filesystem::path& path);

// A field as it must be written: quoted when it holds a comma, quote, CR or LF.
std::string CsvField(std::string_view field);

// Parses a finite decimal number (surrounding blanks and a leading '+' allowed); false if the
// text is anything else.
bool TryParseFiniteDouble(std::string_view text, double* value);

// Parses a finite decimal number; throws InputError "<where>: '<text>' is not a finite number".
double ParseFiniteDouble(std::string_view text, std::string_view where);

// Parses a whole number in [0, `most`] (written as a decimal number with no fraction, "12" or
// "12.0"); throws InputError "<where>: '<text>' is not a whole number from 0 to <most>".
int64_t ParseCount(std::string_view text, std::string_view where, int64_t most);

}  // namespace daylit
