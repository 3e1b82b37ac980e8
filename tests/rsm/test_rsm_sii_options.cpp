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
    o.assign = light_assignment::similarity;
    o.selection = vpl_selection::grid;
    o.thesis_weights = true;
    const auto rsm = indirect_technique::rsm_gather, sii = indirect_technique::sii;
    const auto c = examples::indirect_options_for(o, rsm, 512, {8, 8}, 0.01f);
    CHECK(c.technique == indirect_technique::rsm_gather);
    CHECK(c.count == 512);
    CHECK(c.assignment == light_assignment::similarity);
    CHECK(c.selection == vpl_selection::grid);
    CHECK_FALSE(c.energy_correct);
    CHECK(c.light.min_distance2 == Approx(1e-4f));
    o.assign = light_assignment::interleaved;
    CHECK(refused([&] { examples::indirect_options_for(o, sii, 0, {4, 4}, 0.f); }) == "--vpls");
    // More sub-buffers than VPLs: the library's refusal, under the program's flag.
    CHECK(refused([&] { examples::indirect_options_for(o, sii, 16, {64, 64}, 0.f); }) == "--vpls");
    try {
        examples::indirect_options_for(o, sii, 16, {64, 64}, 0.f);
    } catch (const parameter_error& e) {
        CHECK_THAT(e.what(), Catch::Contains("'--vpls': 16 VPLs are fewer than the 4096 sub-buffers"));
    }
    CHECK(refused([&] { examples::indirect_options_for(o, rsm, 16, {4, 4}, 0.f); }) == "");
    o.offset = -1.f;
    CHECK(refused([&] { examples::indirect_options_for(o, sii, 16, {4, 4}, 0.f); }) == "--offset");
}

namespace {
// "ok" when rsm_sii's command line `args` parses (into *out when given), else "refused: " and why.
std::string parse(std::vector<std::string> args, examples::options* out = nullptr) {
    CLI::App app;
    examples::options o;
    examples::add_options(app, o);
    std::reverse(args.begin(), args.end());
    try {
        app.parse(args);
    } catch (const CLI::ParseError& e) {
        return std::string("refused: ") + e.what();
    }
    if (out) *out = o;
    return std::string("ok");
}
}  // namespace

TEST_CASE("rsm_sii's named choices read into the library's enums; other spellings are refused", "[rsm][examples]") {
    examples::options o;
    REQUIRE(parse({"--technique", "rsm", "--assign", "similar", "--selection", "grid", "--backend", "gl"}, &o) == "ok");
    CHECK(o.technique == indirect_technique::rsm_gather);
    CHECK(o.assign == light_assignment::similarity);
    CHECK(o.selection == vpl_selection::grid);
    CHECK(o.backend == examples::backend::gl);
    REQUIRE(parse({}, &o) == "ok");
    CHECK(o.technique == indirect_technique::sii);
    CHECK(o.assign == light_assignment::interleaved);
    CHECK(o.selection == vpl_selection::flux_warping);
    CHECK(o.backend == examples::backend::cpu);
    CHECK(examples::name_of(examples::assignment_names, o.assign) == "interleaved");
    CHECK_THAT(parse({"--assign", "random"}), Catch::Contains("random not in {interleaved,blocked,similar}"));
    CHECK_THAT(parse({"--backend", "vulkan"}), Catch::Contains("vulkan not in {cpu,gl}"));
    // The enums' numbers are not spellings.
    CHECK_THAT(parse({"--technique", "0"}), Catch::Contains("0 not in {rsm,sii}"));
    CHECK_THAT(parse({"--backend", "1"}), Catch::StartsWith("refused"));
}

TEST_CASE("rsm_sii's number flags refuse what would wrap or be ignored", "[rsm][examples]") {
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
