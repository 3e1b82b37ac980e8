#pragma once
/// \file indirect_renderer.hpp
/// One frame of one-bounce indirect irradiance from reflective shadow maps on the CPU, by
/// the RSM gather (DS05) or by splatting indirect illumination (DS06), optionally
/// interleaved (Segovia et al. 2006) and energy-correct (docs/rsm-sii-interleaved.md):
///
///   split G-buffer -> shade each sub-buffer with its light subset -> gather -> blur
///   (the RSM gather may also run at 1/f resolution, then upsample with fallback)
///
/// A renderer keeps one `indirect_renderer` and calls `render` per frame with views of its
/// own G-buffer and reflective shadow maps; scratch buffers are kept between frames and
/// reallocated only when the size changes. The result is irradiance (W/m^2 per channel) or,
/// asked for output_quantity::radiance, rho_d / pi times it with the G-buffer's albedo
/// (output.hpp).
///
/// The options and timings (bounce::indirect_options, bounce::indirect_timings in
/// indirect/options.hpp) and the host-side choices (disc pattern, VPL selection, splat
/// rectangles in indirect/rsm_sampling.hpp) are the core's, shared with gl::indirect_renderer.

#include <bounce/camera.hpp>
#include <bounce/cpu/imperfect_shadow_maps.hpp>
#include <bounce/cpu/interleave.hpp>
#include <bounce/cpu/rsm_gather.hpp>
#include <bounce/cpu/sii_splat.hpp>
#include <bounce/cpu/view_selection.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/indirect/options.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/indirect/visibility.hpp>
#include <bounce/indirect/vpl_sampling.hpp>
#include <bounce/output.hpp>

#include <chrono>
#include <cmath>
#include <span>
#include <vector>

namespace bounce::cpu {

class indirect_renderer {
public:
    /// `occlusion` answers the visibility queries of options.visibility == rays
    /// (embree::occlusion_query); `points` samples the scene for visibility ism. Both must
    /// outlive the frames that use them. `near_field` answers the rays of the RSM gather's
    /// clamp compensation (options.clamp_compensation_rays > 0 with visibility rays or none;
    /// embree::near_field_rays).
    explicit indirect_renderer(const indirect_options& options = {}, const occlusion_query* occlusion = nullptr,
                               const ism_point_sampler* points = nullptr, const near_field_query* near_field = nullptr)
        : options_(options), occlusion_(occlusion), points_(points), near_field_(near_field) {
        options_.validate();
        require_occlusion(options_, occlusion_);
        require_points(options_, points_);
        require_near_field(options_, near_field_);
    }

    /// The near-field query of the next frames (the gather's clamp compensation); nullptr
    /// allowed only while the options ask for no compensation. Throws parameter_error otherwise.
    void set_near_field_query(const near_field_query* near_field) {
        require_near_field(options_, near_field);
        near_field_ = near_field;
    }

    /// The scene's point sampler of the next frames (visibility ism); nullptr allowed only
    /// while options().visibility is not ism. Throws parameter_error otherwise.
    void set_point_sampler(const ism_point_sampler* points) {
        require_points(options_, points);
        if (points != points_) ism_points_.clear();
        points_ = points;
    }

    const indirect_options& options() const noexcept { return options_; }

    /// The occlusion query of the next frames (nullptr: none, allowed only while
    /// options().visibility is none). Throws parameter_error otherwise (the old one stays).
    void set_occlusion_query(const occlusion_query* occlusion) {
        require_occlusion(options_, occlusion);
        occlusion_ = occlusion;
    }

    /// Validates and takes `options` for the next frames; the scratch buffers stay (they
    /// depend on the image size and pattern only), the disc pattern is redrawn when the
    /// options differ. Throws parameter_error naming the bad field (the old options stay).
    void set_options(const indirect_options& options) {
        options.validate();
        require_occlusion(options, occlusion_);
        require_points(options, points_);
        require_near_field(options, near_field_);
        if (options == options_) return;
        options_ = options;
        full_pattern_.clear();
        pattern_texels_ = 0;
    }

    /// set_options(options), then render(gb, cam, maps, out, quantity): the call
    /// gl::offscreen_indirect_renderer offers too, so a caller switches backends by type.
    indirect_timings render(const indirect_options& options, const gbuffer_view<float>& gb, const camera& cam,
                            std::span<const rsm_view> maps, image_view<glm::vec3> out,
                            output_quantity quantity = output_quantity::irradiance) {
        set_options(options);
        return render(gb, cam, maps, out, quantity);
    }

