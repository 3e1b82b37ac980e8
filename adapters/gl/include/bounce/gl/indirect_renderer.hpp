#pragma once
/// \file indirect_renderer.hpp
/// `gl::indirect_renderer`: one frame of one-bounce indirect irradiance from reflective
/// shadow maps on OpenGL, by the RSM gather (Dachsbacher and Stamminger 2005) or by
/// splatting indirect illumination (Dachsbacher and Stamminger 2006), optionally
/// interleaved (Keller and Heidrich 2001, in the deferred form of Segovia et al. 2006) and
/// energy-correct (docs/rsm-sii-interleaved.md, section 5), on the caller's G-buffer and
/// RSM textures in the caller's context, into the caller's output texture:
///
///   split G-buffer (fragment pass, index maps of indirect/interleaved_sampling.hpp)
///   -> shade each sub-buffer with its light subset
///        RSM gather: a fragment pass reading the disc pattern from a storage buffer
///        SII: one instanced quad per VPL on its split-buffer rectangle, additive blending
///   -> gather (fragment pass) -> discontinuity buffer -> separable geometry-aware tent
///   (the RSM gather may also run at 1/f resolution: a downsampling pass, the frame above at
///   low resolution, then the geometry-aware upsampling with the full-resolution fallback
///   gather of DS05 section 3.3, as the CPU renderer does)
///
/// It is the GL twin of cpu::indirect_renderer: the same options and timings (the core's
/// bounce::indirect_options and bounce::indirect_timings, indirect/options.hpp), the same
/// disc pattern, light groups, VPLs (selected on the host from the read-back RSM) and pixel
/// rectangles (the core's indirect/rsm_sampling.hpp, which the CPU renderer calls too), and every
/// formula an emitted kernel of indirect/rsm.hpp and indirect/interleaved_sampling.hpp, so its image agrees
/// with the CPU's to float rounding (tests/gl_rsm). Each pixel sums its terms in the CPU's order (blending
/// adds in primitive order).
///
/// Textures are in GL row order (row 0 at the bottom); the index maps are applied to the
/// rows counted from the top, as on the CPU, so both backends put a pixel in the same
/// sub-buffer. The renderer restores the GL state it changes (framebuffers, viewport,
/// program, vertex array, storage bindings 0-2, texture units 0-5 and their samplers,
/// blend, depth and dither state).

#include <bounce/camera.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/gl/context.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/output_pass.hpp>
#include <bounce/gl/rsm_textures.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/indirect/imperfect_shadow_maps.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/vpl_sampling.hpp>
#include <bounce/output.hpp>

#include <chrono>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <glm/mat4x4.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

namespace bounce::gl {

class indirect_renderer {
public:
    /// Compiles the passes' programs (a context must be current; it must outlive the
    /// renderer). Throws parameter_error for bad options (validate_options). With `time_stages`, glFinish
    /// after every stage, so the stage times are the GPU's (wall clock between finishes);
    /// without, the times measure only the issuing of commands.
    explicit indirect_renderer(const indirect_options& options = {}, bool time_stages = false);

    /// options.validate(), and what this backend cannot do: receiver-sender visibility by
    /// rays (indirect_visibility::rays runs on the CPU, cpu::indirect_renderer with
    /// embree::occlusion_rays; ism runs here). Throws parameter_error naming the field.
    static void validate_options(const indirect_options& options);
    ~indirect_renderer();
    indirect_renderer(const indirect_renderer&) = delete;
    indirect_renderer& operator=(const indirect_renderer&) = delete;

    const indirect_options& options() const noexcept { return options_; }
    bool time_stages() const noexcept { return time_stages_; }

    /// The scene's point sampler for visibility ism (indirect/imperfect_shadow_maps.hpp): its
    /// points are uploaded on the first ism frame (again when it, the VPL count or the
    /// points per VPL change) and each SII frame splats them into the VPLs' maps (compute
    /// passes, in the shade stage). It must outlive the frames; render throws
    /// parameter_error when the options ask for ism and none was given.
    void set_point_sampler(const ism_point_sampler* points) noexcept { points_ = points; }

