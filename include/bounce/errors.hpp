#pragma once
/// \file errors.hpp
/// Typed exceptions of the core. Each names the parameter or buffer at fault, so a
/// caller can report it without guessing; adapters derive their own (`io::scene_error`,
/// `gl::gl_error`, `embree::embree_error`) from `bounce::error`.

#include <stdexcept>
#include <string>

namespace bounce {

/// Base of every exception bounce throws.
struct error : std::runtime_error {
    using std::runtime_error::runtime_error;
};

/// A parameter outside its domain (a <= 0, zero-sized image, NaN in an input buffer).
/// `parameter()` names it as the API spells it.
struct parameter_error : error {
    parameter_error(std::string parameter, const std::string& what)
        : error("bounce: parameter '" + parameter + "': " + what), name_(std::move(parameter)) {}
    const std::string& parameter() const noexcept { return name_; }

private:
    std::string name_;
};

/// Throws `parameter_error` unless `ok`.
inline void require(bool ok, const char* parameter, const char* what) {
    if (!ok) throw parameter_error(parameter, what);
}

}  // namespace bounce