    /// Fills `out` (the G-buffer's size) with the one-bounce indirect light that `maps` (one
    /// per spot or directional light, six per point light) reflect onto the G-buffer's
    /// pixels, as `quantity` (output.hpp): irradiance (W/m^2, the default) or radiance with
    /// the G-buffer's albedo; 0 where the G-buffer sees nothing. Unoccluded (light passes
    /// through walls, as DS05/DS06 publish it) unless options().visibility asks for rays or
    /// imperfect shadow maps (ism).
    indirect_timings render(const gbuffer_view<float>& gb, const camera& cam, std::span<const rsm_view> maps,
                            image_view<glm::vec3> out, output_quantity quantity = output_quantity::irradiance) {
        const indirect_timings t = render_irradiance(gb, cam, maps, out);
        apply_output(quantity, image_view<const glm::vec3>(gb.albedo), out);
        return t;
    }

private:
    indirect_timings render_irradiance(const gbuffer_view<float>& gb, const camera& cam, std::span<const rsm_view> maps,
                                       image_view<glm::vec3> irradiance) {
        cam.validate();
        require(irradiance.width() == gb.width() && irradiance.height() == gb.height(), "out",
                "size differs from the G-buffer");
        require(!gb.depth.empty(), "gb", "is empty");
        for (const auto& m : maps) m.validate();
        indirect_timings t;
        totals_ = {};
        const int f = options_.low_resolution;
        if (f == 1) {
            frame(gb, cam, maps, irradiance, full_, t);
            return t;
        }
        auto start = clock::now();
        const std::size_t lw = (gb.width() + std::size_t(f) - 1) / std::size_t(f);
        const std::size_t lh = (gb.height() + std::size_t(f) - 1) / std::size_t(f);
        if (low_gb_.width() != lw || low_gb_.height() != lh) {
            low_gb_ = gbuffer<float>(lw, lh);
            low_irradiance_ = image<glm::vec3>(lw, lh);
        }
        downsample_gbuffer(gb, f, low_gb_.view());
        t.split_ms += ms_since(start);
        frame(low_gb_.view(), cam, maps, low_irradiance_.view(), low_, t);
        start = clock::now();
        compensation_totals fallback;
        t.fallback_pixels = upsample_or_gather(gb, cam, low_gb_.view(), low_irradiance_.view(), f, options_.upsample,
                                               maps, full_pattern_, options_.light, irradiance, occlusion(),
                                               compensation(), &fallback);
        t.upsample_ms = ms_since(start);
        add_totals(fallback, t);
        return t;
    }

    using clock = std::chrono::steady_clock;
    static double ms_since(clock::time_point s) {
        return std::chrono::duration<double, std::milli>(clock::now() - s).count();
    }

    /// Scratch of one resolution.
    struct buffers {
        interleave_maps maps;
        gbuffer<float> split_gb;
        image<glm::vec3> split_out, gathered, scratch;
        image<glm::vec2> edges;
        /// Visibility edges (rays, interleaved, blurred): the splat's per-pixel sums in the
        /// split buffer and gathered back (add_visibility_edges).
        image<glm::vec3> split_stats, stats;
    };

    /// Whether the frame cuts its blur at visibility edges too: interleaved SII blurred
    /// with rays and discontinuity.visibility_sigmas > 0.
    bool visibility_edges() const noexcept {
        return options_.technique == indirect_technique::sii && options_.pattern.cells() > 1 && options_.blur &&
               occlusion() != nullptr && options_.discontinuity.visibility_sigmas > 0.f;
    }

