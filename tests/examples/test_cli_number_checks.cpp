// The examples' numeric option checks: what CLI11's own PositiveNumber lets through.
#include <common/cli_number_checks.hpp>

#include <catch2/catch.hpp>

#include <initializer_list>
#include <string>
#include <vector>

namespace {

// Parses `--x VALUE` against an option checked by `check`; returns whether CLI11 accepted it
// (and the value it stored), rethrowing anything but a validation failure.
bool accepts(const CLI::Validator& check, const std::string& value, double* stored = nullptr) {
    CLI::App app;
    double x = -7;
    app.add_option("--x", x)->check(check);
    std::vector<std::string> args{value, "--x"};  // CLI11 takes them in reverse order
    try {
        app.parse(args);
    } catch (const CLI::ValidationError&) {
        return false;
    }
    if (stored) *stored = x;
    return true;
}

// `check` takes each of `good`, storing it as written, and refuses each of `bad`.
void takes_exactly(const CLI::Validator& check, std::initializer_list<const char*> good,
                   std::initializer_list<const char*> bad) {
    for (const char* g : good) {
        double stored = -1;
        CAPTURE(g);
        CHECK(accepts(check, g, &stored));
        CHECK(stored == std::stod(g));
    }
    for (const char* b : bad) {
        CAPTURE(b);
        CHECK_FALSE(accepts(check, b));
    }
}

}  // namespace

TEST_CASE("finite_positive refuses what is not a finite number above zero", "[examples][cli]") {
    const std::string bad = GENERATE("0", "-0", "-1", "-1e-30", "nan", "NaN", "-nan", "inf", "-inf", "infinity",
                                     "1e400", "abc", "0.15x", "", " ");
    CAPTURE(bad);
    CHECK_FALSE(bounce::examples::finite_positive(std::string(bad)).empty());
    CHECK_FALSE(accepts(bounce::examples::finite_positive, bad));
}

TEST_CASE("finite_positive keeps every finite number above zero as written", "[examples][cli]") {
    const std::string good = GENERATE("0.15", "1", "4e-45", "1e-300", "3.4e38", "1e308", "0x1p-3", "+2");
    double stored = 0;
    CAPTURE(good);
    REQUIRE(accepts(bounce::examples::finite_positive, good, &stored));
    CHECK(stored == std::stod(good));
}

TEST_CASE("finite_non_negative takes zero and refuses the rest of what finite_positive refuses", "[examples][cli]") {
    CHECK(accepts(bounce::examples::finite_non_negative, "0"));
    CHECK(accepts(bounce::examples::finite_non_negative, "-0"));
    CHECK(accepts(bounce::examples::finite_non_negative, "2.5"));
    const std::string bad = GENERATE("-1e-30", "nan", "inf", "-inf", "abc", "");
    CAPTURE(bad);
    CHECK_FALSE(accepts(bounce::examples::finite_non_negative, bad));
}

TEST_CASE("unit_interval takes [0, 1] and nothing else", "[examples][cli]") {
    takes_exactly(bounce::examples::unit_interval, {"0", "-0", "1", "0.881", "1e-300", "0x1p-1"},
                  {"-1e-30", "1.0000001", "2", "nan", "inf", "-inf", "abc", "0.5x", ""});
}

TEST_CASE("quarter_turn_deg takes [0, 90) and nothing else", "[examples][cli]") {
    takes_exactly(bounce::examples::quarter_turn_deg, {"0", "-0", "30", "89.999", "1e-300", "0x1p+6"},
                  {"-1e-30", "90", "90.0000001", "180", "nan", "inf", "-inf", "abc", ""});
}

TEST_CASE("the refusal says what the option wants", "[examples][cli]") {
    const std::string message = bounce::examples::finite_positive(std::string("nan"));
    CHECK(message.find("'nan'") != std::string::npos);
    CHECK(message.find("finite number > 0") != std::string::npos);
}

TEST_CASE("seed_u64 takes every 64-bit seed in decimal digits and nothing else", "[examples][cli]") {
    // Doubles hold these exactly; larger seeds are checked through the message alone.
    takes_exactly(bounce::examples::seed_u64, {"0", "1", "4294967296", "9007199254740992"},
                  {"-1", "1.5", "1e3", "+3", " 7", "0x10", "nan", "", "18446744073709551616", "99999999999999999999"});
    CHECK(bounce::examples::seed_u64(std::string("18446744073709551615")).empty());
    CHECK(bounce::examples::seed_u64(std::string("-1")).find("whole number in [0, 18446744073709551615]") !=
          std::string::npos);
}
