#pragma once
/// \file run_program.hpp
/// How the programs end when their work throws: one line "<program>: <message>" on stderr and
/// an exit code that says whose fault it was, the same for every program.

#include <bounce/errors.hpp>

#include <fmt/core.h>

#include <exception>
#include <new>
#include <string_view>

namespace bounce::examples {

/// Returns `run()` (the program's work, after its command line is parsed), or, when it throws,
/// prints what and returns 2 for a bounce::error (input refused, an output that cannot be
/// written: a cause the message names) or 1 for anything else. Out of memory adds
/// `out_of_memory`: what to ask for instead ("choose fewer --maps or a smaller --size").
template <class Run>
int run_program(std::string_view program, Run&& run, std::string_view out_of_memory = {}) {
    try {
        return run();
    } catch (const bounce::error& e) {
        fmt::print(stderr, "{}: {}\n", program, e.what());
        return 2;
    } catch (const std::bad_alloc&) {
        fmt::print(stderr, "{}: out of memory (std::bad_alloc){}{}\n", program, out_of_memory.empty() ? "" : ": ",
                   out_of_memory);
    } catch (const std::exception& e) {
        fmt::print(stderr, "{}: {}\n", program, e.what());
    }
    return 1;
}

}  // namespace bounce::examples
