#include "io/bytes.h"

#include <charconv>
#include <cmath>
#include <string>

#include "io/error.h"

namespace terravol::io {

void check_dimensions(const std::string& source, long long rows, long long cols,
                      std::size_t max_from_input) {
  if (rows <= 0 || cols <= 0) {
    throw FormatError(source, "grid of " + std::to_string(rows) + " x " + std::to_string(cols) +
                                  " samples is empty or negative");
  }
  if (rows > kMaxSide || cols > kMaxSide ||
      static_cast<unsigned long long>(rows) * static_cast<unsigned long long>(cols) > kMaxSamples) {
    throw FormatError(source, "grid of " + std::to_string(rows) + " x " + std::to_string(cols) +
                                  " samples is absurdly large");
  }
  const auto n = static_cast<std::size_t>(rows) * static_cast<std::size_t>(cols);
  if (n > max_from_input) {
    throw FormatError(source, "header claims " + std::to_string(rows) + " x " +
                                  std::to_string(cols) + " samples but the file holds at most " +
                                  std::to_string(max_from_input));
  }
}

namespace {
std::string_view trim(std::string_view t) {
  while (!t.empty() && (t.front() == ' ' || t.front() == '\t' || t.front() == '\r' ||
                        t.front() == '\n'))
    t.remove_prefix(1);
  while (!t.empty() &&
         (t.back() == ' ' || t.back() == '\t' || t.back() == '\r' || t.back() == '\n'))
    t.remove_suffix(1);
  return t;
}
}  // namespace

std::optional<double> parse_number(std::string_view text) {
  text = trim(text);
  if (text.empty() || text.size() > 64) return std::nullopt;
  std::string s(text);
  for (char& c : s) {
    if (c == 'D' || c == 'd') c = 'E';
  }
  if (s.front() == '+') s.erase(0, 1);
  double value = 0.0;
  const auto [end, ec] = std::from_chars(s.data(), s.data() + s.size(), value);
  if (ec != std::errc() || end != s.data() + s.size() || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<long long> parse_integer(std::string_view text) {
  text = trim(text);
  if (!text.empty() && text.front() == '+') text.remove_prefix(1);
  if (text.empty()) return std::nullopt;
  long long value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc() || end != text.data() + text.size()) return std::nullopt;
  return value;
}

void TextCursor::skip_blanks() {
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == '\n') {
      ++line_;
    } else if (c != ' ' && c != '\t' && c != '\r' && c != '\0') {
      break;
    }
    ++pos_;
  }
}

std::string_view TextCursor::next() {
  skip_blanks();
  const std::size_t start = pos_;
  while (pos_ < text_.size()) {
    const char c = text_[pos_];
    if (c == ' ' || c == '\t' || c == '\r' || c == '\n' || c == '\0') break;
    ++pos_;
  }
  return text_.substr(start, pos_ - start);
}

std::string_view TextCursor::next_line() {
  const std::size_t start = pos_;
  std::size_t end = text_.find('\n', pos_);
  if (end == std::string_view::npos) end = text_.size();
  pos_ = end < text_.size() ? end + 1 : end;
  if (end < text_.size()) ++line_;
  std::string_view line = text_.substr(start, end - start);
  if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
  return line;
}

bool TextCursor::at_end() {
  skip_blanks();
  return pos_ >= text_.size();
}

std::string to_lower(std::string_view text) {
  std::string s(text);
  for (char& c : s) {
    if (c >= 'A' && c <= 'Z') c = static_cast<char>(c - 'A' + 'a');
  }
  return s;
}

std::string xml_escaped(std::string_view text) {
  std::string out;
  out.reserve(text.size());
  for (const char c : text) {
    switch (c) {
      case '&': out += "&amp;"; break;
      case '<': out += "&lt;"; break;
      case '>': out += "&gt;"; break;
      case '"': out += "&quot;"; break;
      case '\'': out += "&apos;"; break;
      default: out += c;
    }
  }
  return out;
}

}  // namespace terravol::io
