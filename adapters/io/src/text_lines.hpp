#pragma once
/// \file text_lines.hpp
/// Private to the io adapter: reading a scene file into memory and walking it line by line
/// the way tinyobjloader does, so that a line number we report is the one it counts.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace bounce::io::detail {

/// The whole of `file`. Throws scene_error (line 0) when it does not exist, is not a
/// regular file (a FIFO or /dev/zero would hang the reader), is larger than `max_bytes`,
/// cannot be read, or is empty.
std::string read_text_file(const std::filesystem::path& file, std::size_t max_bytes);

/// Splits text into lines ended by "\n", "\r\n" or "\r" (tinyobjloader's safeGetline),
/// numbered from 1.
class line_reader {
public:
    explicit line_reader(std::string_view text) noexcept : text_(text) {}
    /// The next line without its ending; false at the end of the text.
    bool next(std::string_view& line) noexcept;
    /// Number of the line `next` returned last.
    std::size_t number() const noexcept { return number_; }

private:
    std::string_view text_;
    std::size_t pos_ = 0, number_ = 0;
};

/// The tokens of `line` separated by spaces and tabs, stored into `out`.
void split_tokens(std::string_view line, std::vector<std::string_view>& out);

/// `token` as a number when all of it is one (an optional sign, digits, a point, an
/// exponent, as std::from_chars reads them) and it is finite in float range; else nullopt.
std::optional<float> parse_float(std::string_view token) noexcept;
/// Whether all of `token` is a number as std::from_chars reads it, even one beyond double
/// range, "inf" or "nan" (an optional leading '+' allowed).
bool is_number(std::string_view token) noexcept;
/// `token` as a whole integer (optional sign), else nullopt.
std::optional<long long> parse_integer(std::string_view token) noexcept;

/// The number after the first "line" (optionally "line:") in a library's message, e.g.
/// tinyobjloader's "(line 12.)" or nlohmann's "at line 3, column 5"; 0 when there is none.
std::size_t line_in_message(std::string_view message) noexcept;

}  // namespace bounce::io::detail