    void frame(const gbuffer_view<float>& gb, const camera& cam, std::span<const rsm_view> maps,
               image_view<glm::vec3> out, buffers& b, indirect_timings& t) {
        const interleave_pattern& p = options_.pattern;
        const bool interleaved = p.cells() > 1;
        const std::size_t w = gb.width(), h = gb.height();
        auto start = clock::now();
        if (b.maps.width != w || b.maps.height != h || b.maps.pattern.n != p.n || b.maps.pattern.m != p.m) {
            b.maps = interleave_maps(p, w, h);
            if (interleaved) {
                b.split_gb = gbuffer<float>(w, h);
                b.split_out = image<glm::vec3>(w, h);
                b.gathered = image<glm::vec3>(w, h);
                b.scratch = image<glm::vec3>(w, h);
                b.edges = image<glm::vec2>(w, h);
            }
        }
        if (visibility_edges() && (b.stats.width() != w || b.stats.height() != h)) {
            b.split_stats = image<glm::vec3>(w, h);
            b.stats = image<glm::vec3>(w, h);
        }
        gbuffer_view<float> shaded_gb = gb;
        image_view<glm::vec3> shaded_out = out;
        if (interleaved) {
            split_gbuffer(gb, b.split_gb.view(), b.maps);
            shaded_gb = b.split_gb.view();
            shaded_out = b.split_out.view();
        }
        t.split_ms += ms_since(start);

        start = clock::now();
        if (options_.technique == indirect_technique::rsm_gather)
            shade_gather(shaded_gb, maps, b.maps, shaded_out, t);
        else
            shade_splat(shaded_gb, cam, maps, b.maps, shaded_out, t,
                        visibility_edges() ? b.split_stats.view() : image_view<glm::vec3>());
        t.shade_ms += ms_since(start);
        if (!interleaved) return;

        start = clock::now();
        image_view<glm::vec3> gathered = options_.blur ? b.gathered.view() : out;
        gather_image<glm::vec3>(b.split_out.view(), gathered, b.maps);
        if (visibility_edges()) gather_image<glm::vec3>(b.split_stats.view(), b.stats.view(), b.maps);
        t.gather_ms += ms_since(start);
        if (!options_.blur) return;
        start = clock::now();
        discontinuity_buffer(gb, options_.discontinuity, b.edges.view());
        if (visibility_edges())
            add_visibility_edges(b.stats.view(), options_.discontinuity.visibility_sigmas, b.edges.view());
        geometry_aware_blur(b.gathered.view(), b.edges.view(), gb.depth, p, b.scratch.view(), out);
        if (options_.technique == indirect_technique::sii && options_.discontinuity.complete_below > 0.f) {
            image<float> reached(w, h);  // the pixels the blur isolates get every VPL (sii_splat.hpp)
            reached_sub_buffers(b.edges.view(), gb.depth, p, reached.view());
            complete_isolated_pixels(gb, reached.view(), options_.discontinuity.complete_below * float(p.cells()),
                                     vpls_, options_.light, out, occlusion());
        }
        t.blur_ms += ms_since(start);
    }

    void shade_gather(const gbuffer_view<float>& gb, std::span<const rsm_view> maps, const interleave_maps& imaps,
                      image_view<glm::vec3> out, indirect_timings& t) {
        t.vpls = options_.count;
        if (maps.empty()) {
            fill_zero(out);
            return;
        }
        // One pattern for every map, sized for the first (maps of one light share a size).
        const std::size_t texels = maps[0].width() * maps[0].height();
        if (full_pattern_.empty() || pattern_texels_ != texels) {
            full_pattern_ = rsm_disc_pattern(options_.count, options_.r_max, texels, options_.seed, options_.disc);
            pattern_texels_ = texels;
        }
        const light_groups g = assign_lights(full_pattern_.size(), imaps.pattern.cells(), light_assignment::interleaved,
                                             {}, options_.shift);
        const auto grouped = grouped_pattern(full_pattern_, g);
        const compensation_totals c = rsm_gather(gb, imaps, maps, grouped, identity_groups(g), options_.light, out,
                                                 options_.energy_correct, occlusion(), compensation());
        add_totals(c, t);
    }

    /// The gather's clamp compensation: active with a positive ray count, a clamp and
    /// visibility rays (each ray's first surface) or none (every surface it crosses).
    gather_compensation compensation() const {
        gather_compensation c;
        if (!compensated(options_)) return c;
        c.every_surface = options_.visibility == indirect_visibility::none;
        c.query = near_field_;
        c.grid = compensation_grid(options_.clamp_compensation_rays);
        c.min_distance2 = options_.light.min_distance2;
        c.seed = options_.seed;
        return c;
    }

    /// Accumulates a gather pass's compensation into the frame's timings.
    void add_totals(const compensation_totals& c, indirect_timings& t) {
        totals_ += c;
        t.compensation_rays = totals_.rays;
        t.compensation_share = totals_.share();
    }

