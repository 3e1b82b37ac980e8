#pragma once
/// \file cli_number_checks.hpp
/// CLI11 validators for the examples' numeric options. CLI::PositiveNumber and
/// CLI::NonNegativeNumber let "nan" through (every comparison with NaN is false), so a run
/// would go on to fail, or quietly give NaN figures, after minutes of reference rendering,
/// and their messages print the range up to DBL_MAX in full. These refuse NaN and
/// infinities at parse time and say what they want.

#include <CLI/CLI.hpp>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <sstream>
#include <string>

namespace bounce::examples {

namespace detail {
/// The number `s` spells (the whole of it), or NaN when it spells none.
inline double parse_number(const std::string& s) {
    const char* begin = s.c_str();
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(begin, &end);
    if (end == begin || *end != '\0' || errno == ERANGE) return std::nan("");
    return v;
}

inline CLI::Validator finite_number_at_least_zero(bool zero_allowed) {
    const std::string want = zero_allowed ? "a finite number >= 0" : "a finite number > 0";
    return CLI::Validator(
        [zero_allowed, want](std::string& s) -> std::string {
            const double v = parse_number(s);
            if (std::isfinite(v) && (v > 0 || (zero_allowed && v == 0))) return {};
            return "'" + s + "' is not " + want;
        },
        zero_allowed ? "FINITE >= 0" : "FINITE > 0");
}

/// A number in [lo, hi] (or with `lo` or `hi` excluded: (lo, hi], [lo, hi)), called `what`
/// in refusals, which print the bounds as given ("'1' is not a support in (1, 16]").
inline CLI::Validator number_in(double lo, double hi, bool hi_included, const std::string& what,
                                bool lo_included = true) {
    std::ostringstream text;
    text << std::setprecision(15) << (lo_included ? '[' : '(') << lo << ", " << hi << (hi_included ? ']' : ')');
    const std::string range = text.str();
    return CLI::Validator(
        [=](std::string& s) -> std::string {
            const double v = parse_number(s);
            if ((v > lo || (lo_included && v == lo)) && (v < hi || (hi_included && v == hi))) return {};
            return "'" + s + "' is not " + what + " in " + range;
        },
        "IN " + range);
}
}  // namespace detail

/// A finite number above zero.
inline const CLI::Validator finite_positive = detail::finite_number_at_least_zero(false);
/// A finite number, zero or above.
inline const CLI::Validator finite_non_negative = detail::finite_number_at_least_zero(true);
/// A number in [0, 1] (CLI::Range lets NaN through as well).
inline const CLI::Validator unit_interval = detail::number_in(0, 1, true, "a number");
/// An angle in [0, 90) degrees: a turn of a square, which repeats every 90.
inline const CLI::Validator quarter_turn_deg = detail::number_in(0, 90, false, "an angle");

/// A whole number in [0, 2^64), spelled in decimal digits only: a seed. CLI11 would take
/// "-1" and wrap it to 2^64 - 1, and a double range would let "1.5" or "1e3" through.
inline const CLI::Validator seed_u64 = CLI::Validator(
    [](std::string& s) -> std::string {
        const bool digits = !s.empty() && s.size() <= 20 && std::all_of(s.begin(), s.end(), [](char c) {
            return c >= '0' && c <= '9';
        });
        if (digits && (s.size() < 20 || s <= "18446744073709551615")) return {};
        return "'" + s + "' is not a whole number in [0, 18446744073709551615]";
    },
    "UINT64");

}  // namespace bounce::examples
