#pragma once
// A fresh folder under the system temp directory for files a test writes, removed at the
// end of the test; unique per process and per instance so tests may run in parallel.
#include <atomic>
#include <filesystem>
#include <fstream>
#include <string>
#include <string_view>

#include <unistd.h>

namespace bounce::test {

class scratch_folder {
public:
    scratch_folder() {
        static std::atomic<int> counter{0};
        path_ = std::filesystem::temp_directory_path() /
                ("bounce_test_io_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(path_);
        std::filesystem::create_directories(path_);
    }
    scratch_folder(const scratch_folder&) = delete;
    scratch_folder& operator=(const scratch_folder&) = delete;
    ~scratch_folder() {
        std::error_code ec;
        std::filesystem::remove_all(path_, ec);
    }

    const std::filesystem::path& path() const noexcept { return path_; }
    /// Writes `content` byte for byte to `name` inside the folder and returns its path.
    std::filesystem::path write(const std::string& name, std::string_view content) const {
        const auto p = path_ / name;
        std::filesystem::create_directories(p.parent_path());  // "sub/file" writes into sub/
        std::ofstream out(p, std::ios::binary);
        out.write(content.data(), std::streamsize(content.size()));
        return p;
    }

private:
    std::filesystem::path path_;
};

}  // namespace bounce::test
