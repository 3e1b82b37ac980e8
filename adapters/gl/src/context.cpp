// Headless OpenGL 4.5 core through EGL: the device platform (each enumerated device), then
// Mesa's surfaceless platform; the first that yields a context wins.
#include <bounce/gl/context.hpp>

#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)
#include <EGL/egl.h>
#include <EGL/eglext.h>

#include <cstring>
#include <string_view>
#include <type_traits>
#include <utility>
#include <vector>

namespace bounce::gl {

static_assert(std::is_same_v<EGLDisplay, void*> && std::is_same_v<EGLContext, void*>,
              "context.hpp stores EGL handles as void*");

namespace {

std::string egl_error_name(EGLint e) {
    switch (e) {
        case EGL_SUCCESS: return "EGL_SUCCESS";
        case EGL_NOT_INITIALIZED: return "EGL_NOT_INITIALIZED";
        case EGL_BAD_ACCESS: return "EGL_BAD_ACCESS";
        case EGL_BAD_ALLOC: return "EGL_BAD_ALLOC";
        case EGL_BAD_ATTRIBUTE: return "EGL_BAD_ATTRIBUTE";
        case EGL_BAD_CONFIG: return "EGL_BAD_CONFIG";
        case EGL_BAD_CONTEXT: return "EGL_BAD_CONTEXT";
        case EGL_BAD_CURRENT_SURFACE: return "EGL_BAD_CURRENT_SURFACE";
        case EGL_BAD_DISPLAY: return "EGL_BAD_DISPLAY";
        case EGL_BAD_MATCH: return "EGL_BAD_MATCH";
        case EGL_BAD_NATIVE_PIXMAP: return "EGL_BAD_NATIVE_PIXMAP";
        case EGL_BAD_NATIVE_WINDOW: return "EGL_BAD_NATIVE_WINDOW";
        case EGL_BAD_PARAMETER: return "EGL_BAD_PARAMETER";
        case EGL_BAD_SURFACE: return "EGL_BAD_SURFACE";
        case EGL_CONTEXT_LOST: return "EGL_CONTEXT_LOST";
        default: return "EGL error " + std::to_string(e);
    }
}

bool has_extension(const char* list, std::string_view name) {
    if (!list) return false;
    for (std::string_view s(list); !s.empty();) {
        const auto end = s.find(' ');
        if (s.substr(0, end) == name) return true;
        if (end == std::string_view::npos) break;
        s.remove_prefix(end + 1);
    }
    return false;
}

struct created {
    EGLDisplay display = EGL_NO_DISPLAY;
    EGLContext context = EGL_NO_CONTEXT;
};

// Initializes `display`, creates an OpenGL core context of the requested version with no
// surface and makes it current. Returns the failure reason, or "" on success.
std::string try_display(EGLDisplay display, const context_options& o, created& out) {
    if (display == EGL_NO_DISPLAY) return "eglGetPlatformDisplayEXT failed (" + egl_error_name(eglGetError()) + ")";
    EGLint major = 0, minor = 0;
    if (!eglInitialize(display, &major, &minor))
        return "eglInitialize failed (" + egl_error_name(eglGetError()) + ")";
    const char* ext = eglQueryString(display, EGL_EXTENSIONS);
    if (!has_extension(ext, "EGL_KHR_surfaceless_context"))
        return "the display lacks EGL_KHR_surfaceless_context (a context without a surface)";
    if (!(major > 1 || minor >= 5) && !has_extension(ext, "EGL_KHR_create_context"))
        return "the display has neither EGL 1.5 nor EGL_KHR_create_context (needed to ask for a core profile)";
    if (!eglBindAPI(EGL_OPENGL_API)) return "no desktop OpenGL on this display (eglBindAPI(EGL_OPENGL_API) failed)";

    // Any config that renders desktop GL; surfaceless rendering needs no surface type.
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    EGLConfig config = nullptr;
    EGLint count = 0;
    if (!eglChooseConfig(display, config_attribs, &config, 1, &count) || count < 1) {
        if (!has_extension(ext, "EGL_KHR_no_config_context")) return "no EGL config renders desktop OpenGL";
        config = EGL_NO_CONFIG_KHR;
    }
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, o.major, EGL_CONTEXT_MINOR_VERSION, o.minor,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    const EGLContext ctx = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
    if (ctx == EGL_NO_CONTEXT)
        return "no OpenGL " + std::to_string(o.major) + "." + std::to_string(o.minor) +
               " core context (eglCreateContext: " + egl_error_name(eglGetError()) + ")";
    if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, ctx)) {
        const auto e = eglGetError();
        eglDestroyContext(display, ctx);
        return "eglMakeCurrent without a surface failed (" + egl_error_name(e) + ")";
    }
    GLint gl_major = 0, gl_minor = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &gl_major);
    glGetIntegerv(GL_MINOR_VERSION, &gl_minor);
    if (gl_major * 100 + gl_minor < o.major * 100 + o.minor) {
        eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
        eglDestroyContext(display, ctx);
        return "the context reports OpenGL " + std::to_string(gl_major) + "." + std::to_string(gl_minor);
    }
    out = {display, ctx};
    return "";
}

}  // namespace

