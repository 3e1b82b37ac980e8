#pragma once
// A solve's progress callback that checks the unshot power never rises (to `tolerance`,
// relative) from one step to the next: what a progressive solver promises first.
#include <bounce/radiosity/solve.hpp>

#include <catch2/catch.hpp>

namespace bounce::radiosity_test {

/// `last`: the unshot fraction to start from (1 before a solve; reset it between solves).
inline auto unshot_never_rises(double& last, double tolerance) {
    return [&last, tolerance](const radiosity_progress& p) {
        CHECK(p.unshot_fraction <= last * (1 + tolerance));
        last = p.unshot_fraction;
        return true;
    };
}

}  // namespace bounce::radiosity_test
