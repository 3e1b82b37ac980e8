#pragma once
/// \file hemisphere_raster.hpp
/// Hemisphere sampling by rasterization onto one plane per record (Gautron 2008, section 8.4),
/// many records per batch in an atlas of planes, with the two summations Gautron 2008 weighs:
/// read-back through pixel buffer objects and a CPU sum (cpu::estimate_plane), or a reduction on
/// the GPU (a compute shader running the emitted plane_pixel_terms kernel).
///
/// One instanced draw renders a whole batch: instance k is record k, placed on its tile of
/// the atlas (tile k at column k % columns, row k / columns, N x N texels). Its vertex stage
/// applies the record's view and the plane camera's projection (square, field of view the
/// aperture, reversed depth with no far plane) and keeps the primitive inside its tile with
/// four clip distances, so tiles never bleed into each other and the scene's state is set
/// once per batch, not once per record. The fragment stage shades with gl::direct_light's
/// shadow-mapped `direct_irradiance` through the emitted lambertian_radiance and stores
/// (radiance rgb, hit distance) in RGBA32F; texels that see nothing keep (environment, +inf).
///
/// A record's plane is its local frame of plane_camera.hpp: x, y = the camera's
/// plane_camera::frame(p, n), z = n; pixel (i, j) of tile k is texel (i, j) of the tile in
/// memory order (the projection flips y so that row 0, the first in memory, is +y). The
/// record's eye is p + offset n, as a ray caster offsets its origins.

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/plane_camera.hpp>
#include <bounce/plane_weights.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <array>
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

namespace bounce::gl {

/// Settings of the raster hemisphere sampler.
struct hemisphere_raster_options {
    plane_camera camera{64, 126.0};  ///< resolution N and aperture of every plane
    std::size_t batch = 64;          ///< records per atlas (one draw, one read-back); typical 16-256
    /// Distance from the surface point to the eye along n (world units); 0 selects 1e-4 of
    /// the scene's bounding-box diagonal (the ray offset of the Embree adapter, ~1000 float
    /// ulps). The near plane lies at offset / 100: a surface meeting the record's at a
    /// corner passes within ~offset of the eye and must not be clipped (reversed float depth
    /// keeps its relative precision at any near distance), while nearer still, float
    /// positions (ulp ~1e-6 at 10 m) no longer resolve the distance.
    float offset = 0.f;
    glm::vec3 environment{0.f};  ///< radiance of texels that see nothing (W/(m^2 sr)); typical 0

    /// Throws parameter_error naming the field (camera, batch 1..4096, offset >= 0 finite,
    /// environment finite and >= 0).
    void validate() const;
};

/// The planes of one batch on the CPU, row 0 at the top (+y) as plane_camera.hpp says.
struct plane_batch {
    plane_camera camera;
    std::vector<image<glm::vec3>> radiance;  ///< per record, N x N
    std::vector<image<float>> distance;      ///< per record, N x N (+infinity: nothing hit)

    std::size_t size() const noexcept { return radiance.size(); }
    /// Record k's plane for cpu::estimate_plane.
    plane_view view(std::size_t k) const { return {radiance.at(k).view(), distance.at(k).view()}; }
};

/// The raster sampler: renders batches of records into an atlas, reads them back
/// asynchronously, and reduces them on the GPU. Works in the context current on the calling
/// thread (which must outlive it) and restores the state it changes: framebuffers,
/// viewport, program, vertex array, storage bindings 0-2, texture units 0..1+lights, pixel
/// pack buffer, depth/blend/clip state.
class hemisphere_raster {
public:
    /// Compiles the programs and allocates the atlas for options.batch planes. `mesh` must be
    /// `scene`'s geometry and `light` built on it; both must outlive this object. Throws
    /// parameter_error on bad options, gl_error when the atlas exceeds GL_MAX_TEXTURE_SIZE.
    hemisphere_raster(const scene_view& scene, const scene_mesh& mesh, const direct_light& light,
                      const hemisphere_raster_options& options = {});
    ~hemisphere_raster();
    hemisphere_raster(const hemisphere_raster&) = delete;
    hemisphere_raster& operator=(const hemisphere_raster&) = delete;

    const hemisphere_raster_options& options() const noexcept { return options_; }
    /// Records per batch (options().batch).
    std::size_t capacity() const noexcept { return options_.batch; }
    /// The offset in use (world units).
    float offset() const noexcept { return offset_; }

    /// Renders the planes of records (positions[k], normals[k]), k < capacity(): world
    /// position of the surface point and its unit normal (the side whose hemisphere is
    /// sampled). Throws parameter_error on mismatched or oversized spans, an empty batch, a
    /// non-finite position or a normal that is not unit length (|n| off by more than 1e-3).
    void render(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals);
    /// Records in the last render (0 before any).
    std::size_t rendered() const noexcept { return rendered_; }
    /// The atlas of the last render: RGBA32F, (radiance, distance) per texel.
    const texture& atlas() const noexcept { return atlas_; }
    /// Columns of tiles in the atlas.
    std::size_t columns() const noexcept { return columns_; }

    /// Starts copying the last render into a pixel buffer object (glGetTextureImage into a
    /// bound GL_PIXEL_PACK_BUFFER, then a fence) and returns at once; the CPU may render and
    /// reduce the next batch meanwhile. Up to two reads may be pending (two buffers, used in
    /// turn). Throws parameter_error before any render or when two are pending already.
    void start_read();
    /// Reads pending (started, not yet collected).
    std::size_t pending_reads() const noexcept { return pending_.size(); }
    /// Waits for the oldest pending read and returns its planes. Throws parameter_error when
    /// none is pending.
    plane_batch finish_read();

    /// Uploads the weight table the GPU reduction uses (its camera must be options().camera).
    void set_weights(const plane_weights& weights);
    /// Sums the last render on the GPU with the weights set: for each record, the sums of
    /// plane_pixel_terms over its plane (one work group of 256 invocations per record, a
    /// tree reduction in shared memory), read back as hemisphere_estimates in the local
    /// frame, irradiance and gradients times weights.scale, like cpu::estimate_plane. Throws
    /// parameter_error before any render or set_weights.
    std::vector<hemisphere_estimate> reduce();

    /// The shaders' sources (the emitted kernels included), for tests and tools.
    const std::string& vertex_source() const noexcept { return vertex_source_; }
    const std::string& fragment_source() const noexcept { return fragment_source_; }
    const std::string& reduce_source() const noexcept { return reduce_source_; }

private:
    struct pending_read;

    const scene_mesh& mesh_;
    const direct_light& light_;
    hemisphere_raster_options options_;
    float offset_ = 0.f;
    std::size_t columns_ = 1, rows_ = 1, rendered_ = 0;
    std::string vertex_source_, fragment_source_, reduce_source_;
    program raster_program_, reduce_program_;
    texture atlas_, depth_;
    framebuffer fbo_;
    buffer records_;  // per record: mat4 view-projection, vec4 tile (scale.xy, offset.xy), vec4 eye
    std::optional<buffer> weights_;
    plane_weights table_;
    buffer sums_;  // 20 floats per record
    std::array<std::optional<buffer>, 2> pbo_;
    std::size_t next_pbo_ = 0;
    std::deque<std::unique_ptr<pending_read>> pending_;
};

}  // namespace bounce::gl
