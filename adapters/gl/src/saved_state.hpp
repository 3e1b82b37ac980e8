#pragma once
// Save-and-restore of the context state a pass changes, so the adapter works inside a
// renderer's own context without disturbing it (private to the adapter).

#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)

#include <array>
#include <initializer_list>
#include <stdexcept>
#include <vector>

namespace bounce::gl::detail {

/// Pixel-pack state set to tightly packed client memory (no pack buffer) for reads.
class pack_state {
public:
    pack_state() {
        glGetIntegerv(GL_PIXEL_PACK_BUFFER_BINDING, &buffer_);
        for (std::size_t i = 0; i < names_.size(); ++i) glGetIntegerv(names_[i], &values_[i]);
        glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
        for (std::size_t i = 0; i < names_.size(); ++i) glPixelStorei(names_[i], names_[i] == GL_PACK_ALIGNMENT ? 4 : 0);
    }
    ~pack_state() {
        for (std::size_t i = 0; i < names_.size(); ++i) glPixelStorei(names_[i], values_[i]);
        glBindBuffer(GL_PIXEL_PACK_BUFFER, GLuint(buffer_));
    }
    pack_state(const pack_state&) = delete;
    pack_state& operator=(const pack_state&) = delete;

private:
    static constexpr std::array<GLenum, 8> names_ = {GL_PACK_ALIGNMENT,  GL_PACK_ROW_LENGTH,  GL_PACK_SKIP_ROWS,
                                                     GL_PACK_SKIP_PIXELS, GL_PACK_IMAGE_HEIGHT, GL_PACK_SKIP_IMAGES,
                                                     GL_PACK_SWAP_BYTES, GL_PACK_LSB_FIRST};
    GLint buffer_ = 0;
    std::array<GLint, 8> values_{};
};

/// The program in use and one indexed shader-storage binding (with its range).
class program_and_storage_state {
public:
    explicit program_and_storage_state(std::initializer_list<GLuint> storage_indices) {
        if (storage_indices.size() > max_bindings)
            throw std::logic_error("program_and_storage_state: more storage bindings than it can save");
        glGetIntegerv(GL_CURRENT_PROGRAM, &program_);
        glGetIntegerv(GL_SHADER_STORAGE_BUFFER_BINDING, &generic_);
        for (GLuint i : storage_indices) {
            binding b{i};
            glGetIntegeri_v(GL_SHADER_STORAGE_BUFFER_BINDING, i, &b.buffer);
            glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_START, i, &b.start);
            glGetInteger64i_v(GL_SHADER_STORAGE_BUFFER_SIZE, i, &b.size);
            bindings_[count_++] = b;
        }
    }
    ~program_and_storage_state() {
        for (std::size_t k = 0; k < count_; ++k) {
            const auto& b = bindings_[k];
            if (b.size > 0) glBindBufferRange(GL_SHADER_STORAGE_BUFFER, b.index, GLuint(b.buffer), b.start, b.size);
            else glBindBufferBase(GL_SHADER_STORAGE_BUFFER, b.index, GLuint(b.buffer));
        }
        glBindBuffer(GL_SHADER_STORAGE_BUFFER, GLuint(generic_));
        glUseProgram(GLuint(program_));
    }
    program_and_storage_state(const program_and_storage_state&) = delete;
    program_and_storage_state& operator=(const program_and_storage_state&) = delete;

private:
    struct binding {
        GLuint index = 0;
        GLint buffer = 0;
        GLint64 start = 0, size = 0;
    };
    static constexpr std::size_t max_bindings = 8;
    GLint program_ = 0, generic_ = 0;
    std::array<binding, max_bindings> bindings_{};
    std::size_t count_ = 0;
};

/// Fixed-function state of a raster pass: framebuffers, viewport, vertex array, the
/// capabilities that would change what a pass draws (set to the pass's needs: depth test
/// on with GL_LESS and writes, everything else off), masks, polygon mode, clip control.
class raster_state {
public:
    raster_state() {
        glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &draw_fb_);
        glGetIntegerv(GL_READ_FRAMEBUFFER_BINDING, &read_fb_);
        glGetIntegerv(GL_VIEWPORT, viewport_.data());
        glGetIntegerv(GL_VERTEX_ARRAY_BINDING, &vao_);
        for (std::size_t i = 0; i < caps_.size(); ++i) enabled_[i] = glIsEnabled(caps_[i]);
        glGetIntegerv(GL_DEPTH_FUNC, &depth_func_);
        glGetBooleanv(GL_DEPTH_WRITEMASK, &depth_mask_);
        glGetDoublev(GL_DEPTH_RANGE, depth_range_.data());
        glGetBooleanv(GL_COLOR_WRITEMASK, color_mask_.data());
        glGetIntegerv(GL_POLYGON_MODE, polygon_mode_.data());
        glGetIntegerv(GL_CLIP_ORIGIN, &clip_origin_);
        glGetIntegerv(GL_CLIP_DEPTH_MODE, &clip_depth_);