context::context(const context_options& o) {
    if (o.major * 100 + o.minor < 405)
        throw parameter_error("context_options::major/minor", "the GL adapter needs OpenGL 4.5 or later");
    // Client extensions (EGL_EXT_client_extensions) say which platforms exist before any
    // display is opened; without them there is no headless platform to ask for.
    const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
    if (!client)
        throw gl_error("bounce::gl: no headless OpenGL context: this EGL has no client extensions "
                       "(EGL_EXT_client_extensions), so neither EGL_EXT_platform_device nor "
                       "EGL_MESA_platform_surfaceless can be used");
    const auto get_platform_display =
        reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(eglGetProcAddress("eglGetPlatformDisplayEXT"));
    std::vector<std::string> failures;
    created made;

    const bool want_device = o.platform != egl_platform::surfaceless;
    const bool want_surfaceless = o.platform != egl_platform::device;
    if (want_device) {
        const auto query_devices = reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
        const auto query_string =
            reinterpret_cast<PFNEGLQUERYDEVICESTRINGEXTPROC>(eglGetProcAddress("eglQueryDeviceStringEXT"));
        if (!has_extension(client, "EGL_EXT_platform_device") || !has_extension(client, "EGL_EXT_device_enumeration") ||
            !get_platform_display || !query_devices) {
            failures.push_back("EGL_EXT_platform_device: not offered by this EGL");
        } else {
            EGLint n = 0;
            std::vector<EGLDeviceEXT> devices;
            if (query_devices(0, nullptr, &n) && n > 0) {
                devices.resize(std::size_t(n));
                query_devices(n, devices.data(), &n);
                devices.resize(std::size_t(n));
            }
            if (devices.empty()) failures.push_back("EGL_EXT_platform_device: no devices");
            for (std::size_t i = 0; i < devices.size() && !made.context; ++i) {
                std::string name = "EGL_EXT_platform_device, device " + std::to_string(i);
                const char* dev_ext = query_string ? query_string(devices[i], EGL_EXTENSIONS) : nullptr;
                if (has_extension(dev_ext, "EGL_EXT_device_drm")) {
                    if (const char* file = query_string(devices[i], EGL_DRM_DEVICE_FILE_EXT)) name += std::string(" (") + file + ")";
                } else if (has_extension(dev_ext, "EGL_MESA_device_software")) {
                    name += " (software)";
                }
                const auto why =
                    try_display(get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr), o, made);
                if (why.empty()) platform_ = name;
                else failures.push_back(name + ": " + why);
            }
        }
    }
    if (want_surfaceless && !made.context) {
        if (!has_extension(client, "EGL_MESA_platform_surfaceless") || !get_platform_display) {
            failures.push_back("EGL_MESA_platform_surfaceless: not offered by this EGL");
        } else {
            const auto why = try_display(
                get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr), o, made);
            if (why.empty()) platform_ = "EGL_MESA_platform_surfaceless";
            else failures.push_back("EGL_MESA_platform_surfaceless: " + why);
        }
    }
    if (!made.context) {
        std::string msg = "bounce::gl: no headless OpenGL " + std::to_string(o.major) + "." + std::to_string(o.minor) +
                          " core context:";
        for (const auto& f : failures) msg += "\n  - " + f;
        throw gl_error(msg);
    }
    display_ = made.display;
    context_ = made.context;
}

context::~context() { release(); }

void context::release() noexcept {
    if (!context_) return;
    if (eglGetCurrentContext() == context_) eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    eglDestroyContext(display_, context_);
    context_ = nullptr;
    display_ = nullptr;
}

context::context(context&& other) noexcept
    : display_(std::exchange(other.display_, nullptr)), context_(std::exchange(other.context_, nullptr)),
      platform_(std::move(other.platform_)) {}

context& context::operator=(context&& other) noexcept {
    if (this != &other) {
        release();
        display_ = std::exchange(other.display_, nullptr);
        context_ = std::exchange(other.context_, nullptr);
        platform_ = std::move(other.platform_);
    }
    return *this;
}

void context::make_current() const {
    if (!context_) throw gl_error("bounce::gl: make_current on a moved-from context");
    if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
        throw gl_error("bounce::gl: eglMakeCurrent failed (" + egl_error_name(eglGetError()) + ")");
}

bool context::is_current() const noexcept { return context_ && eglGetCurrentContext() == context_; }

std::string context::renderer() const {
    const auto* s = glGetString(GL_RENDERER);
    return s ? reinterpret_cast<const char*>(s) : "";
}

std::string context::version() const {
    const auto* s = glGetString(GL_VERSION);
    return s ? reinterpret_cast<const char*>(s) : "";
}

}  // namespace bounce::gl
