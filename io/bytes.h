// Byte and text helpers shared by the DEM readers. Hand-written: these are a few lines of
// bounds-checked decoding that no library here offers for in-memory buffers.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace terravol::io {

using Bytes = std::span<const std::uint8_t>;

// No single file may claim more samples than this (2^28, 1 GiB of floats): a header that
// claims more is rejected before anything is allocated.
inline constexpr std::size_t kMaxSamples = std::size_t{1} << 28;
// Nor more than this many rows or columns.
inline constexpr long long kMaxSide = 1 << 20;

// Throws FormatError(source, ...) unless 0 < rows, cols <= kMaxSide and rows * cols is at most
// kMaxSamples and at most max_from_input (the most samples the input could hold, given its size).
void check_dimensions(const std::string& source, long long rows, long long cols,
                      std::size_t max_from_input);

// Big-endian 16-bit two's complement integer at p (2 readable bytes).
inline std::int16_t read_be_i16(const std::uint8_t* p) {
  return static_cast<std::int16_t>(static_cast<std::uint16_t>((p[0] << 8) | p[1]));
}

// Parses a whole string (surrounding blanks allowed) as a decimal number; Fortran 'D'/'d'
// exponents are accepted as 'E'. Returns nullopt for anything else, including inf and nan.
std::optional<double> parse_number(std::string_view text);

// Parses a whole string (surrounding blanks allowed) as a decimal integer.
std::optional<long long> parse_integer(std::string_view text);

// Whitespace-separated tokens of a text buffer, with the line number for messages.
class TextCursor {
 public:
  explicit TextCursor(std::string_view text) : text_(text) {}
  // The next token, or an empty view at the end of the text.
  std::string_view next();
  // The rest of the current line (without the newline), advancing past it.
  std::string_view next_line();
  bool at_end();  // true when only blanks remain
  int line() const { return line_; }  // 1-based line of the last token returned
  std::size_t offset() const { return pos_; }

 private:
  void skip_blanks();
  std::string_view text_;
  std::size_t pos_ = 0;
  int line_ = 1;
};

// Lower-case ASCII copy.
std::string to_lower(std::string_view text);

// The text with XML's five special characters as entities (&amp; &lt; &gt; &quot; &apos;), for
// the writers' XML (KML, GDAL metadata).
std::string xml_escaped(std::string_view text);

}  // namespace terravol::io
