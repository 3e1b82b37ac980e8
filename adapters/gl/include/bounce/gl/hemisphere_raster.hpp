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
/// A record's plane is its local frame of cache/plane_camera.hpp: x, y = the camera's
/// plane_camera::frame(p, n), z = n; pixel (i, j) of tile k is texel (i, j) of the tile in
/// memory order (the projection flips y so that row 0, the first in memory, is +y). The
/// record's eye is p + offset n, as a ray caster offsets its origins.
///
/// A renderer with its own scene, shaders and lights builds the raster with a draw callback
/// instead (hemisphere_raster(scene, plane_drawer, options)), as lightmapper.h draws its
/// user's scene: the raster calls it once per record with that record's view, projection
/// and tile, and the caller draws its scene with its own program. The reading and the
/// reduction are the same for both kinds.

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/cache/plane_camera.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/image.hpp>
#include <bounce/scene_view.hpp>

#include <array>
#include <cstddef>
#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
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

/// The planes of one batch on the CPU, row 0 at the top (+y) as cache/plane_camera.hpp says.
struct plane_batch {
    plane_camera camera;
    std::vector<image<glm::vec3>> radiance;  ///< per record, N x N
    std::vector<image<float>> distance;      ///< per record, N x N (+infinity: nothing hit)

    std::size_t size() const noexcept { return radiance.size(); }
    /// Record k's plane for cpu::estimate_plane.
    plane_view view(std::size_t k) const { return {radiance.at(k).view(), distance.at(k).view()}; }
    /// Every record's plane, in order.
    std::vector<plane_view> views() const {
        std::vector<plane_view> v;
        for (std::size_t k = 0; k < size(); ++k) v.push_back(view(k));
        return v;
    }
};

/// Called with the index of a batch's first record among all those passed to
/// hemisphere_raster::read_planes and the batch's planes (valid during the call only).
using plane_batch_consumer = std::function<void(std::size_t first, const plane_batch& planes)>;

/// What a plane_drawer is given for one record: where the record is, the camera it must
/// draw with, and the tile of the atlas it draws into.
struct plane_draw {
    /// A rectangle of the atlas in texels, GL window coordinates (x, y: lower-left corner).
    struct rect {
        std::int32_t x = 0, y = 0, width = 0, height = 0;
    };
    std::size_t record = 0;  ///< index of the record in the batch passed to render: tile `record`
    glm::vec3 position{0.f};  ///< the record's surface point (world), as passed to render
    glm::vec3 normal{0.f};    ///< its unit normal (world), as passed to render
    glm::vec3 eye{0.f};       ///< position + offset() * normal: the centre of projection (world)
    /// World to view: view x, y = plane_camera::frame(position, normal), view -z = normal,
    /// eye at the origin.
    glm::mat4 view{1.f};
    /// The plane projection the built-in drawer uses: square, field of view the aperture,
    /// y flipped (plane row 0, +y, is the tile's first row in memory), reversed depth for
    /// glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE) with no far plane: window depth =
    /// near / (distance along -z), near = offset() / 100; 0 is infinitely far.
    glm::mat4 projection{1.f};
    glm::mat4 view_projection{1.f};  ///< projection * view: gl_Position = view_projection * world
    rect tile;                       ///< the record's tile: the viewport and the scissor box
};

/// The caller's scene drawer: draws the scene seen from one record into the bound tile.
///
/// Contract. Before each call the raster sets, and the callback may rely on:
/// - the atlas framebuffer bound as GL_DRAW_FRAMEBUFFER, fragment output 0 routed to the
///   RGBA32F atlas, a 32-bit float depth attachment;
/// - glViewport and glScissor set to `d.tile`, GL_SCISSOR_TEST on (so nothing the callback
///   draws or clears lands in another record's tile, with no clip distances in its shader);
/// - reversed depth: glClipControl(GL_LOWER_LEFT, GL_ZERO_TO_ONE), GL_DEPTH_TEST on,
///   glDepthFunc(GL_GREATER), depth writes on, glDepthRange(0, 1); the tile was cleared to
///   depth 0 (infinitely far) and colour (environment, +infinity) before the first call;
/// - colour writes on for all channels; GL_BLEND, GL_CULL_FACE, GL_STENCIL_TEST,
///   GL_RASTERIZER_DISCARD, GL_DEPTH_CLAMP, GL_POLYGON_OFFSET_FILL, GL_SAMPLE_ALPHA_TO_COVERAGE,
///   GL_SAMPLE_COVERAGE, GL_COLOR_LOGIC_OP, the primitive restarts and every
///   GL_CLIP_DISTANCEi off; polygon mode GL_FILL.
/// The callback draws with `d.view_projection` (or `d.projection` times its own equal view)
/// unchanged: the reductions read texel (i, j) of the tile as the direction of plane pixel
/// (i, j), and only this depth convention keeps the nearest surface under GL_GREATER
/// against the cleared 0 (a texel nothing covers keeps (environment, +infinity)). The y flip reverses every triangle's winding in the
/// window: a callback that culls faces must cull GL_FRONT where an unflipped camera culls
/// GL_BACK (or set glFrontFace(GL_CW)). Each fragment must write
/// to colour output 0 `vec4(L, r)`: L the radiance (rgb, W/(m^2 sr)) leaving the visible
/// surface towards the eye, r = length(world position - d.eye), the hit distance (world
/// units) the gradients and the harmonic mean distance are computed from. The callback binds
/// its own program, vertex arrays, buffers and textures and may change any state; the raster
/// sets the list above again before the next call. After the last call the raster restores
/// the state it saved on entry (see hemisphere_raster); what the callback bound beyond it
/// (its buffers, textures, uniform blocks, storage and image bindings) stays bound, as
/// after any of its own draws. The callback must not delete or reattach the framebuffer.
/// It costs one call, so typically one draw, per record, where the built-in drawer draws
/// a whole batch with one instanced draw.
using plane_drawer = std::function<void(const plane_draw&)>;

