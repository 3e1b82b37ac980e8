#pragma once
/// \file context.hpp
/// A headless OpenGL 4.5 core context through EGL, for programs and tests without a window.
///
/// Nothing else in the adapter needs this class: every object and pass works in whatever
/// context is current on the calling thread, so a renderer with its own context (GLFW, Qt,
/// its own EGL) makes it current and uses the adapter directly.

#include <bounce/gl/errors.hpp>

#include <string>

namespace bounce::gl {

/// Which EGL platform `context` may use.
enum class egl_platform {
    any,          ///< the device platform, then Mesa's surfaceless platform
    device,       ///< EGL_EXT_platform_device: each enumerated device in turn (NVIDIA, Mesa)
    surfaceless,  ///< EGL_MESA_platform_surfaceless (Mesa, including llvmpipe)
};

struct context_options {
    egl_platform platform = egl_platform::any;
    int major = 4;  ///< OpenGL core version to ask for; at least 4.5, what the adapter uses
    int minor = 5;
};

/// Owns an EGL display connection's OpenGL core context without any surface, current on
/// the thread that created it. Move-only; the destructor releases it (if current on this
/// thread) and destroys it. The EGL display is left initialized, because EGL displays are
/// per process and another context may be using the same one.
class context {
public:
    /// Creates the context and makes it current. Throws gl_error listing, for each
    /// platform and device tried, what was missing (no EGL client extensions, no such
    /// platform, no desktop OpenGL, no OpenGL 4.5 core, no surfaceless contexts);
    /// parameter_error when the requested version is below 4.5.
    explicit context(const context_options& options = {});
    ~context();
    context(context&& other) noexcept;
    context& operator=(context&& other) noexcept;
    context(const context&) = delete;
    context& operator=(const context&) = delete;

    /// Makes this context current on the calling thread. Throws gl_error on failure.
    void make_current() const;
    /// Whether this context is current on the calling thread.
    bool is_current() const noexcept;
    /// Where it came from, e.g. "EGL_MESA_platform_surfaceless" or
    /// "EGL_EXT_platform_device, device 0 (/dev/dri/renderD128)".
    const std::string& platform() const noexcept { return platform_; }
    /// GL_RENDERER and GL_VERSION of the context (it must be current).
    std::string renderer() const;
    std::string version() const;

private:
    void release() noexcept;

    void* display_ = nullptr;  // EGLDisplay
    void* context_ = nullptr;  // EGLContext
    std::string platform_;
};

}  // namespace bounce::gl
