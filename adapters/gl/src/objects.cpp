// The GL object owners: creation with direct state access, errors with logs and numbered
// sources.
#include <bounce/gl/objects.hpp>

#include "saved_state.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cstdio>
#include <type_traits>

namespace bounce::gl {

static_assert(std::is_same_v<object_id, GLuint>, "object_id must be GLuint");

namespace {

const char* error_name(GLenum e) {
    switch (e) {
        case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
        case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
        case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
        case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
        case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
        case GL_STACK_UNDERFLOW: return "GL_STACK_UNDERFLOW";
        case GL_STACK_OVERFLOW: return "GL_STACK_OVERFLOW";
        default: return "unknown GL error";
    }
}

const char* stage_name(shader_stage s) {
    switch (s) {
        case shader_stage::vertex: return "vertex";
        case shader_stage::fragment: return "fragment";
        case shader_stage::compute: return "compute";
    }
    return "?";
}

GLenum stage_enum(shader_stage s) {
    switch (s) {
        case shader_stage::vertex: return GL_VERTEX_SHADER;
        case shader_stage::fragment: return GL_FRAGMENT_SHADER;
        case shader_stage::compute: return GL_COMPUTE_SHADER;
    }
    return GL_NONE;
}

// The source with 1-based line numbers, as the drivers' logs count them ("0:12(3)").
std::string numbered(const std::string& source) {
    std::string out;
    std::size_t line = 1, start = 0;
    while (start < source.size()) {
        auto end = source.find('\n', start);
        if (end == std::string::npos) end = source.size();
        char num[24];
        std::snprintf(num, sizeof num, "%4zu| ", line++);
        out += num;
        out.append(source, start, end - start);
        out += '\n';
        start = end + 1;
    }
    return out;
}

void require_context() {
    // Without a current context every GL call is a silent no-op; say so instead.
    if (!glGetString(GL_VERSION)) throw gl_error("bounce::gl: no OpenGL context is current on this thread");
}

}  // namespace

void check_error(const char* call) {
    GLenum first = GL_NO_ERROR;
    for (GLenum e; (e = glGetError()) != GL_NO_ERROR;)
        if (first == GL_NO_ERROR) first = e;
    if (first != GL_NO_ERROR) throw gl_error(std::string("bounce::gl: ") + call + " failed: " + error_name(first));
}

void finish() {
    glFinish();
    check_error("glFinish");
}

namespace detail {

object::~object() {
    if (!id_) return;
    switch (kind_) {
        case object_kind::shader: glDeleteShader(id_); break;
        case object_kind::program: glDeleteProgram(id_); break;
        case object_kind::buffer: glDeleteBuffers(1, &id_); break;
        case object_kind::texture: glDeleteTextures(1, &id_); break;
        case object_kind::framebuffer: glDeleteFramebuffers(1, &id_); break;
        case object_kind::vertex_array: glDeleteVertexArrays(1, &id_); break;
    }
}

object& object::operator=(object&& o) noexcept {
    if (this != &o) {
        object tmp(std::move(*this));  // deletes the old name
        kind_ = o.kind_;
        id_ = o.release();
    }
    return *this;
}

}  // namespace detail

// ---- shaders and programs ---------------------------------------------------------------

shader::shader(shader_stage stage, std::string source) : stage_(stage), source_(std::move(source)) {
    require_context();
    object_ = detail::object(detail::object_kind::shader, glCreateShader(stage_enum(stage)));
    if (!object_.id()) throw gl_error(std::string("bounce::gl: glCreateShader(") + stage_name(stage) + ") failed");
    const char* text = source_.c_str();
    const GLint length = GLint(source_.size());
    glShaderSource(id(), 1, &text, &length);
    glCompileShader(id());
    GLint ok = GL_FALSE, log_length = 0;
    glGetShaderiv(id(), GL_COMPILE_STATUS, &ok);
    if (ok) return;
    glGetShaderiv(id(), GL_INFO_LOG_LENGTH, &log_length);
    std::string log(std::size_t(std::max(log_length, 1)), '\0');
    glGetShaderInfoLog(id(), GLsizei(log.size()), nullptr, log.data());
    log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
    throw shader_error(std::string("bounce::gl: ") + stage_name(stage) + " shader failed to compile:\n" + log +
                           "\n--- " + stage_name(stage) + " shader source ---\n" + numbered(source_),
                       log, source_);
}

program::program(std::span<const shader* const> stages) {
    require_context();
    object_ = detail::object(detail::object_kind::program, glCreateProgram());
    for (const shader* s : stages) glAttachShader(id(), s->id());
    glLinkProgram(id());
    for (const shader* s : stages) glDetachShader(id(), s->id());
    GLint ok = GL_FALSE, log_length = 0;
    glGetProgramiv(id(), GL_LINK_STATUS, &ok);
    if (ok) return;
    glGetProgramiv(id(), GL_INFO_LOG_LENGTH, &log_length);
    std::string log(std::size_t(std::max(log_length, 1)), '\0');
    glGetProgramInfoLog(id(), GLsizei(log.size()), nullptr, log.data());
    log.resize(log.find('\0') == std::string::npos ? log.size() : log.find('\0'));
    std::string sources, all;
    for (const shader* s : stages) {
        sources += std::string("--- ") + stage_name(s->stage()) + " shader source ---\n" + numbered(s->source());
        all += s->source();
    }
    throw shader_error("bounce::gl: program failed to link:\n" + log + "\n" + sources, log, all);
}

program::program(const std::string& vertex_source, const std::string& fragment_source) {
    const shader vs(shader_stage::vertex, vertex_source), fs(shader_stage::fragment, fragment_source);
    const shader* stages[] = {&vs, &fs};
    *this = program(std::span<const shader* const>(stages));
}

program program::compute(const std::string& source) {
    const shader cs(shader_stage::compute, source);
    const shader* stages[] = {&cs};
    return program(std::span<const shader* const>(stages));
}

void program::set(int location, float v) const { glProgramUniform1f(id(), location, v); }
void program::set(int location, unsigned v) const { glProgramUniform1ui(id(), location, v); }
void program::set(int location, int v) const { glProgramUniform1i(id(), location, v); }
void program::set(int location, const glm::vec2& v) const { glProgramUniform2fv(id(), location, 1, glm::value_ptr(v)); }
void program::set(int location, const glm::vec3& v) const { glProgramUniform3fv(id(), location, 1, glm::value_ptr(v)); }
void program::set(int location, const glm::vec4& v) const { glProgramUniform4fv(id(), location, 1, glm::value_ptr(v)); }
void program::set(int location, const glm::mat4& m) const {
    glProgramUniformMatrix4fv(id(), location, 1, GL_FALSE, glm::value_ptr(m));
}

// ---- buffers ----------------------------------------------------------------------------

buffer::buffer(std::size_t bytes, const void* data) : size_(bytes) {
    require_context();
    require(bytes > 0, "bytes", "a GL buffer cannot be empty");
    GLuint name = 0;
    glCreateBuffers(1, &name);
    object_ = detail::object(detail::object_kind::buffer, name);
    // Zero-fill rather than leave undefined contents when no data is given.
    std::vector<unsigned char> zeros;
    if (!data) zeros.assign(bytes, 0);
    glNamedBufferStorage(name, GLsizeiptr(bytes), data ? data : zeros.data(), GL_DYNAMIC_STORAGE_BIT);
    check_error("glNamedBufferStorage");
}

void buffer::write(std::size_t offset, const void* data, std::size_t bytes) {
    require(offset <= size_ && bytes <= size_ - offset, "bytes", "write past the end of the buffer");
    if (bytes) glNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
}

void buffer::read(std::size_t offset, void* data, std::size_t bytes) const {
    require(offset <= size_ && bytes <= size_ - offset, "bytes", "read past the end of the buffer");
    // Shader writes through storage blocks must be made visible to buffer reads.
    glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);
    if (bytes) glGetNamedBufferSubData(id(), GLintptr(offset), GLsizeiptr(bytes), data);
    check_error("glGetNamedBufferSubData");
}

