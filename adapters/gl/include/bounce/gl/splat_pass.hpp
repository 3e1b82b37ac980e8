#pragma once
/// \file splat_pass.hpp
/// Irradiance splatting on OpenGL (Gautron 2008, section 8.1, Algorithms 1-4), and the
/// normalization and composition of Algorithm 5.
///
/// One quad per record, instanced from a buffer of records (per-instance attributes for the
/// vertex stage, a storage buffer indexed by instance for the fragment stage): the vertex
/// stage puts
/// the quad on the exact screen box of the record's sphere of influence (the emitted
/// `sphere_ndc_bounds` of splat_bounds.hpp around the emitted `influence_radius` of the
/// weighting policy), the fragment stage fetches the G-buffer at its pixel and adds the
/// emitted `splat_contribution` (cache/record.hpp) into an RGBA32F splat texture with
/// additive blending. Blending happens in primitive order, i.e. record order, and adds
/// the same float terms as cpu::splat_records in the same order, so the two splat
/// buffers agree to the rounding of the kernels themselves.
///
/// Textures are in GL row order (row 0 at the bottom); every upload and read here flips
/// rows so that images on the CPU side have row 0 at the top, as bounce::image_view says.

#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/image.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>

#include <cstddef>
#include <limits>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <tuple>
#include <utility>

#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

/// The three G-buffer textures a pass reads (GL row order): position (xyz) and depth along
/// the view axis (w, +infinity where no geometry) in an RGBA32F texture; the unit normal
/// facing the camera (xyz) in RGBA32F or RGB32F; the diffuse reflectance (rgb) in RGBA32F,
/// RGB32F or RGBA8 (normalized). gbuffer_pass writes all three as RGBA32F. Borrowed: bounce
/// textures or a renderer's own (texture_ref::of(name)); they must outlive the use.
struct gbuffer_textures {
    texture_ref position_depth, normal, albedo;

    /// Size in pixels (0 when position_depth is not set).
    std::size_t width() const noexcept { return position_depth.width; }
    std::size_t height() const noexcept { return position_depth.height; }
    /// Throws parameter_error (parameter "gbuffer") unless all three are set, of the formats
    /// above and of one size.
    void validate() const;
};

/// The textures of `pass`'s last rendering. Throws parameter_error before any render.
gbuffer_textures textures_of(const gbuffer_pass& pass);

/// Reads the G-buffer textures `g` into `out` (row 0 at the top; every view of g's size):
/// the CPU's view of a G-buffer a renderer drew. Throws parameter_error on bad textures or
/// sizes.
void read_gbuffer(const gbuffer_textures& g, gbuffer_view<float> out);

/// A CPU G-buffer (e.g. a ray-cast one, or an analytic one in tests) uploaded as textures
/// of gbuffer_pass's layout, rows flipped, so GL passes can read it.
class gbuffer_upload {
public:
    gbuffer_upload() = default;
    /// Uploads `g` (a context must be current).
    explicit gbuffer_upload(const gbuffer_view<float>& g) { upload(g); }
    /// Replaces the contents with `g` (textures reallocated when the size changes).
    /// Throws parameter_error for an empty G-buffer or views of different sizes.
    void upload(const gbuffer_view<float>& g);
    /// The uploaded textures. Throws parameter_error before any upload.
    gbuffer_textures textures() const;

private:
    std::optional<texture> position_depth_, normal_, albedo_;
};

/// Copies `image` (row 0 at the top) into the RGBA32F texture `t` of the same size.
/// Throws parameter_error on a size or format mismatch.
void write_texture(const texture& t, image_view<const glm::vec4> image);
/// Copies the RGBA32F texture `t` into `out` (row 0 at the top). Throws parameter_error on
/// a size or format mismatch.
void read_texture(const texture_ref& t, image_view<glm::vec4> out);
/// Copies the rgb of the RGBA32F texture `t` into `out` (row 0 at the top).
void read_texture(const texture_ref& t, image_view<glm::vec3> out);

/// Parameters shared by every splat of a frame (cache/record.hpp).
using bounce::splat_params;

/// The GL irradiance splatting pass: a record buffer on the GPU that grows by appending,
/// and a splat texture (RGBA32F: sum of w rho_d/pi E_k(p) in rgb, sum of w in alpha).
///
/// Algorithm 5 with it: `clear`; `splat` every cached record; `read_splat`; the CPU scan
/// adds records and splats them into its copy; `upload_splat` of that copy, or keep the
/// GPU buffer and `append` the new records and `splat(..., first = old count)` them on
/// top; then compose_pass normalizes and adds direct light.
///
/// Programs (one per weighting policy and gradients on/off) are compiled on first use and
/// kept. Works in the context current on the calling thread and restores what it changes
/// (framebuffers, viewport, program, vertex array, storage binding 0, texture units 0-2
/// and their samplers, blend, depth and dither state).
class splat_pass {
public:
    /// Everything from `first` on.
    static constexpr std::size_t all = std::numeric_limits<std::size_t>::max();