/// The raster sampler: renders batches of records into an atlas, reads them back
/// asynchronously, and reduces them on the GPU. Works in the context current on the calling
/// thread (which must outlive it) and restores the state it changes: framebuffers,
/// viewport, scissor box, program, vertex array, storage bindings 0-1, texture units
/// 0..1+lights, pixel pack buffer, depth/blend/stencil/cull/scissor and the other
/// capabilities of plane_drawer's list, colour mask, polygon mode, clip control, clip
/// distance enables.
///
/// Two kinds, the same afterwards (render, start_read/finish_read, set_weights, reduce):
/// - built-in: bounce's scene_mesh shaded with gl::direct_light, one instanced draw per batch;
/// - callback: the caller's plane_drawer, called once per record (one draw or more each).
class hemisphere_raster {
public:
    /// The built-in drawer: compiles the programs and allocates the atlas for options.batch
    /// planes. `mesh` must be `scene`'s geometry and `light` built on it; both must outlive
    /// this object. Throws parameter_error on bad options, gl_error when the atlas exceeds
    /// GL_MAX_TEXTURE_SIZE.
    hemisphere_raster(const scene_view& scene, const scene_mesh& mesh, const direct_light& light,
                      const hemisphere_raster_options& options = {});
    /// The caller's drawer: `draw` renders the caller's scene for each record (the contract
    /// is plane_drawer's). `scene` gives only the bounds for the default offset (a view of
    /// positions alone will do) and need not outlive the constructor. Throws parameter_error
    /// naming `draw` when it is empty and on bad options, gl_error as above.
    hemisphere_raster(const scene_view& scene, plane_drawer draw, const hemisphere_raster_options& options = {});
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
    /// With a draw callback, calls it for k = 0, 1, ... in order; an exception from it
    /// propagates after the GL state is restored, leaving nothing rendered (start_read and
    /// reduce refuse until the next render).
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

    /// The planes of every record (positions[k], normals[k]), any number of them, rendered
    /// capacity() per batch and read back through the two pixel buffers in turn: batch b + 1
    /// renders while batch b is copied, then `consume(first of b, planes of b)` runs (on
    /// the calling thread) while b + 1 is copied, and so on; the CPU's work on a batch
    /// overlaps the GPU's on the next (Gautron 2008's read-back with CPU sums). Throws
    /// parameter_error when the spans' sizes differ, `consume` is empty, or reads are pending
    /// (it would collect another caller's); render's errors for bad points. When `consume` or
    /// the GL throws, the reads it started are dropped before the exception propagates, so
    /// the raster can be used again.
    void read_planes(std::span<const glm::vec3> positions, std::span<const glm::vec3> normals,
                     const plane_batch_consumer& consume);

    /// Uploads the weight table the GPU reduction uses (its camera must be options().camera).
    void set_weights(const plane_weights& weights);
    /// Sums the last render on the GPU with the weights set: for each record, the sums of
    /// plane_pixel_terms over its plane (one work group of 256 invocations per record, a
    /// tree reduction in shared memory), read back as hemisphere_estimates in the local
    /// frame, irradiance and gradients times weights.scale, like cpu::estimate_plane. Throws
    /// parameter_error before any render or set_weights.
    std::vector<hemisphere_estimate> reduce();

    /// The shaders' sources (the emitted kernels included), for tests and tools; the raster
    /// ones are empty with a draw callback.
    const std::string& vertex_source() const noexcept { return vertex_source_; }
    const std::string& fragment_source() const noexcept { return fragment_source_; }
    const std::string& reduce_source() const noexcept { return reduce_source_; }

private:
    struct pending_read;

    hemisphere_raster(const scene_view& scene, const scene_mesh* mesh, const direct_light* light, plane_drawer draw,
                      const hemisphere_raster_options& options);
    void draw_built_in(std::size_t records);
    void draw_callback(std::span<const plane_draw> draws);

    const scene_mesh* mesh_ = nullptr;    // the built-in drawer's, or null
    const direct_light* light_ = nullptr;
    plane_drawer draw_;                   // the caller's, or empty
    hemisphere_raster_options options_;
    float offset_ = 0.f;
    std::size_t columns_ = 1, rows_ = 1, rendered_ = 0;
    std::string vertex_source_, fragment_source_, reduce_source_;
    std::optional<program> raster_program_;  // the built-in drawer's
    program reduce_program_;
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
