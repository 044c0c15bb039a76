// Internal to the text-format readers (colmap_text.cc, tum.cc): lines, whitespace fields
// and strict, locale-independent numbers, with errors "FILE:LINE: FIELD: what is wrong".
#pragma once

#include <charconv>
#include <cmath>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Geometry>

#include "pipeline/core/status.h"

namespace fresco::text {

struct Line {
  int number = 0;         // 1-based
  std::string_view text;  // without the line break (and without a trailing '\r')
};

inline std::vector<Line> SplitLines(std::string_view text) {
  std::vector<Line> lines;
  size_t start = 0;
  int number = 1;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    lines.push_back({number++, line});
    start = end + 1;
  }
  return lines;
}

inline bool IsSpace(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

inline std::string_view Trim(std::string_view s) {
  while (!s.empty() && IsSpace(s.front())) s.remove_prefix(1);
  while (!s.empty() && IsSpace(s.back())) s.remove_suffix(1);
  return s;
}

// A line that holds no data: empty, blank or a '#' comment.
inline bool IsBlankOrComment(std::string_view line) {
  line = Trim(line);
  return line.empty() || line.front() == '#';
}

inline std::vector<std::string_view> SplitFields(std::string_view line) {
  std::vector<std::string_view> fields;
  size_t i = 0;
  while (i < line.size()) {
    while (i < line.size() && IsSpace(line[i])) ++i;
    const size_t start = i;
    while (i < line.size() && !IsSpace(line[i])) ++i;
    if (i > start) fields.push_back(line.substr(start, i - start));
  }
  return fields;
}

// Whole-field parses; a leading '+' is accepted. "nan"/"inf" parse (callers check finiteness).
inline bool ParseDouble(std::string_view s, double* value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), *value);
  return error == std::errc() && end == s.data() + s.size();
}

inline bool ParseInt64(std::string_view s, long long* value) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return false;
  const auto [end, error] = std::from_chars(s.data(), s.data() + s.size(), *value);
  return error == std::errc() && end == s.data() + s.size();
}

// Builds "FILE:LINE: FIELD: what" messages and parses fields of one line.
class LineParser {
 public:
  LineParser(const std::string& file, int line) : file_(file), line_(line) {}

  Status Error(const std::string& field, const std::string& what) const {
    return Status::Error(Where() + (field.empty() ? "" : field + ": ") + what);
  }
  std::string Where() const { return file_ + ":" + std::to_string(line_) + ": "; }

  Status Double(std::string_view s, const std::string& field, double* value) const {
    if (!ParseDouble(s, value)) return Error(field, "not a number ('" + std::string(s) + "')");
    if (!std::isfinite(*value)) return Error(field, "not finite (" + std::string(s) + ")");
    return Status::Ok();
  }
  Status Int(std::string_view s, const std::string& field, int* value) const {
    long long v = 0;
    if (!ParseInt64(s, &v)) return Error(field, "not an integer ('" + std::string(s) + "')");
    if (v < -2147483647LL || v > 2147483647LL) {
      return Error(field, "out of range (" + std::string(s) + ")");
    }
    *value = static_cast<int>(v);
    return Status::Ok();
  }
  Status Int64(std::string_view s, const std::string& field, long long* value) const {
    if (!ParseInt64(s, value)) {
      return Error(field, "not an integer ('" + std::string(s) + "')");
    }
    return Status::Ok();
  }

 private:
  const std::string& file_;
  int line_;
};

// Full precision, locale-independent: the shortest text that reads back as the very same
// double (as exact as "%.17g", but 0.1 stays "0.1" instead of "0.10000000000000001").
// Plain decimals are preferred over exponents unless much longer (1700000000, not 1.7e+09).
inline std::string FormatDouble(double value) {
  char general[64], fixed[64];
  const auto g = std::to_chars(general, general + sizeof(general), value);
  const auto f = std::to_chars(fixed, fixed + sizeof(fixed), value, std::chars_format::fixed);
  if (f.ec == std::errc() && (f.ptr - fixed) <= (g.ptr - general) + 8) {
    return std::string(fixed, f.ptr);
  }
  return std::string(general, g.ptr);
}

// Appends " field" (a separate statement: GCC 12 warns falsely on `" " + std::string`).
inline void AppendField(std::string* out, const std::string& field) {
  out->push_back(' ');
  out->append(field);
}

// A rotation read from a file: normalized when not unit; a zero quaternion is an error.
inline Status NormalizedQuaternion(const LineParser& parser, double w, double x, double y, double z,
                                   Eigen::Quaterniond* q) {
  const double norm = std::sqrt(w * w + x * x + y * y + z * z);
  if (!(norm > 1e-12) || !std::isfinite(norm)) {
    return parser.Error("quaternion", "zero norm, not a rotation");
  }
  // Unit to rounding (as written by us or COLMAP) stays bit-identical, so files round-trip.
  if (std::abs(norm - 1.0) <= 1e-15) {
    *q = Eigen::Quaterniond(w, x, y, z);
  } else {
    *q = Eigen::Quaterniond(w / norm, x / norm, y / norm, z / norm);
  }
  return Status::Ok();
}

}  // namespace fresco::text
