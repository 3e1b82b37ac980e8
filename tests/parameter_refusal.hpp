#pragma once
// The message of the parameter_error a call throws, or "" when it throws none: for tests that
// check what a refusal says (the option or field it names, the range it wants).
#include <bounce/errors.hpp>

#include <string>

namespace bounce::test {

template <class F>
std::string refusal_message(F&& f) {
    try {
        f();
    } catch (const parameter_error& e) {
        return e.what();
    }
    return {};
}

}  // namespace bounce::test
