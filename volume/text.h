// Small text helpers of the SPLAT! file parsers (splat.cpp, antenna.cpp): internal to volume/.
#pragma once

#include <charconv>
#include <cmath>
#include <cstddef>
#include <optional>
#include <string>
#include <string_view>
#include <system_error>
#include <vector>

namespace terravol::volume::text {

// Without leading and trailing blanks (space, tab, carriage return).
inline std::string_view trim(std::string_view s) {
  while (!s.empty() && (s.front() == ' ' || s.front() == '\t' || s.front() == '\r'))
    s.remove_prefix(1);
  while (!s.empty() && (s.back() == ' ' || s.back() == '\t' || s.back() == '\r'))
    s.remove_suffix(1);
  return s;
}

// A token for a message: quoted, at most 24 characters, non-printable bytes as '?'.
inline std::string quote_token(std::string_view token) {
  std::string s = "'";
  for (std::size_t i = 0; i < token.size() && i < 24; ++i) {
    const char c = token[i];
    s += (c >= 0x20 && c < 0x7f) ? c : '?';
  }
  if (token.size() > 24) s += "...";
  return s + "'";
}

// A finite number filling the whole (trimmed) text (a leading '+' allowed), or nothing.
inline std::optional<double> to_number(std::string_view text) {
  text = trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  double v = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), v);
  if (text.empty() || ec != std::errc() || end != text.data() + text.size() || !std::isfinite(v))
    return std::nullopt;
  return v;
}

// Splits text into lines (without '\n'); calls f(line_number, line) for each.
template <typename F>
inline void for_each_line(std::string_view text, F&& f) {
  std::size_t start = 0, line = 1;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    f(line, text.substr(start, end - start));
    start = end + 1;
    ++line;
  }
}

// The line without its comment (from ';') and surrounding blanks.
inline std::string_view strip_comment(std::string_view line) {
  const std::size_t semi = line.find(';');
  return trim(semi == std::string_view::npos ? line : line.substr(0, semi));
}

// The parts between separators (empty parts kept).
inline std::vector<std::string_view> split_on(std::string_view text, char sep) {
  std::vector<std::string_view> parts;
  std::size_t start = 0;
  while (true) {
    const std::size_t end = text.find(sep, start);
    parts.push_back(
        text.substr(start, end == std::string_view::npos ? std::string_view::npos : end - start));
    if (end == std::string_view::npos) return parts;
    start = end + 1;
  }
}

// The non-empty runs between spaces and tabs.
inline std::vector<std::string_view> split_whitespace(std::string_view text) {
  std::vector<std::string_view> parts;
  std::size_t i = 0;
  while (i < text.size()) {
    while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
    const std::size_t start = i;
    while (i < text.size() && text[i] != ' ' && text[i] != '\t') ++i;
    if (i > start) parts.push_back(text.substr(start, i - start));
  }
  return parts;
}

}  // namespace terravol::volume::text