    void shade_splat(const gbuffer_view<float>& gb, const camera& cam, std::span<const rsm_view> maps,
                     const interleave_maps& imaps, image_view<glm::vec3> out, indirect_timings& t,
                     image_view<glm::vec3> stats) {
        // With rays, VPLs chosen by their visible contribution to the view (view_selection.hpp).
        vpls_ = occlusion() && options_.view_selection.enabled()
                    ? select_vpls_for_view(maps, options_, gb, occlusion(), imaps.pattern.cells())
                    : select_vpls(maps, options_);
        t.vpls = vpls_.size();
        fill_zero(out);
        if (!stats.empty()) fill_zero(stats);
        std::vector<glm::vec3> positions;
        if (options_.assignment == light_assignment::similarity)
            for (const auto& l : vpls_) positions.push_back(l.position);
        const light_groups g =
            assign_lights(vpls_.size(), imaps.pattern.cells(), options_.assignment, positions, options_.shift);
        sii_params sp;
        sp.light = options_.light;
        sp.cutoff = options_.sii_cutoff;
        sp.energy_correct = options_.energy_correct;
        const imperfect_shadow_maps* ism = nullptr;
        if (options_.visibility == indirect_visibility::ism) {
            build_ism();
            ism = &ism_;
        }
        splat_vpls(gb, imaps, cam, vpls_, g, sp, out, occlusion(), ism, stats);
    }

    /// The frame's imperfect shadow maps: the point set (count x points_per_vpl points,
    /// kept while neither changes), then the maps of vpls_.
    void build_ism() {
        const ism_params& p = options_.ism;
        const std::size_t total = options_.count * std::size_t(p.points_per_vpl);
        if (ism_points_.size() != total || ism_seed_ != p.seed) {
            ism_points_ = points_->points(total, p.seed);
            ism_seed_ = p.seed;
        }
        ism_.build(vpls_, ism_points_, p, ism_point_spacing(points_->area(), p.points_per_vpl));
    }

    /// The groups of a pattern already reordered by grouped_pattern: run s is
    /// [begin[s], begin[s + 1]) of the reordered list.
    static light_groups identity_groups(const light_groups& g) {
        light_groups id;
        id.begin = g.begin;
        id.order.resize(g.order.size());
        for (std::size_t k = 0; k < id.order.size(); ++k) id.order[k] = std::uint32_t(k);
        return id;
    }

    static void require_occlusion(const indirect_options& o, const occlusion_query* q) {
        if (o.visibility == indirect_visibility::rays && !q)
            throw parameter_error("visibility", "rays needs an occlusion query (embree::occlusion_query) given to the "
                                                "renderer");
    }

    /// Whether `o` asks for the gather's clamp compensation (visibility rays or none).
    static bool compensated(const indirect_options& o) {
        return o.clamp_compensation_rays > 0 &&
               (o.visibility == indirect_visibility::rays || o.visibility == indirect_visibility::none);
    }

    static void require_near_field(const indirect_options& o, const near_field_query* q) {
        if (compensated(o) && o.technique == indirect_technique::rsm_gather && !q)
            throw parameter_error("clamp_compensation_rays", "needs a near_field_query (embree::near_field_rays) "
                                                             "given to the renderer");
    }

    static void require_points(const indirect_options& o, const ism_point_sampler* p) {
        if (o.visibility == indirect_visibility::ism && !p)
            throw parameter_error("visibility", "ism needs the scene's ism_point_sampler given to the renderer");
    }

    /// The query the frame asks: none unless the options ask for rays.
    const occlusion_query* occlusion() const noexcept {
        return options_.visibility == indirect_visibility::rays ? occlusion_ : nullptr;
    }

    static void fill_zero(image_view<glm::vec3> img) {
        for (std::size_t y = 0; y < img.height(); ++y)
            for (auto& px : img.row(y)) px = glm::vec3(0.f);
    }

    indirect_options options_;
    const occlusion_query* occlusion_ = nullptr;
    buffers full_, low_;
    gbuffer<float> low_gb_;
    image<glm::vec3> low_irradiance_;
    std::vector<glm::vec3> full_pattern_;
    std::size_t pattern_texels_ = 0;
    std::vector<vpl> vpls_;
    const ism_point_sampler* points_ = nullptr;
    const near_field_query* near_field_ = nullptr;
    compensation_totals totals_;  // the frame's compensation so far
    std::vector<glm::vec3> ism_points_;
    std::uint64_t ism_seed_ = 0;
    imperfect_shadow_maps ism_;
};

}  // namespace bounce::cpu