        for (std::size_t i = 0; i < caps_.size(); ++i)
            if (caps_[i] == GL_DEPTH_TEST) glEnable(caps_[i]);
            else glDisable(caps_[i]);
        glDepthFunc(GL_LESS);
        glDepthMask(GL_TRUE);
        glDepthRange(0.0, 1.0);
        glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
        glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
        glClipControl(GL_LOWER_LEFT, GL_NEGATIVE_ONE_TO_ONE);
    }
    ~raster_state() {
        glClipControl(GLenum(clip_origin_), GLenum(clip_depth_));
        glPolygonMode(GL_FRONT_AND_BACK, GLenum(polygon_mode_[0]));
        glColorMask(color_mask_[0], color_mask_[1], color_mask_[2], color_mask_[3]);
        glDepthRange(depth_range_[0], depth_range_[1]);
        glDepthMask(depth_mask_);
        glDepthFunc(GLenum(depth_func_));
        for (std::size_t i = 0; i < caps_.size(); ++i)
            if (enabled_[i]) glEnable(caps_[i]);
            else glDisable(caps_[i]);
        glBindVertexArray(GLuint(vao_));
        glViewport(viewport_[0], viewport_[1], viewport_[2], viewport_[3]);
        glBindFramebuffer(GL_READ_FRAMEBUFFER, GLuint(read_fb_));
        glBindFramebuffer(GL_DRAW_FRAMEBUFFER, GLuint(draw_fb_));
    }
    raster_state(const raster_state&) = delete;
    raster_state& operator=(const raster_state&) = delete;

private:
    static constexpr std::array<GLenum, 13> caps_ = {
        GL_DEPTH_TEST,      GL_BLEND,           GL_CULL_FACE,          GL_SCISSOR_TEST,
        GL_STENCIL_TEST,    GL_RASTERIZER_DISCARD, GL_DEPTH_CLAMP,     GL_POLYGON_OFFSET_FILL,
        GL_SAMPLE_ALPHA_TO_COVERAGE, GL_SAMPLE_COVERAGE, GL_COLOR_LOGIC_OP, GL_PRIMITIVE_RESTART,
        GL_PRIMITIVE_RESTART_FIXED_INDEX};
    GLint draw_fb_ = 0, read_fb_ = 0, vao_ = 0, depth_func_ = GL_LESS, clip_origin_ = GL_LOWER_LEFT,
          clip_depth_ = GL_NEGATIVE_ONE_TO_ONE;
    std::array<GLint, 4> viewport_{};
    std::array<GLboolean, 13> enabled_{};
    GLboolean depth_mask_ = GL_TRUE;
    std::array<GLdouble, 2> depth_range_{0, 1};
    std::array<GLboolean, 4> color_mask_{GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE};
    std::array<GLint, 2> polygon_mode_{GL_FILL, GL_FILL};
};

/// The scissor box, which raster_state leaves alone (it saves the scissor test's enable,
/// not the rectangle): saved as found, restored on destruction; nothing is set here.
class scissor_box_state {
public:
    scissor_box_state() { glGetIntegerv(GL_SCISSOR_BOX, box_.data()); }
    ~scissor_box_state() { glScissor(box_[0], box_[1], box_[2], box_[3]); }
    scissor_box_state(const scissor_box_state&) = delete;
    scissor_box_state& operator=(const scissor_box_state&) = delete;

private:
    std::array<GLint, 4> box_{};
};

/// Pixel-unpack state set to tightly packed client memory (no unpack buffer) for uploads.
class unpack_state {
public:
    unpack_state() {
        glGetIntegerv(GL_PIXEL_UNPACK_BUFFER_BINDING, &buffer_);
        for (std::size_t i = 0; i < names_.size(); ++i) glGetIntegerv(names_[i], &values_[i]);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
        for (std::size_t i = 0; i < names_.size(); ++i) glPixelStorei(names_[i], names_[i] == GL_UNPACK_ALIGNMENT ? 4 : 0);
    }
    ~unpack_state() {
        for (std::size_t i = 0; i < names_.size(); ++i) glPixelStorei(names_[i], values_[i]);
        glBindBuffer(GL_PIXEL_UNPACK_BUFFER, GLuint(buffer_));
    }
    unpack_state(const unpack_state&) = delete;
    unpack_state& operator=(const unpack_state&) = delete;

private:
    static constexpr std::array<GLenum, 8> names_ = {GL_UNPACK_ALIGNMENT,  GL_UNPACK_ROW_LENGTH,  GL_UNPACK_SKIP_ROWS,
                                                     GL_UNPACK_SKIP_PIXELS, GL_UNPACK_IMAGE_HEIGHT, GL_UNPACK_SKIP_IMAGES,
                                                     GL_UNPACK_SWAP_BYTES, GL_UNPACK_LSB_FIRST};
    GLint buffer_ = 0;
    std::array<GLint, 8> values_{};
};

