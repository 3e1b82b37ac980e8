#pragma once
/// \file objects.hpp
/// Move-only owners of OpenGL objects: shaders and programs, buffers, textures,
/// framebuffers, vertex arrays.
///
/// Each is created in, and must be destroyed in, the context current on the calling
/// thread (destroy them before the context). They use direct state access (OpenGL 4.5),
/// so creating or filling one changes no binding of the context. This header includes no
/// GL header, so it mixes with any loader a renderer uses; ids are `GLuint`s.

#include <bounce/gl/errors.hpp>

#include <cstddef>
#include <span>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

/// A GL object name (GLuint).
using object_id = unsigned int;

/// Throws gl_error naming `call` and the error if glGetError reports one (the queue is
/// drained, so an older error is reported too).
void check_error(const char* call);

/// Blocks until the current context has executed every command issued so far (glFinish):
/// a stage timing that ends without it measures only the driver's queueing.
void finish();

namespace detail {
enum class object_kind { shader, program, buffer, texture, framebuffer, vertex_array };
/// The owned name and how to delete it.
class object {
public:
    object() = default;
    object(object_kind k, object_id id) noexcept : kind_(k), id_(id) {}
    ~object();
    object(object&& o) noexcept : kind_(o.kind_), id_(o.release()) {}
    object& operator=(object&& o) noexcept;
    object(const object&) = delete;
    object& operator=(const object&) = delete;
    object_id id() const noexcept { return id_; }
    object_id release() noexcept {
        const auto i = id_;
        id_ = 0;
        return i;
    }

private:
    object_kind kind_ = object_kind::buffer;
    object_id id_ = 0;
};
}  // namespace detail

enum class shader_stage { vertex, fragment, compute };

/// A compiled shader stage.
class shader {
public:
    /// Compiles `source`. Throws shader_error with the info log and the numbered source.
    shader(shader_stage stage, std::string source);
    object_id id() const noexcept { return object_.id(); }
    shader_stage stage() const noexcept { return stage_; }
    const std::string& source() const noexcept { return source_; }

private:
    detail::object object_;
    shader_stage stage_;
    std::string source_;
};

/// A linked program. Uniforms are set with direct state access (glProgramUniform*), so
/// setting one does not bind the program.
class program {
public:
    /// Links the given stages. Throws shader_error with the log and every stage's
    /// numbered source.
    explicit program(std::span<const shader* const> stages);
    /// Compiles and links a vertex + fragment program.
    program(const std::string& vertex_source, const std::string& fragment_source);
    /// Compiles and links a compute program.
    static program compute(const std::string& source);

    object_id id() const noexcept { return object_.id(); }
    /// Uniform at `location` (as declared with layout(location = ...)).
    void set(int location, float v) const;
    void set(int location, unsigned v) const;
    void set(int location, int v) const;
    void set(int location, const glm::vec2& v) const;
    void set(int location, const glm::vec3& v) const;
    void set(int location, const glm::vec4& v) const;
    void set(int location, const glm::mat4& m) const;

private:
    program() = default;
    detail::object object_;
};

/// An immutable-size buffer (glNamedBufferStorage) whose contents can be rewritten and
/// read back.
class buffer {
public:
    /// `bytes` bytes, initialized from `data` when not null (zeros otherwise).
    explicit buffer(std::size_t bytes, const void* data = nullptr);
    template <class T>
    explicit buffer(std::span<const T> data) : buffer(data.size_bytes(), data.data()) {}

    object_id id() const noexcept { return object_.id(); }
    std::size_t size() const noexcept { return size_; }
    /// Writes `bytes` bytes at `offset`. Throws parameter_error past the end.
    void write(std::size_t offset, const void* data, std::size_t bytes);
    /// Reads `bytes` bytes at `offset` (waits for the GPU). Throws parameter_error past the end.
    void read(std::size_t offset, void* data, std::size_t bytes) const;
    /// The whole buffer as elements of T (size must be a multiple of sizeof(T)).
    template <class T>
    std::vector<T> read_all() const {
        require(size_ % sizeof(T) == 0, "T", "buffer size is not a multiple of the element size");
        std::vector<T> v(size_ / sizeof(T));
        read(0, v.data(), size_);
        return v;
    }

private:
    detail::object object_;
    std::size_t size_ = 0;
};

enum class texel_format {
    rgba32f,  ///< four floats (GL_RGBA32F)
    rgb32f,   ///< three floats (GL_RGB32F); read back and sampled with alpha 1
    r32f,     ///< one float (GL_R32F)
    rgba8,    ///< four unsigned normalized bytes (GL_RGBA8)
    depth32f  ///< float depth (GL_DEPTH_COMPONENT32F)
};

/// A 2D texture with immutable storage (one mip level), nearest filtering, clamped.
class texture {
public:
    /// Throws parameter_error for a zero size and gl_error beyond GL_MAX_TEXTURE_SIZE.
    texture(texel_format format, std::size_t width, std::size_t height);
    object_id id() const noexcept { return object_.id(); }
    texel_format format() const noexcept { return format_; }
    std::size_t width() const noexcept { return width_; }
    std::size_t height() const noexcept { return height_; }
    /// The texels as floats, in GL order (row 0 at the bottom), 4 per texel for rgba
    /// formats, 1 for r32f and depth32f. Pixel-pack state is set for the read and restored.
    std::vector<float> read_floats() const;

private:
    detail::object object_;
    texel_format format_;
    std::size_t width_, height_;
};

/// A texture by name, owned by whoever made it (a renderer's own G-buffer target, or a
/// bounce::gl::texture): passes read it and never delete it. It must outlive the use.
struct texture_ref {
    object_id id = 0;
    texel_format format = texel_format::rgba32f;
    std::size_t width = 0, height = 0;

    texture_ref() = default;
    /// A bounce texture.
    texture_ref(const texture& t) noexcept  // NOLINT: implicit, so bounce textures pass as they are
        : id(t.id()), format(t.format()), width(t.width()), height(t.height()) {}
    /// A texture the caller made: its size and internal format are read from GL (a context
    /// must be current). Throws parameter_error naming `name` when `id` is not a texture
    /// name, has no storage, or its format is none of texel_format's.
    static texture_ref of(object_id id, const char* name = "texture");
    /// The texels as floats, in GL order, as texture::read_floats.
    std::vector<float> read_floats() const;
};

/// A framebuffer object with textures attached.
class framebuffer {
public:
    framebuffer();
    object_id id() const noexcept { return object_.id(); }
    /// Attaches `t` as colour attachment `index`.
    void attach_color(unsigned index, const texture& t);
    /// Attaches a depth32f texture as the depth attachment.
    void attach_depth(const texture& t);
    /// Routes fragment outputs 0..count-1 to colour attachments 0..count-1.
    void set_draw_buffers(unsigned count);
    /// Throws gl_error naming the incompleteness status unless the framebuffer is complete.
    void check_complete() const;

private:
    detail::object object_;
};

/// A vertex array object.
class vertex_array {
public:
    vertex_array();
    object_id id() const noexcept { return object_.id(); }

private:
    detail::object object_;
};

}  // namespace bounce::gl