    /// Creates the (empty) record buffer. A context must be current.
    splat_pass();

    /// Replaces the records on the GPU with `records`. Throws parameter_error naming
    /// "records[i]" for a non-finite field or a radius that is not positive.
    void upload(std::span<const irradiance_record> records);
    /// Adds `records` after those already uploaded (the buffer grows geometrically; only
    /// the new records travel). Same errors as upload.
    void append(std::span<const irradiance_record> records);
    /// Number of records on the GPU.
    std::size_t record_count() const noexcept { return count_; }

    /// Makes the splat texture width x height (reallocated when the size changes) and
    /// zeroes it. Throws parameter_error for a zero size.
    void clear(std::size_t width, std::size_t height);
    /// Replaces the splat texture with `splat` (row 0 at the top), e.g. the buffer the
    /// CPU cache-miss scan completed. Throws parameter_error for an empty image.
    void upload_splat(image_view<const glm::vec4> splat);
    /// Adds records [first, first + count) (clipped to record_count()) into the splat
    /// texture, in record order, seen by `cam` over the G-buffer `g` (whose size must be the
    /// splat texture's). Throws parameter_error for bad parameters, a size mismatch, no
    /// splat texture yet (call clear or upload_splat), or first > record_count().
    void splat(const gbuffer_textures& g, const camera& cam, const splat_params& params, weighting_kind weighting,
               std::size_t first = 0, std::size_t count = all);
    /// The same with the weighting given as a policy object, as the CPU cache and
    /// cpu::splat_records take it (cache/weighting.hpp): `pass.splat(g, cam, params,
    /// ward_smooth_weight{})`, or `with_weighting(kind, [&](auto w) { pass.splat(g, cam,
    /// params, w); })`. Only the named policies (those with a weighting_kind) compile here.
    template <named_weighting Weight>
    void splat(const gbuffer_textures& g, const camera& cam, const splat_params& params, Weight,
               std::size_t first = 0, std::size_t count = all) {
        splat(g, cam, params, weighting_kind_of<Weight>, first, count);
    }
    /// Copies the splat texture into `out` (row 0 at the top; sizes must match).
    void read_splat(image_view<glm::vec4> out) const;
    /// The splat texture as an owning image.
    image<glm::vec4> read_splat() const;

    /// The splat texture (throws parameter_error before clear or upload_splat).
    const texture& splat_texture() const;
    /// Size of the splat texture in pixels (0 before clear or upload_splat).
    std::size_t width() const noexcept { return width_; }
    std::size_t height() const noexcept { return height_; }

    /// The shaders of a variant, with the emitted kernels in them (for inspection).
    static std::string vertex_source(weighting_kind weighting);
    static std::string fragment_source(weighting_kind weighting, bool gradients, bool front_test = false);

private:
    const program& variant(weighting_kind weighting, bool gradients, bool front_test);
    void ensure_target(std::size_t width, std::size_t height);
    void write_records(std::size_t at, std::span<const irradiance_record> records);

    std::optional<buffer> records_;
    std::size_t count_ = 0, capacity_ = 0;
    std::optional<texture> splat_;
    framebuffer fbo_;
    vertex_array record_vao_;
    std::size_t width_ = 0, height_ = 0;
    std::map<std::tuple<int, bool, bool>, program> programs_;  // (weighting, gradients, front test)
};

/// Normalization and composition (Algorithm 5, last steps) on the GPU: per pixel the
/// emitted `normalized_splat` (sum / weight, black where no record reached) plus the
/// direct radiance, into an RGBA32F texture (rgb; alpha 1).
class compose_pass {
public:
    /// Compiles the two programs (with and without direct light). A context must be current.
    compose_pass();
    /// result = normalized_splat(splat) + direct, where `direct` (RGBA32F, rgb = direct
    /// radiance, e.g. direct_light::radiance()) may be null for the indirect image alone.
    /// Throws parameter_error when the sizes differ or a texture is not RGBA32F.
    void compose(const texture& splat, const texture* direct = nullptr);
    /// Progressive hole filling: result = hole_filled_splat(splat, wide, lambda) + direct,
    /// `wide` holding the same records splatted with a wider a (see cpu::normalize_splats);
    /// `wide` null is the plain compose. Throws parameter_error on sizes, formats or
    /// lambda <= 0.
    void compose(const texture& splat, const texture* direct, const texture* wide, float lambda);
    /// The same with the direct radiance given as a CPU image (row 0 at the top).
    void compose(const texture& splat, image_view<const glm::vec3> direct);
    /// Copies the result's rgb into `out` (row 0 at the top; sizes must match).
    void read(image_view<glm::vec3> out) const;
    /// The result texture (throws parameter_error before compose).
    const texture& result() const;

private:
    program with_direct_, without_direct_, with_direct_wide_, without_direct_wide_;
    std::optional<texture> result_, uploaded_direct_;
    framebuffer fbo_;
    vertex_array empty_vao_;
};

}  // namespace bounce::gl
