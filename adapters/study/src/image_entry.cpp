#include <bounce/study/image_entry.hpp>

#include <bounce/errors.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>

#include <system_error>

#include <unistd.h>

namespace bounce::study {

namespace {
// Writes through a temporary name in the same directory, then renames (atomic on POSIX).
template <class Write>
void write_atomically(const std::filesystem::path& final_path, const char* extension, Write write) {
    const auto tmp = final_path.parent_path() /
                     (final_path.filename().string() + ".tmp" + std::to_string(::getpid()) + extension);
    write(tmp);
    std::error_code ec;
    std::filesystem::rename(tmp, final_path, ec);
    if (ec) {
        std::filesystem::remove(tmp, ec);
        throw bounce::error("bounce::study: cannot move " + tmp.string() + " to " + final_path.string());
    }
}
}  // namespace

std::optional<std::vector<image<glm::vec3>>> load_image_entry(const std::filesystem::path& dir, const std::string& key,
                                                              std::initializer_list<const char*> suffixes,
                                                              std::size_t width, std::size_t height) {
    std::vector<image<glm::vec3>> images;
    std::error_code ec;
    for (const char* suffix : suffixes) {
        const auto file = dir / (key + suffix);
        if (!std::filesystem::exists(file, ec)) return std::nullopt;
        try {
            images.push_back(io::read_rgb(file));
        } catch (const bounce::error&) {
            return std::nullopt;  // unreadable or truncated
        }
        if (images.back().width() != width || images.back().height() != height) return std::nullopt;
    }
    return images;
}

void store_image_entry(const std::filesystem::path& dir, const std::string& key,
                       std::initializer_list<std::pair<const char*, const image<glm::vec3>*>> images,
                       std::string_view description) {
    std::error_code ec;
    std::filesystem::create_directories(dir, ec);
    if (ec) throw bounce::error("bounce::study: cannot create the cache directory " + dir.string() + ": " + ec.message());
    for (const auto& [suffix, img] : images)
        write_atomically(dir / (key + suffix), ".exr", [&](const std::filesystem::path& p) { io::write_exr(p, img->view()); });
    write_atomically(dir / (key + ".json"), ".json",
                     [&](const std::filesystem::path& p) { io::write_text_file(p, description); });
}

}  // namespace bounce::study