    /// Writes into `irradiance` (RGBA32F, the G-buffer's size; rgb = W/m^2, a = 0) the
    /// one-bounce indirect irradiance `maps` (one per spot or directional light, six per
    /// point light, one size for the gather) reflect onto the G-buffer `g` seen by `cam`,
    /// unoccluded; 0 where the G-buffer sees nothing. Throws parameter_error naming the
    /// texture or map at fault (sizes, formats, zero-sized textures). The SII shade stage
    /// includes reading the maps back and selecting the VPLs on the host; fallback_pixels
    /// is counted by an occlusion query.
    indirect_timings render(const gbuffer_textures& g, const camera& cam, std::span<const rsm_textures> maps,
                            const texture_ref& irradiance);
    /// The same as `quantity` (output.hpp): radiance is rho/pi E with g's albedo, made in
    /// `out` after the frame by gl::output_pass (compiled on first use; not in the timings).
    indirect_timings render(const gbuffer_textures& g, const camera& cam, std::span<const rsm_textures> maps,
                            const texture_ref& out, output_quantity quantity) {
        const indirect_timings t = render(g, cam, maps, out);
        if (quantity == output_quantity::radiance) {
            if (!output_) output_.emplace();
            output_->apply(quantity, g.albedo, out);
        }
        return t;
    }

    /// The last frame's VPLs (SII), in the order of their light groups (sub-buffer 0's
    /// first), each with its interleaving weight already applied to the flux.
    const std::vector<vpl>& splatted_vpls() const noexcept { return splatted_; }

private:
    struct passes;
    using clock = std::chrono::steady_clock;
    double lap(clock::time_point& t) const;
    void frame(const gbuffer_textures& g, std::size_t w, std::size_t h, const camera& cam,
               std::span<const rsm_textures> maps, object_id out, indirect_timings& t, clock::time_point& start);

    indirect_options options_;
    bool time_stages_ = false;
    std::unique_ptr<passes> passes_;
    std::vector<vpl> splatted_;
    std::optional<output_pass> output_;
    const ism_point_sampler* points_ = nullptr;
};

/// `gl::indirect_renderer` in an EGL context of its own, on a G-buffer and maps held in host
/// images (what the CPU renderer takes: a ray-cast G-buffer, embree::rsm_ray_caster's
/// maps), for programs and studies that run both backends on the same inputs. It has the
/// call of cpu::indirect_renderer (`render(options, gb, cam, maps, irradiance)`): each
/// call uploads the G-buffer and maps as RGBA32F textures, renders with `options` (the
/// renderer and its programs are kept while the options compare equal) and reads the
/// irradiance back. The stage times are the GPU's (time_stages); neither the uploads nor
/// the read-back are timed. The context is made current on construction and by each
/// render; use the object from one thread.
class offscreen_indirect_renderer {
public:
    /// Creates the context (throws gl_error when EGL gives none).
    explicit offscreen_indirect_renderer(const context_options& context = {});
    ~offscreen_indirect_renderer();
    offscreen_indirect_renderer(const offscreen_indirect_renderer&) = delete;
    offscreen_indirect_renderer& operator=(const offscreen_indirect_renderer&) = delete;

    /// Fills `irradiance` (the G-buffer's size) as cpu::indirect_renderer::render does.
    /// Throws parameter_error for bad options (before any GL work) or inputs.
    indirect_timings render(const indirect_options& options, const gbuffer_view<float>& gb, const camera& cam,
                            std::span<const rsm_view> maps, image_view<glm::vec3> irradiance);
    /// The same as `quantity` (output.hpp): radiance is rho/pi times the irradiance with the
    /// G-buffer's albedo, as cpu::indirect_renderer::render gives it.
    indirect_timings render(const indirect_options& options, const gbuffer_view<float>& gb, const camera& cam,
                            std::span<const rsm_view> maps, image_view<glm::vec3> out, output_quantity quantity) {
        const indirect_timings t = render(options, gb, cam, maps, out);
        apply_output(quantity, image_view<const glm::vec3>(gb.albedo), out);
        return t;
    }

    /// The scene's point sampler for visibility ism (indirect_renderer::set_point_sampler).
    void set_point_sampler(const ism_point_sampler* points) noexcept { points_ = points; }

    /// GL_RENDERER of the context ("llvmpipe (LLVM 15.0.6, 256 bits)" ...).
    std::string gl_renderer() const { return context_.renderer(); }

private:
    struct uploads;
    context context_;  // first: everything below needs it current
    std::unique_ptr<uploads> uploads_;
    std::optional<indirect_renderer> renderer_;
    const ism_point_sampler* points_ = nullptr;
};

}  // namespace bounce::gl
