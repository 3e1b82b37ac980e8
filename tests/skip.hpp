#pragma once
// Skipping a test case whose input is absent (the shared scenes, outside the repository), so
// that ctest reports it as skipped rather than passed. Catch2 v2 has no skip, so a test case
// run alone (as catch_discover_tests registers every case with ctest: one process per case,
// selected by its name) exits with skip_exit_code, which bounce_add_test maps to "Skipped"
// through ctest's SKIP_RETURN_CODE. Run among others (the executable without a filter), the
// case only warns and returns, so the rest still run.
#include <catch2/catch.hpp>

#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <string>

namespace bounce::test {

/// The exit code ctest reads as "skipped" (tests/CMakeLists.txt, SKIP_RETURN_CODE).
inline constexpr int skip_exit_code = 77;

/// True when the command line selects exactly one test case (the current one).
inline bool running_alone() {
    const auto config = Catch::getCurrentContext().getConfig();
    if (!config || !config->hasTestFilters()) return false;
    return Catch::filterTests(Catch::getAllTestCasesSorted(*config), config->testSpec(), *config).size() == 1;
}

/// Skips the current test case for `reason`: exits with skip_exit_code when it runs alone,
/// else warns. The caller returns from the test case after it.
inline void skip(const std::string& reason) {
    if (running_alone()) {
        std::cout << "skipped: " << reason << std::endl;
        std::fflush(nullptr);
        std::exit(skip_exit_code);
    }
    WARN("skipped: " << reason);
}

}  // namespace bounce::test
