// A saved cache reads back bit for bit, and only with the parameters that built it.
#include <bounce/study/record_cache.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cstring>
#include <fstream>

using namespace bounce;

namespace {
std::filesystem::path temp_file(const char* name) {
    const auto dir = std::filesystem::temp_directory_path() / "bounce-test-ic";
    std::filesystem::create_directories(dir);
    return dir / name;
}
}  // namespace

TEST_CASE("records survive a save and load bit for bit", "[cache][study]") {
    pcg32 rng(3);
    std::vector<irradiance_record> recs(300);
    auto f = [&] { return (rng.next_float() - 0.5f) * 1e3f * rng.next_float() * rng.next_float(); };
    for (auto& r : recs) {
        r.position = {f(), f(), f()};
        r.normal = glm::normalize(glm::vec3(f(), f(), f() + 1e-3f));
        r.irradiance = {rng.next_float(), 1e-30f, 3e7f};
        for (int c = 0; c < 3; ++c) r.rotation[c] = {f(), f(), f()}, r.translation[c] = {f(), f(), f()};
        r.radius = 1e-3f + rng.next_float();
    }
    const nlohmann::json params = {{"scene", "cornell"}, {"rings", 16}, {"wedges", 64}, {"min_pixels", 1.5}};
    const auto file = temp_file("roundtrip.json");
    study::save_records(file, recs, params);
    const auto back = study::load_records(file, params);
    REQUIRE(back.size() == recs.size());
    CHECK(std::memcmp(back.data(), recs.data(), recs.size() * sizeof(irradiance_record)) == 0);
}

TEST_CASE("a cache built with other parameters, or a damaged one, is refused with the reason", "[cache][study][bad-input]") {
    const std::vector<irradiance_record> recs(2);
    const nlohmann::json params = {{"scene", "cornell"}, {"rings", 16}};
    const auto file = temp_file("params.json");
    study::save_records(file, recs, params);
    try {
        study::load_records(file, {{"scene", "cornell"}, {"rings", 32}});
        FAIL("loaded with other parameters");
    } catch (const study::cache_error& e) {
        CHECK(std::string(e.what()).find("rings") != std::string::npos);
        CHECK(e.file() == file);
    }
    CHECK_THROWS_AS(study::load_records(temp_file("missing.json"), params), study::cache_error);
    for (const char* text : {"", "{", "[1,2]", R"({"format":"bounce-irradiance-cache-1","parameters":{"scene":"cornell","rings":16},"records":[{"p":[1,2]}]})",
                             R"({"format":"bounce-irradiance-cache-1","parameters":{"scene":"cornell","rings":16},"records":[{"p":[0,0,0],"n":[0,0,1],"e":[1,1,1],"rot":[[0,0,0],[0,0,0],[0,0,0]],"tr":[[0,0,0],[0,0,0],[0,0,0]],"r":-1}]})"}) {
        std::ofstream(temp_file("bad.json")) << text;
        CHECK_THROWS_AS(study::load_records(temp_file("bad.json"), params), study::cache_error);
    }
}
