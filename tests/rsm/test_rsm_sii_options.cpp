// The rsm_sii program's options: patterns of any N x M parse, and what cannot be rendered is
// refused by the option's name before any reference is computed.
#include <rsm_sii/options.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <string>
#include <vector>

using namespace bounce;

namespace {
// The parameter a parameter_error names, or "" when `f` does not throw one.
template <class F>
std::string refused(F&& f) {
    try {
        f();
    } catch (const parameter_error& e) {
        return e.parameter();
    }
    return "";
}
}  // namespace

TEST_CASE("rsm_sii patterns parse as N x M and bad ones are refused naming --pattern", "[rsm][examples]") {
    CHECK(examples::parse_pattern("1x1").cells() == 1);
    const auto p = examples::parse_pattern("2x4");
    CHECK((p.n == 2 && p.m == 4));
    CHECK(examples::parse_pattern("8x8").cells() == 64);
    for (const char* bad : {"4", "x4", "4x", "4x4x", "0x4", "65x1", "4xfour", "-2x2", " 4x4"})
        CHECK(refused([&] { examples::parse_pattern(bad); }) == "--pattern");
}

TEST_CASE("rsm_sii's options make the renderer's options, and bad values are refused by name", "[rsm][examples]") {
    examples::options o;
    o.assign = "similar";
    o.selection = "grid";
    o.thesis_weights = true;
    const auto c = examples::indirect_options_for(o, "rsm", 512, {8, 8}, 0.01f);
    CHECK(c.technique == indirect_technique::rsm_gather);
    CHECK(c.count == 512);
    CHECK(c.assignment == light_assignment::similarity);
    CHECK(c.selection == vpl_selection::grid);
    CHECK_FALSE(c.energy_correct);
    CHECK(c.light.min_distance2 == Approx(1e-4f));
    o.assign = "random";
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 512, {4, 4}, 0.f); }) == "--assign");
    o.assign = "interleaved";
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 0, {4, 4}, 0.f); }) == "--vpls");
    // More sub-buffers than VPLs: the library's refusal, under the program's flag.
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 16, {64, 64}, 0.f); }) == "--vpls");
    try {
        examples::indirect_options_for(o, "sii", 16, {64, 64}, 0.f);
    } catch (const parameter_error& e) {
        CHECK_THAT(e.what(), Catch::Contains("'--vpls': 16 VPLs are fewer than the 4096 sub-buffers"));
    }
    CHECK(refused([&] { examples::indirect_options_for(o, "rsm", 16, {4, 4}, 0.f); }) == "");
    o.offset = -1.f;
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 16, {4, 4}, 0.f); }) == "--offset");
}

TEST_CASE("rsm_sii's number flags refuse what would wrap or be ignored", "[rsm][examples]") {
    const auto parse = [](std::vector<std::string> args) {
        CLI::App app;
        examples::options o;
        examples::add_options(app, o);
        std::reverse(args.begin(), args.end());
        try {
            app.parse(args);
        } catch (const CLI::ParseError& e) {
            return std::string("refused: ") + e.what();
        }
        return std::string("ok");
    };
    CHECK(parse({"--seed", "18446744073709551615"}) == "ok");
    CHECK_THAT(parse({"--seed", "-1"}), Catch::Contains("'-1' is not a whole number"));
    CHECK_THAT(parse({"--seed", "18446744073709551616"}), Catch::StartsWith("refused"));
    CHECK_THAT(parse({"--seed", "1e3"}), Catch::StartsWith("refused"));
    CHECK(parse({"--clamp", "0"}) == "ok");
    CHECK(parse({"--clamp", "0.25"}) == "ok");
    for (const char* bad : {"nan", "-1", "inf", "x"}) CHECK_THAT(parse({"--clamp", bad}), Catch::StartsWith("refused"));
    CHECK(parse({"--ref-spp", "4"}) == "ok");
    CHECK(parse({"--ref-spp", "1048576"}) == "ok");
    for (const char* bad : {"3", "0", "1", "2", "2049", "1048578", "nan", "4.0000001"})
        CHECK_THAT(parse({"--ref-spp", bad}), Catch::Contains("even number"));
    CHECK_THAT(parse({"--r-max", "0"}), Catch::Contains("'0' is not a radius in (0, 2]"));
    CHECK(parse({"--r-max", "2"}) == "ok");
}