// ---- textures, framebuffers, vertex arrays ---------------------------------------------

namespace {
GLenum internal_format(texel_format f) {
    switch (f) {
        case texel_format::rgba32f: return GL_RGBA32F;
        case texel_format::rgb32f: return GL_RGB32F;
        case texel_format::r32f: return GL_R32F;
        case texel_format::rgba8: return GL_RGBA8;
        case texel_format::depth32f: return GL_DEPTH_COMPONENT32F;
    }
    return GL_NONE;
}
}  // namespace

texture::texture(texel_format format, std::size_t width, std::size_t height)
    : format_(format), width_(width), height_(height) {
    require_context();
    require(width > 0 && height > 0, "width/height", "a texture must have a positive size");
    GLint max_size = 0;
    glGetIntegerv(GL_MAX_TEXTURE_SIZE, &max_size);
    if (width > std::size_t(max_size) || height > std::size_t(max_size))
        throw gl_error("bounce::gl: texture of " + std::to_string(width) + " x " + std::to_string(height) +
                       " exceeds GL_MAX_TEXTURE_SIZE = " + std::to_string(max_size));
    GLuint name = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &name);
    object_ = detail::object(detail::object_kind::texture, name);
    glTextureStorage2D(name, 1, internal_format(format), GLsizei(width), GLsizei(height));
    glTextureParameteri(name, GL_TEXTURE_MIN_FILTER, GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
    glTextureParameteri(name, GL_TEXTURE_WRAP_S, GL_CLAMP_TO_EDGE);
    glTextureParameteri(name, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
    check_error("glTextureStorage2D");
}

std::vector<float> texture::read_floats() const { return texture_ref(*this).read_floats(); }

std::vector<float> texture_ref::read_floats() const {
    const bool single = format == texel_format::r32f || format == texel_format::depth32f;
    const GLenum fmt = format == texel_format::depth32f ? GL_DEPTH_COMPONENT : single ? GL_RED : GL_RGBA;
    std::vector<float> texels(width * height * (single ? 1 : 4));
    const detail::pack_state pack;
    glGetTextureImage(id, 0, fmt, GL_FLOAT, GLsizei(texels.size() * sizeof(float)), texels.data());
    check_error("glGetTextureImage");
    return texels;
}

texture_ref texture_ref::of(object_id id, const char* name) {
    require_context();
    if (!glIsTexture(id)) throw parameter_error(name, "is not a texture name");
    GLint w = 0, h = 0, internal = 0;
    glGetTextureLevelParameteriv(id, 0, GL_TEXTURE_WIDTH, &w);
    glGetTextureLevelParameteriv(id, 0, GL_TEXTURE_HEIGHT, &h);
    glGetTextureLevelParameteriv(id, 0, GL_TEXTURE_INTERNAL_FORMAT, &internal);
    check_error("glGetTextureLevelParameteriv");
    texture_ref r;
    r.id = id;
    r.width = std::size_t(std::max(w, 0));
    r.height = std::size_t(std::max(h, 0));
    switch (internal) {
        case GL_RGBA32F: r.format = texel_format::rgba32f; break;
        case GL_RGB32F: r.format = texel_format::rgb32f; break;
        case GL_R32F: r.format = texel_format::r32f; break;
        case GL_RGBA8: r.format = texel_format::rgba8; break;
        case GL_DEPTH_COMPONENT32F: r.format = texel_format::depth32f; break;
        default: throw parameter_error(name, "has an internal format bounce does not read (RGBA32F, RGB32F, R32F, RGBA8, DEPTH32F)");
    }
    if (r.width == 0 || r.height == 0) throw parameter_error(name, "has no storage (zero size)");
    return r;
}

framebuffer::framebuffer() {
    require_context();
    GLuint name = 0;
    glCreateFramebuffers(1, &name);
    object_ = detail::object(detail::object_kind::framebuffer, name);
}

void framebuffer::attach_color(unsigned index, const texture& t) {
    glNamedFramebufferTexture(id(), GL_COLOR_ATTACHMENT0 + index, t.id(), 0);
    check_error("glNamedFramebufferTexture");
}

void framebuffer::attach_depth(const texture& t) {
    require(t.format() == texel_format::depth32f, "t", "the depth attachment must be a depth32f texture");
    glNamedFramebufferTexture(id(), GL_DEPTH_ATTACHMENT, t.id(), 0);
    check_error("glNamedFramebufferTexture");
}

void framebuffer::set_draw_buffers(unsigned count) {
    std::vector<GLenum> buffers(count);
    for (unsigned i = 0; i < count; ++i) buffers[i] = GL_COLOR_ATTACHMENT0 + i;
    glNamedFramebufferDrawBuffers(id(), GLsizei(count), buffers.data());
    check_error("glNamedFramebufferDrawBuffers");
}

void framebuffer::check_complete() const {
    const GLenum status = glCheckNamedFramebufferStatus(id(), GL_DRAW_FRAMEBUFFER);
    if (status == GL_FRAMEBUFFER_COMPLETE) return;
    const char* name = status == GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT          ? "GL_FRAMEBUFFER_INCOMPLETE_ATTACHMENT"
                       : status == GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT ? "GL_FRAMEBUFFER_INCOMPLETE_MISSING_ATTACHMENT"
                       : status == GL_FRAMEBUFFER_UNSUPPORTED                   ? "GL_FRAMEBUFFER_UNSUPPORTED"
                       : status == GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER        ? "GL_FRAMEBUFFER_INCOMPLETE_DRAW_BUFFER"
                                                                                : "incomplete";
    throw gl_error(std::string("bounce::gl: framebuffer is not complete: ") + name);
}

vertex_array::vertex_array() {
    require_context();
    GLuint name = 0;
    glCreateVertexArrays(1, &name);
    object_ = detail::object(detail::object_kind::vertex_array, name);
}

}  // namespace bounce::gl
