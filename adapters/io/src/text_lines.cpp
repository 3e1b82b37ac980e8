#include "text_lines.hpp"

#include <bounce/io/scene.hpp>

#include <charconv>
#include <cmath>
#include <fstream>
#include <limits>
#include <system_error>

namespace bounce::io::detail {

std::string read_text_file(const std::filesystem::path& file, std::size_t max_bytes) {
    std::error_code ec;
    const auto status = std::filesystem::status(file, ec);
    if (ec || !std::filesystem::exists(status)) throw scene_error(file, 0, "no such file");
    if (!std::filesystem::is_regular_file(status)) throw scene_error(file, 0, "not a regular file");
    const auto size = std::filesystem::file_size(file, ec);
    if (ec) throw scene_error(file, 0, "cannot read its size: " + ec.message());
    if (size == 0) throw scene_error(file, 0, "empty file");
    if (size > max_bytes)
        throw scene_error(file, 0,
                          "file too large (" + std::to_string(size) + " bytes, at most " + std::to_string(max_bytes) + ")");
    std::ifstream in(file, std::ios::binary);
    if (!in) throw scene_error(file, 0, "cannot open");
    std::string text(static_cast<std::size_t>(size), '\0');
    in.read(text.data(), static_cast<std::streamsize>(text.size()));
    // A file that shrank while we read it is truncated: keep what arrived.
    text.resize(static_cast<std::size_t>(in.gcount()));
    if (text.empty()) throw scene_error(file, 0, "empty file");
    return text;
}

bool line_reader::next(std::string_view& line) noexcept {
    if (pos_ >= text_.size()) return false;
    const std::size_t end = text_.find_first_of("\r\n", pos_);
    ++number_;
    if (end == std::string_view::npos) {
        line = text_.substr(pos_);
        pos_ = text_.size();
        return true;
    }
    line = text_.substr(pos_, end - pos_);
    pos_ = end + 1;
    if (text_[end] == '\r' && pos_ < text_.size() && text_[pos_] == '\n') ++pos_;
    return true;
}

void split_tokens(std::string_view line, std::vector<std::string_view>& out) {
    out.clear();
    std::size_t i = 0;
    while (i < line.size()) {
        while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
        const std::size_t start = i;
        while (i < line.size() && line[i] != ' ' && line[i] != '\t') ++i;
        if (i > start) out.push_back(line.substr(start, i - start));
    }
}

namespace {
// std::from_chars reads no leading '+', which OBJ writers do emit.
std::string_view drop_plus(std::string_view t) noexcept {
    if (t.size() > 1 && t[0] == '+' && t[1] != '+' && t[1] != '-') t.remove_prefix(1);
    return t;
}
}  // namespace

std::optional<float> parse_float(std::string_view token) noexcept {
    token = drop_plus(token);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size()) return std::nullopt;
    // Parsed as double so that tiny values round to float denormals or zero instead of
    // failing; anything beyond float range would become infinity in the mesh.
    if (!std::isfinite(value) || std::abs(value) > double(std::numeric_limits<float>::max())) return std::nullopt;
    return static_cast<float>(value);
}

bool is_number(std::string_view token) noexcept {
    token = drop_plus(token);
    double value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    return (ec == std::errc() || ec == std::errc::result_out_of_range) && ptr == token.data() + token.size() &&
           !token.empty();
}

std::optional<long long> parse_integer(std::string_view token) noexcept {
    token = drop_plus(token);
    long long value = 0;
    const auto [ptr, ec] = std::from_chars(token.data(), token.data() + token.size(), value);
    if (ec != std::errc() || ptr != token.data() + token.size() || token.empty()) return std::nullopt;
    return value;
}

std::size_t line_in_message(std::string_view message) noexcept {
    for (std::size_t at = message.find("line"); at != std::string_view::npos; at = message.find("line", at + 4)) {
        std::size_t i = at + 4;
        if (i < message.size() && message[i] == ':') ++i;
        if (i >= message.size() || message[i] != ' ') continue;
        ++i;
        std::size_t end = i;
        while (end < message.size() && message[end] >= '0' && message[end] <= '9') ++end;
        if (end == i) continue;
        std::size_t line = 0;
        const auto [ptr, ec] = std::from_chars(message.data() + i, message.data() + end, line);
        if (ec == std::errc()) return line;
    }
    return 0;
}

}  // namespace bounce::io::detail