/// What raster_state leaves alone and blending, shadow and cube-map passes change: blend
/// equations and factors, dithering, polygon-offset factor and units, seamless cube-map
/// filtering. Saved as found, restored on destruction; nothing is set here.
class blend_offset_state {
public:
    blend_offset_state() {
        glGetIntegerv(GL_BLEND_EQUATION_RGB, &equation_rgb_);
        glGetIntegerv(GL_BLEND_EQUATION_ALPHA, &equation_alpha_);
        glGetIntegerv(GL_BLEND_SRC_RGB, &src_rgb_);
        glGetIntegerv(GL_BLEND_DST_RGB, &dst_rgb_);
        glGetIntegerv(GL_BLEND_SRC_ALPHA, &src_alpha_);
        glGetIntegerv(GL_BLEND_DST_ALPHA, &dst_alpha_);
        dither_ = glIsEnabled(GL_DITHER);
        seamless_ = glIsEnabled(GL_TEXTURE_CUBE_MAP_SEAMLESS);
        glGetFloatv(GL_POLYGON_OFFSET_FACTOR, &offset_factor_);
        glGetFloatv(GL_POLYGON_OFFSET_UNITS, &offset_units_);
    }
    ~blend_offset_state() {
        glPolygonOffset(offset_factor_, offset_units_);
        if (seamless_) glEnable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
        else glDisable(GL_TEXTURE_CUBE_MAP_SEAMLESS);
        if (dither_) glEnable(GL_DITHER);
        else glDisable(GL_DITHER);
        glBlendFuncSeparate(GLenum(src_rgb_), GLenum(dst_rgb_), GLenum(src_alpha_), GLenum(dst_alpha_));
        glBlendEquationSeparate(GLenum(equation_rgb_), GLenum(equation_alpha_));
    }
    blend_offset_state(const blend_offset_state&) = delete;
    blend_offset_state& operator=(const blend_offset_state&) = delete;

private:
    GLint equation_rgb_ = GL_FUNC_ADD, equation_alpha_ = GL_FUNC_ADD, src_rgb_ = GL_ONE, dst_rgb_ = GL_ZERO,
          src_alpha_ = GL_ONE, dst_alpha_ = GL_ZERO;
    GLboolean dither_ = GL_TRUE, seamless_ = GL_FALSE;
    GLfloat offset_factor_ = 0.f, offset_units_ = 0.f;
};

/// The 2D and cube-map texture bindings and the sampler object of texture units
/// [first, first + count), and the active unit.
class texture_unit_state {
public:
    texture_unit_state(GLuint first, GLuint count) : first_(first) {
        glGetIntegerv(GL_ACTIVE_TEXTURE, &active_);
        units_.resize(count);
        for (GLuint i = 0; i < count; ++i) {
            glActiveTexture(GL_TEXTURE0 + first + i);
            glGetIntegerv(GL_TEXTURE_BINDING_2D, &units_[i].texture_2d);
            glGetIntegerv(GL_TEXTURE_BINDING_CUBE_MAP, &units_[i].texture_cube);
            glGetIntegerv(GL_SAMPLER_BINDING, &units_[i].sampler);
        }
        glActiveTexture(GLenum(active_));
    }
    ~texture_unit_state() {
        for (GLuint i = 0; i < GLuint(units_.size()); ++i) {
            glActiveTexture(GL_TEXTURE0 + first_ + i);
            glBindTexture(GL_TEXTURE_2D, GLuint(units_[i].texture_2d));
            glBindTexture(GL_TEXTURE_CUBE_MAP, GLuint(units_[i].texture_cube));
            glBindSampler(first_ + i, GLuint(units_[i].sampler));
        }
        glActiveTexture(GLenum(active_));
    }
    texture_unit_state(const texture_unit_state&) = delete;
    texture_unit_state& operator=(const texture_unit_state&) = delete;

private:
    struct unit {
        GLint texture_2d = 0, texture_cube = 0, sampler = 0;
    };
    GLuint first_;
    GLint active_ = GL_TEXTURE0;
    std::vector<unit> units_;
};

}  // namespace bounce::gl::detail
