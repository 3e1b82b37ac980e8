#pragma once
/// \file errors.hpp
/// Exceptions of the GL adapter.

#include <bounce/errors.hpp>

#include <string>

namespace bounce::gl {

/// Something OpenGL or EGL could not do: no headless context, an unsupported feature,
/// a GL error after a call. The message names the call and what was missing.
struct gl_error : bounce::error {
    using bounce::error::error;
};

/// A shader that did not compile or a program that did not link. `what()` holds the
/// driver's info log followed by every source involved, with line numbers, so the line
/// the log points at can be read off the message.
struct shader_error : gl_error {
    shader_error(const std::string& what, std::string log, std::string source)
        : gl_error(what), log_(std::move(log)), source_(std::move(source)) {}
    /// The driver's info log.
    const std::string& log() const noexcept { return log_; }
    /// The source(s) as given (without line numbers).
    const std::string& source() const noexcept { return source_; }

private:
    std::string log_, source_;
};

}  // namespace bounce::gl
