#pragma once
/// \file output_files.hpp
/// Output files checked before the work that fills them, and written so that a failed write
/// is an error: a program that computes for minutes must not learn at the end that its
/// `--json` or `--out` cannot be written, nor report success after a write that failed.

#include <bounce/errors.hpp>

#include <filesystem>
#include <string_view>

namespace bounce::io {

/// A file that could not be written (opened, filled, flushed or closed); `file()` names it.
struct output_error : bounce::error {
    output_error(std::filesystem::path file, const std::string& what);
    const std::filesystem::path& file() const noexcept { return file_; }

private:
    std::filesystem::path file_;
};

/// Throws parameter_error naming `option` (e.g. "--json") unless `file` can be written
/// where it is to go: not empty, not a folder, not a device, pipe or other special file
/// (`/dev/full`, `/dev/stdout`), its folder exists or can be made, and the file can be
/// created there or, when present, opened for writing (checked by opening it, not by
/// permission bits: root may not create files in `/proc`). A file this check creates is
/// removed again; an existing one is left unchanged.
void check_output_file(std::string_view option, const std::filesystem::path& file);

/// check_output_file, and the extension names an image format this build can write
/// (OpenImageIO's writers: `.png`, `.exr` ...), so `--out x.unknown` fails before the work.
void check_image_output(std::string_view option, const std::filesystem::path& file);

/// Writes `text` to `file` (replacing it, making its folder), flushed and closed.
/// Throws output_error naming the file when any step fails (a full disk, `/dev/full`).
void write_text_file(const std::filesystem::path& file, std::string_view text);

}  // namespace bounce::io
