// The rsm_sii program's options: patterns of any N x M parse, and what cannot be rendered is
// refused by the option's name before any reference is computed.
#include <rsm_sii/options.hpp>

#include <catch2/catch.hpp>

#include <string>

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
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 0, {4, 4}, 0.f); }) == "count");
    o.offset = -1.f;
    CHECK(refused([&] { examples::indirect_options_for(o, "sii", 16, {4, 4}, 0.f); }) == "offset");
}
