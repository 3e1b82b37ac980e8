// Output paths are checked before a program's work, and a write that fails is an error: the
// cases users hit (/proc, /dev/full, a folder, an unknown image extension) each refused.
#include "../parameter_refusal.hpp"
#include "../scoped_environment.hpp"
#include "scratch_folder.hpp"

#include <bounce/io/output_files.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <string>

using namespace bounce;
using bounce::test::refusal_message;
using bounce::test::scratch_folder;
using Catch::Matchers::Contains;
namespace fs = std::filesystem;

namespace {
std::string read_all(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}
}  // namespace

TEST_CASE("a writable output path passes the check and is left as it was", "[io][output][bad-input]") {
    scratch_folder dir;
    const fs::path fresh = dir.path() / "new" / "deeper" / "run.json";
    CHECK_NOTHROW(io::check_output_file("--json", fresh));
    CHECK(fs::is_directory(fresh.parent_path()));  // the folder is made ...
    CHECK_FALSE(fs::exists(fresh));                // ... but the file the check created is gone
    const fs::path existing = dir.write("old.json", "keep me");
    CHECK_NOTHROW(io::check_output_file("--json", existing));
    CHECK(read_all(existing) == "keep me");
}

TEST_CASE("outputs that cannot be written are refused naming the option", "[io][output][bad-input]") {
    scratch_folder dir;
    CHECK_THAT(refusal_message([&] { io::check_output_file("--json", dir.path()); }), Contains("'--json'") && Contains("is a folder"));
    CHECK_THAT(refusal_message([&] { io::check_output_file("--json", ""); }), Contains("empty"));
    const fs::path blocker = dir.write("file", "x");
    CHECK_THAT(refusal_message([&] { io::check_output_file("--out", blocker / "x.png"); }), Contains("'--out'"));
    if (fs::is_directory("/proc/self"))  // root may write almost anywhere, but not create files in /proc
        CHECK_THAT(refusal_message([&] { io::check_output_file("--json", "/proc/x.json"); }), Contains("cannot create"));
    if (fs::exists("/dev/full"))
        CHECK_THAT(refusal_message([&] { io::check_output_file("--json", "/dev/full"); }), Contains("not a regular file"));
}

TEST_CASE("an image output needs an extension the image writer knows", "[io][output][bad-input]") {
    scratch_folder dir;
    CHECK_NOTHROW(io::check_image_output("--out", dir.path() / "a.png"));
    CHECK_NOTHROW(io::check_image_output("--exr", dir.path() / "a.exr"));
    CHECK_THAT(refusal_message([&] { io::check_image_output("--out", dir.path() / "a.unknown"); }),
               Contains("'--out'") && Contains("'.unknown' is not an image format"));
    CHECK_THAT(refusal_message([&] { io::check_image_output("--out", dir.path() / "noextension"); }), Contains("'--out'"));
}

TEST_CASE("a failed write raises output_error naming the file, and a good one writes every byte", "[io][output][bad-input]") {
    scratch_folder dir;
    const fs::path good = dir.path() / "sub" / "a.txt";
    io::write_text_file(good, "hello\n");
    CHECK(read_all(good) == "hello\n");
    const fs::path blocker = dir.write("file", "x");
    try {
        io::write_text_file(blocker / "a.txt", "x");
        FAIL("wrote under a regular file");
    } catch (const io::output_error& e) {
        CHECK(e.file() == blocker / "a.txt");
    }
    // /dev/full opens, then fails every write: the failure must surface, not pass as success.
    if (fs::exists("/dev/full")) CHECK_THROWS_AS(io::write_text_file("/dev/full", std::string(100000, 'x')), io::output_error);
}

TEST_CASE("a scene name that is not under BOUNCE_SCENES names the folder it looked in", "[io][scene][bad-input]") {
    scratch_folder dir;
    bounce::test::scoped_environment env("BOUNCE_SCENES");
    env.set(dir.path().string());
    try {
        (void)io::load_scene_arg("sponza");
        FAIL("loaded a scene that is not there");
    } catch (const io::scene_error& e) {
        CHECK_THAT(e.what(), Contains((dir.path() / "sponza").string()) && Contains("BOUNCE_SCENES"));
    }
}
