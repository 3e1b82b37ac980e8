#include <bounce/io/output_files.hpp>

#include <OpenImageIO/imageio.h>

#include <fstream>
#include <string>
#include <system_error>

namespace bounce::io {

namespace fs = std::filesystem;

output_error::output_error(fs::path file, const std::string& what)
    : bounce::error("bounce::io: " + file.string() + ": " + what), file_(std::move(file)) {}

void check_output_file(std::string_view option, const fs::path& file) {
    const std::string name(option);
    if (file.empty()) throw parameter_error(name, "the path is empty");
    std::error_code ec;
    const fs::file_status st = fs::status(file, ec);
    if (fs::is_directory(st)) throw parameter_error(name, file.string() + " is a folder");
    if (fs::exists(st)) {
        if (!fs::is_regular_file(st))
            throw parameter_error(name, file.string() + " is not a regular file (a device, pipe or socket)");
        std::ofstream probe(file, std::ios::binary | std::ios::app);  // app: leaves the contents alone
        if (!probe) throw parameter_error(name, file.string() + " exists and cannot be written");
        return;
    }
    const fs::path dir = file.has_parent_path() ? file.parent_path() : fs::path(".");
    fs::create_directories(dir, ec);
    if (!fs::is_directory(dir, ec)) throw parameter_error(name, "cannot make the folder " + dir.string());
    {
        std::ofstream probe(file, std::ios::binary | std::ios::trunc);
        if (!probe) throw parameter_error(name, "cannot create " + file.string());
    }
    fs::remove(file, ec);
}

void check_image_output(std::string_view option, const fs::path& file) {
    check_output_file(option, file);
    // ImageOutput::create picks the writer by extension; no writer means no format.
    if (!OIIO::ImageOutput::create(file.string()))
        throw parameter_error(std::string(option), file.string() + ": '" + file.extension().string() +
                                                       "' is not an image format this build writes (use .png or .exr)");
}

void write_text_file(const fs::path& file, std::string_view text) {
    std::error_code ec;
    if (file.has_parent_path()) fs::create_directories(file.parent_path(), ec);
    std::ofstream out(file, std::ios::binary | std::ios::trunc);
    if (!out) throw output_error(file, "cannot open for writing");
    out.write(text.data(), std::streamsize(text.size()));
    out.flush();
    if (!out) throw output_error(file, "write failed (disk full or device error)");
    out.close();
    if (out.fail()) throw output_error(file, "close failed");
}

}  // namespace bounce::io
