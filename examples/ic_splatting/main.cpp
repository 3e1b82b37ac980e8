// ic_splatting: irradiance caching by splatting (seed 000, Algorithm 5), its classical
// octree baseline, and the figures that compare them against the reference integrator.
//
//   build/bin/ic_splatting --scene cornell --width 512 --height 512 --a 0.15
//       --weight ward-smooth --gradients on --interp splat-cpu --json ic.json --out ic.png
//
// Stages (the names of timings_ms): gbuffer, splat_existing (step 2), scan (step 4 minus
// record computation), compute_records, interpolate (making the indirect image from the
// cache: the final splat of step 5, or the octree's lookups), normalize, total.
#include <bounce/cpu/batched_scan.hpp>
#include <bounce/cpu/neighbour_index.hpp>
#include <bounce/cpu/octree_cache.hpp>
#include <bounce/cpu/splatting.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/record_cache.hpp>
#include <bounce/io/report.hpp>
#include <bounce/io/scene.hpp>
#ifdef BOUNCE_IC_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#include <bounce/gl/splat_pass.hpp>
#endif

#include <CLI/CLI.hpp>
#include "../common/cli_number_checks.hpp"
#include <fmt/core.h>
#include <glm/gtc/quaternion.hpp>

#include <chrono>
#include <functional>
#include <cmath>
#include <algorithm>
#include <filesystem>
#include <fstream>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bounce;

namespace {

using clock_type = std::chrono::steady_clock;
double ms_since(clock_type::time_point t0) {
    return std::chrono::duration<double, std::milli>(clock_type::now() - t0).count();
}

struct options {
    std::string scene = "cornell";
    std::size_t width = 512, height = 512;
    float a = 0.15f;
    std::string weight = "ward-smooth";
    bool gradients = true;
    std::string sampler = "embree";
    float falloff_kappa = 1.f;  // raster sampler: fall-off stretching's band factor (1: border stretching)
    double plane_turn = 0.0;    // raster sampler: plane_camera::turn_deg
    bool hashed_turn = false;   // raster sampler: plane_camera::hashed_turn
    int shadow_resolution = 2048;  // GL: texels per side of the shadow maps (raster records, GL frames' direct light)
    std::string interp = "splat-cpu";
    std::size_t progressive = 0;  // records per frame; 0: two-pass quality mode
    float fill_holes = 4.f;       // progressive: wide splat's a / a (0: leave holes black)
    std::size_t frames = 8;
    std::vector<float> a_sweep;
    std::uint32_t record_samples = 1024, ref_spp = 1024;
    float min_pixels = 1.5f, max_pixels = 64.f;
    bool neighbour_clamp = false;
    std::string scan = "batched";
    std::string scan_order;  // linear | coarse-to-fine; empty: linear, coarse-to-fine when progressive
    std::size_t scan_batch = 0;
    bool gradient_limit = true;
    float max_extrapolation = 1.f;
    float front_tolerance = 1.f;
    float min_weight = 0.f;  // 0: a, as the seed's Eq. 8.8
    int repeat = 1;
    bool mc_compare = false;
    fs::path json, out, exr, indirect_out, indirect_exr, cache_in, cache_out;
};

weighting_kind parse_weight(const std::string& w) {
    if (w == "ward") return weighting_kind::ward;
    if (w == "ward-smooth") return weighting_kind::ward_smooth;
    if (w == "ward-gpu") return weighting_kind::ward_gpu;
    if (w == "ward-gpu-shader") return weighting_kind::ward_gpu_shader;
    if (w == "tabellion") return weighting_kind::tabellion;
    throw parameter_error("--weight", "unknown weighting function '" + w + "'");
}

// Everything a frame needs that does not change with a or the camera.
struct context {
    const options& opt;
    const io::scene& scene;
    const embree::accel& bvh;
    const embree::reference_integrator& integrator;
    /// The record sampler (Embree rays or the GL plane rasterizer): a record at (p, n).
    std::function<std::optional<irradiance_record>(glm::vec3, glm::vec3, double)> sampler;
    /// The records so far for --neighbour-clamp (null when off); mirrors `records`.
    cpu::neighbour_index* clamp = nullptr;
    /// The sampler's batch form (the GL raster sampler: one atlas per batch); when empty,
    /// batches are measured with `sampler` in parallel (Embree: thread-safe). Both samplers
    /// are pure functions of the point, so the scans may measure records ahead.
    std::function<void(std::span<const glm::vec3>, std::span<const glm::vec3>, std::span<const double>,
                       std::span<std::optional<irradiance_record>>)>
        batch_sampler{};
    cpu::scan_batch batch{};
    std::vector<std::uint32_t> order{};  // the cache-miss scan's pixel order; empty: row by row
};

// The parameters records depend on (not a: records are valid for every a). falloff_kappa
// and the plane's turn keep their defaults unless the raster sampler takes them (run()
// refuses them with the Embree sampler).
nlohmann::json cache_parameters(const options& o, const io::scene& s) {
    return {{"scene", s.name},         {"sampler", o.sampler},           {"record_samples", o.record_samples},
            {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
            {"shadow_resolution", o.sampler == "raster" ? o.shadow_resolution : 0},  // the raster's records see the maps
            {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels}, {"neighbour_clamp", o.neighbour_clamp},
            {"gradient_limit", o.gradient_limit}, {"height", o.height}};
}

// One frame of the chosen interpolation for `cam`: Algorithm 5 with the splat buffer, or
// the classical two passes with the octree. `records` grows with the new records.
struct frame_result {
    gbuffer<float> g;                      // what the frame saw
    image<glm::vec3> indirect;             // rho/pi * E from the cache
    std::optional<image<glm::vec3>> combined;  // direct + indirect, when the backend composed it
    std::size_t new_records = 0;
    std::size_t measured = 0, wasted = 0;  // batched scan: records measured, guesses dropped
};

// What a batched scan reports: its records, the wall time of its measuring, its guesses.
void take_scan_stats(const cpu::scan_stats& stats, frame_result& fr, double& record_ms) {
    fr.new_records = stats.created;
    record_ms = stats.measure_ms;
    fr.measured = stats.measured;
    fr.wasted = stats.wasted;
}

cpu::splat_params splat_params_for(const options& o, float a) {
    cpu::splat_params sp;
    sp.a = a;
    sp.gradients = o.gradients;
    sp.max_extrapolation = o.max_extrapolation;
    sp.front_tolerance = o.front_tolerance;
    return sp;
}

// A record at pixel (x, y): the sampler at its point, with the pixel footprint for radius
// clamps.
auto record_measurer(const context& ctx, const camera& cam, const gbuffer<float>& g) {
    return [&ctx, &cam, &g](std::size_t x, std::size_t y) {
        return ctx.sampler(g.position(x, y), g.normal(x, y), cam.pixel_footprint(g.depth(x, y), g.height()));
    };
}

// Records for a batch of pixels (the batched scans' guesses): one call of the batch sampler,
// or the per-point sampler on the worker threads.
auto record_batch_measurer(const context& ctx, const camera& cam, const gbuffer<float>& g) {
    return [&ctx, &cam, &g](std::span<const cpu::pixel_xy> px, std::span<std::optional<irradiance_record>> out) {
        if (ctx.batch_sampler) {
            std::vector<glm::vec3> p(px.size()), n(px.size());
            std::vector<double> footprint(px.size());
            for (std::size_t k = 0; k < px.size(); ++k) {
                p[k] = g.position(px[k].x, px[k].y);
                n[k] = g.normal(px[k].x, px[k].y);
                footprint[k] = cam.pixel_footprint(g.depth(px[k].x, px[k].y), g.height());
            }
            ctx.batch_sampler(p, n, footprint, out);
            return;
        }
        const auto one = record_measurer(ctx, cam, g);
        tbb::parallel_for(std::size_t(0), px.size(), [&](std::size_t k) { out[k] = one(px[k].x, px[k].y); });
    };
}

// What a new record owes to the records before it, applied in scan order: neighbour clamping.
auto record_committer(const context& ctx, const std::vector<irradiance_record>& records) {
    return [&ctx, &records](irradiance_record& rec) {
        if (!ctx.clamp) return;
        ctx.clamp->sync(records);
        rec.radius = ctx.clamp->clamped_radius(rec);
    };
}

// The sequential scans' record-creation callback: measure then commit, adding the time to
// `record_ms`.
auto record_creator(const context& ctx, const camera& cam, const gbuffer<float>& g,
                    const std::vector<irradiance_record>& records, double& record_ms) {
    return [measure = record_measurer(ctx, cam, g), commit = record_committer(ctx, records),
            &record_ms](std::size_t x, std::size_t y) -> std::optional<irradiance_record> {
        const auto t0 = clock_type::now();
        auto rec = measure(x, y);
        if (rec) commit(*rec);
        record_ms += ms_since(t0);
        return rec;
    };
}

// Step 4 over a splat buffer, for the CPU and GL backends alike: the batched scan (guesses
// measured together) or the sequential one; sets fr's record counts, adds to record_ms.
// `record_g`: where the records of missed pixels are measured (the scanned G-buffer `g`
// itself, or for GL frames the sampler's own view of the same pixels, record_points_for).
template <class W>
void scan_splat_buffer(const context& ctx, const camera& cam, gbuffer<float>& g, const gbuffer<float>& record_g,
                       const cpu::splat_params& sp, float min_weight, std::vector<irradiance_record>& records,
                       image_view<glm::vec4> splat, std::size_t max_new, frame_result& fr, double& record_ms) {
    if (ctx.opt.scan == "batched") {
        const auto stats = cpu::scan_cache_misses_batched<W>(g.view(), cam, sp, min_weight,
                                                             record_batch_measurer(ctx, cam, record_g),
                                                             record_committer(ctx, records), records, splat, ctx.batch,
                                                             ctx.order, max_new);
        take_scan_stats(stats, fr, record_ms);
    } else {
        fr.new_records = cpu::scan_cache_misses<W>(g.view(), cam, sp, min_weight,
                                                   record_creator(ctx, cam, record_g, records, record_ms), records,
                                                   splat, ctx.order, max_new);
    }
}

// Whether two G-buffers see the same surface at a pixel: points within 1e-4 of the scene's
// size and normals within 2.6 degrees (the error mask of GL frames uses the same test).
bool same_surface(const gbuffer<float>& g, const gbuffer<float>& h, std::size_t x, std::size_t y, float scene_size) {
    return std::isfinite(g.depth(x, y)) && std::isfinite(h.depth(x, y)) &&
           glm::length(g.position(x, y) - h.position(x, y)) <= 1e-4f * scene_size &&
           glm::dot(g.normal(x, y), h.normal(x, y)) >= 0.999f;
}

// CPU backends: splat-cpu (Algorithm 5 on the CPU) and octree / octree-lanes (the classical
// two passes, the records evaluated one or four at a time).
frame_result render_frame(const context& ctx, const camera& cam, gbuffer<float> g_in, float a,
                          std::vector<irradiance_record>& records, io::stage_timer& timer, std::size_t max_new) {
    const gbuffer<float>& g = g_in;
    const options& o = ctx.opt;
    const cpu::splat_params sp = splat_params_for(o, a);
    const float min_weight = o.min_weight > 0.f ? o.min_weight : a;
    const auto gv = g_in.view();

    double record_ms = 0;
    frame_result fr;
    fr.indirect = image<glm::vec3>(g.width(), g.height());
    image<glm::vec4> splat(g.width(), g.height(), glm::vec4(0.f));
    const bool fill_holes = max_new != std::size_t(-1) && o.fill_holes > 0.f;
    std::optional<image<glm::vec4>> wide;  // hole filling's wide splat
    with_weighting(parse_weight(o.weight), [&](auto w) {
        using W = decltype(w);
        if (o.interp.starts_with("octree")) {
            // Classical: the tree depends on a, so it is built for this frame's a.
            const auto [lo, hi] = ctx.scene.bounds();
            cpu::octree_cache<W> tree(lo, hi, sp);
            {
                auto t = timer.measure("splat_existing");  // (re)inserting existing records
                for (const auto& r : records) tree.insert(r);
            }
            const auto t0 = clock_type::now();
            // The classical fill: the same driver as the splat scan; --scan sequential makes it
            // one record at a time (a batch of one guesses nothing).
            cpu::scan_batch batch = ctx.batch;
            if (o.scan == "sequential") batch.max_records = 1;
            const glm::mat4 view = cam.view_matrix();
            const auto stats = cpu::batched_scan(
                g.width(), g.height(), ctx.order, max_new, batch,
                [&](std::size_t x, std::size_t y) {
                    return gv.covered(x, y) && tree.lookup(g.position(x, y), g.normal(x, y), g.albedo(x, y)).w < min_weight;
                },
                record_batch_measurer(ctx, cam, g), record_committer(ctx, records), [&](const irradiance_record& rec) {
                    records.push_back(rec);
                    tree.insert(rec);
                    const float zone = W::template influence_radius<float>(rec.radius, a);
                    return cpu::guess_spacing(cpu::splat_rect(cam, view, rec.position, zone, g.width(), g.height()));
                });
            take_scan_stats(stats, fr, record_ms);
            timer.add_sample("scan", ms_since(t0) - record_ms);
            timer.add_sample("compute_records", record_ms);
            auto t = timer.measure("interpolate");
            tree.render(gv, splat.view(), o.interp == "octree-lanes" ? cpu::octree_evaluation::lanes
                                                                      : cpu::octree_evaluation::scalar);
        } else {
            {
                auto t = timer.measure("splat_existing");
                cpu::splat_records<W>(gv, cam, records, sp, splat.view());
            }
            const auto t0 = clock_type::now();
            scan_splat_buffer<W>(ctx, cam, g_in, g_in, sp, min_weight, records, splat.view(), max_new, fr, record_ms);
            timer.add_sample("scan", ms_since(t0) - record_ms);
            timer.add_sample("compute_records", record_ms);
            // Step 5: the image comes from splatting every record (on the GPU in the seed).
            auto t = timer.measure("interpolate");
            std::fill(splat.data(), splat.data() + splat.width() * splat.height(), glm::vec4(0.f));
            cpu::splat_records<W>(gv, cam, records, sp, splat.view());
            if (fill_holes) {
                // A budget left pixels uncovered: the same records again with zones fill x wider.
                cpu::splat_params wide_sp = sp;
                wide_sp.a = a * o.fill_holes;
                wide = image<glm::vec4>(g.width(), g.height(), glm::vec4(0.f));
                cpu::splat_records<W>(gv, cam, records, wide_sp, wide->view());
            }
        }
    });
    {
        auto t = timer.measure("normalize");
        if (wide) cpu::normalize_splats(splat.view(), wide->view(), 1e-3f, fr.indirect.view());
        else cpu::normalize_splats(splat.view(), fr.indirect.view());
    }
    fr.g = std::move(g_in);
    return fr;
}

#ifdef BOUNCE_IC_WITH_GL
// Everything the GL backend keeps across frames: context, mesh, passes, and how many
// records the GPU copy of the cache holds.
struct gl_backend {
    gl::context gl_context;
    gl::scene_mesh mesh;
    gl::gbuffer_pass gbuffer;
    gl::direct_light light;
    gl::splat_pass splats;
    gl::compose_pass compose;
    std::size_t on_gpu = 0;
    gl::splat_pass wide_splats;  // progressive hole filling: the same records, wider a
    std::size_t wide_on_gpu = 0;

    std::optional<gl::hemisphere_raster> raster;  // the record sampler, for --sampler raster

    gl_backend(const io::scene& s, int shadow_resolution) : mesh(s), light(s, mesh, shadow_resolution) {}
};

// Where a GL frame's records are measured. The Embree sampler starts its rays at its own
// hit of the pixel's camera ray, where that is the surface the raster saw: the rasterized
// point is only within about 1e-6 of the triangle, and at a contact line (a gallery's
// underside meeting a wall) that is enough to put the ray origin inside the touching solid,
// whose record then sees a closed hemisphere. Elsewhere (silhouettes, where the two see
// different surfaces), and for the raster sampler, the raster's own point is kept.
gbuffer<float> record_points_for(const context& ctx, const camera& cam, const gbuffer<float>& g) {
    gbuffer<float> out = g;
    if (ctx.opt.sampler != "embree") return out;
    const gbuffer<float> ray = embree::ray_cast_gbuffer(ctx.bvh, ctx.scene, cam, g.width(), g.height());
    const float scene_size = glm::length(ctx.scene.bounds().second - ctx.scene.bounds().first);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            if (same_surface(g, ray, x, y, scene_size)) {
                out.position(x, y) = ray.position(x, y);
                out.normal(x, y) = ray.normal(x, y);
                out.depth(x, y) = ray.depth(x, y);
            }
    return out;
}

// Algorithm 5 as the seed runs it: G-buffer, direct light and splatting on the GPU, the
// cache-miss scan on the CPU over the read-back splat buffer.
frame_result render_frame_gl(const context& ctx, gl_backend& gb, const camera& cam, float a,
                             std::vector<irradiance_record>& records, io::stage_timer& timer, std::size_t max_new) {
    const options& o = ctx.opt;
    const cpu::splat_params sp = splat_params_for(o, a);
    const weighting_kind kind = parse_weight(o.weight);
    const bool fill_holes = max_new != std::size_t(-1) && o.fill_holes > 0.f;
    frame_result fr;
    {  // step 1
        auto t = timer.measure("gbuffer");
        gb.gbuffer.render(gb.mesh, cam, o.width, o.height);
        gl::finish();
    }
    const gl::gbuffer_textures tex = gl::textures_of(gb.gbuffer);
    {
        auto t = timer.measure("direct");
        gb.light.render(tex);
        gl::finish();
    }
    image<glm::vec4> splat(o.width, o.height);
    {  // step 2: the records the GPU already holds
        auto t = timer.measure("splat_existing");
        if (gb.on_gpu < records.size()) gb.splats.append(std::span(records).subspan(gb.on_gpu));
        gb.on_gpu = records.size();
        gb.splats.clear(o.width, o.height);
        gb.splats.splat(tex, cam, sp, kind);
        gl::finish();
    }
    {  // step 3
        auto t = timer.measure("readback");
        fr.g = gb.gbuffer.read();
        gb.splats.read_splat(splat.view());
    }
    const std::size_t before = records.size();
    {  // step 4
        double record_ms = 0;
        const auto t0 = clock_type::now();
        const float min_weight = o.min_weight > 0.f ? o.min_weight : a;
        const auto t_points = clock_type::now();
        const gbuffer<float> record_g = record_points_for(ctx, cam, fr.g);
        record_ms += ms_since(t_points);
        with_weighting(kind, [&](auto w) {
            scan_splat_buffer<decltype(w)>(ctx, cam, fr.g, record_g, sp, min_weight, records, splat.view(), max_new, fr,
                                           record_ms);
        });
        timer.add_sample("scan", ms_since(t0) - record_ms);
        timer.add_sample("compute_records", record_ms);
    }
    {  // step 5: upload the new records and splat them on top of step 2's buffer
        auto t = timer.measure("interpolate");
        gb.splats.append(std::span(records).subspan(before));
        gb.on_gpu = records.size();
        gb.splats.splat(tex, cam, sp, kind, before);
        if (fill_holes) {
            // A budget left pixels uncovered: every record again with zones fill x wider.
            if (gb.wide_on_gpu < records.size()) gb.wide_splats.append(std::span(records).subspan(gb.wide_on_gpu));
            gb.wide_on_gpu = records.size();
            gb.wide_splats.clear(o.width, o.height);
            gl::splat_params wide_sp = sp;
            wide_sp.a *= o.fill_holes;
            gb.wide_splats.splat(tex, cam, wide_sp, kind);
        }
        gl::finish();
    }
    {
        auto t = timer.measure("normalize");
        fr.indirect = image<glm::vec3>(o.width, o.height);
        fr.combined = image<glm::vec3>(o.width, o.height);
        const gl::texture* wide = fill_holes ? &gb.wide_splats.splat_texture() : nullptr;
        gb.compose.compose(gb.splats.splat_texture(), nullptr, wide, 1e-3f);
        gb.compose.read(fr.indirect.view());
        gb.compose.compose(gb.splats.splat_texture(), &gb.light.radiance(), wide, 1e-3f);
        gb.compose.read(fr.combined->view());
    }
    return fr;
}
#endif

image<float> coverage_mask(const gbuffer<float>& g) {
    image<float> m(g.width(), g.height(), 0.f);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) m(x, y) = std::isfinite(g.depth(x, y)) ? 1.f : 0.f;
    return m;
}

// The pixels where a frame's G-buffer (the raster one, for the GL backend) sees the same
// surface as the ray-cast G-buffer the reference was computed on: elsewhere (a few
// silhouette pixels) the two images show different surfaces and their difference is
// not the cache's error.
image<float> comparable_mask(const gbuffer<float>& g, const gbuffer<float>& ref_g, float scene_size) {
    image<float> m = coverage_mask(g);
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            if (m(x, y) > 0.f && !same_surface(g, ref_g, x, y, scene_size)) m(x, y) = 0.f;
    return m;
}

// The progressive mode's camera path: from the scene's camera, a walk forward along the
// view axis (a tenth of the way to the target, and never more than half the way to the first
// surface on the axis) while the view pans from -10 to +10 degrees about the up axis, so the
// eye stays in the open space it starts in. (An orbit about the target, the first path, swung
// Sponza's eye 3 m sideways through the colonnade: frames saw one column face from
// centimetres away, and their errors told nothing about the cache.)
struct camera_path {
    camera base;
    glm::vec3 forward;
    float walk;  // world units the eye moves over the whole path
    std::size_t frames;

    camera_path(const embree::accel& bvh, const camera& start, std::size_t frame_count)
        : base(start), forward(start.forward()), frames(frame_count) {
        const embree::hit first = bvh.intersect({base.position, forward});  // t = inf on a miss
        walk = std::min(0.1f * glm::length(base.look_at - base.position), 0.5f * first.t);
    }

    camera at(std::size_t f) const {
        const float t = float(f) / float(std::max<std::size_t>(1, frames - 1));
        camera cam = base;
        cam.position = base.position + t * walk * forward;
        const glm::quat pan = glm::angleAxis(glm::radians(20.f) * (t - 0.5f), glm::normalize(base.up));
        cam.look_at = cam.position + pan * (base.look_at - cam.position);
        return cam;
    }
};

nlohmann::ordered_json error_json(const io::error_figures& e) {
    return {{"rel_rms", e.rel_rms}, {"max_abs", e.max_abs}, {"sum_sq", e.sum_sq}, {"pixels", e.pixels}};
}

embree::reference_settings reference_settings_for(std::uint32_t spp, std::uint64_t seed) {
    embree::reference_settings s;
    s.hemisphere_samples = spp;
    s.seed = seed;
    return s;
}

int run(const options& o) {
    if (o.falloff_kappa != 1.f && o.sampler != "raster")
        throw parameter_error("--falloff-kappa", "applies to --sampler raster only");
    if ((o.plane_turn != 0.0 || o.hashed_turn) && o.sampler != "raster")
        throw parameter_error("--plane-turn/--hashed-turn", "apply to --sampler raster only");
    io::stage_timer setup;
    const io::scene scene = io::load_scene_arg(o.scene);
    std::optional<embree::accel> bvh_storage;
    setup.time("bvh", [&] { bvh_storage.emplace(scene); });
    const embree::accel& bvh = *bvh_storage;
    const embree::reference_integrator integrator(bvh, scene, reference_settings_for(64, 1));
    radius_limits limits;
    limits.min_pixels = o.min_pixels;
    limits.max_pixels = o.max_pixels;
    limits.gradient_limit = o.gradient_limit;
    embree::record_sampler embree_sampler(integrator, embree::hemisphere_grid_for(o.record_samples), limits);
    context ctx{o, scene, bvh, integrator, std::ref(embree_sampler)};
    ctx.batch.max_records = o.scan_batch;
    const std::string scan_order = !o.scan_order.empty() ? o.scan_order : (o.progressive > 0 ? "coarse-to-fine" : "linear");
    if (scan_order == "coarse-to-fine") ctx.order = cpu::coarse_to_fine_order(o.width, o.height);
    cpu::neighbour_index clamp_index(scene.bounds().first, scene.bounds().second);
    if (o.neighbour_clamp) ctx.clamp = &clamp_index;
    std::vector<irradiance_record> records;

#ifdef BOUNCE_IC_WITH_GL
    std::optional<gl_backend> gl_state;
    if (o.interp == "splat-gl" || o.sampler == "raster")
        setup.time("gl_setup", [&] { gl_state.emplace(scene, o.shadow_resolution); });
    std::optional<gl::raster_record_sampler> raster_sampler;
    if (o.sampler == "raster") {
        // Records from 64 x 64 planes of 126 degrees with border stretching (seed 8.4), or
        // fall-off stretching with a fixed kappa (docs/hemisphere-sampling.md).
        // One atlas per batch of the scan's guesses (16 planes unless --scan-batch says).
        const std::size_t planes = o.scan_batch > 0 ? o.scan_batch : 16;
        gl_state->raster.emplace(scene, gl_state->mesh, gl_state->light,
                                 gl::hemisphere_raster_options{{64, 126.0, o.plane_turn, o.hashed_turn}, planes});
        raster_sampler.emplace(*gl_state->raster, limits,
                               o.falloff_kappa < 1.f ? plane_weighting::falloff : plane_weighting::stretch,
                               double(o.falloff_kappa));
        ctx.sampler = [&](glm::vec3 p, glm::vec3 n, double fp) { return (*raster_sampler)(p, n, fp); };
        ctx.batch_sampler = [&](std::span<const glm::vec3> p, std::span<const glm::vec3> n, std::span<const double> fp,
                                std::span<std::optional<irradiance_record>> out) { (*raster_sampler)(p, n, fp, out); };
        ctx.batch.max_records = planes;
    }
    const bool gl_frames = o.interp == "splat-gl";
#else
    if (o.sampler != "embree")
        throw parameter_error("--sampler", "'raster' needs the GL adapter, which this build does not have");
    if (o.interp == "splat-gl")
        throw parameter_error("--interp", "'splat-gl' needs the GL adapter, which this build does not have");
#endif
    // One frame for `cam` with the chosen backend; the G-buffer is part of its timing.
    auto frame = [&](const camera& cam, float a, io::stage_timer& t, std::size_t max_new) -> frame_result {
#ifdef BOUNCE_IC_WITH_GL
        if (gl_frames) return render_frame_gl(ctx, *gl_state, cam, a, records, t, max_new);
#endif
        gbuffer<float> g;
        t.time("gbuffer", [&] { g = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height); });
        return render_frame(ctx, cam, std::move(g), a, records, t, max_new);
    };

    const nlohmann::json cache_params = cache_parameters(o, scene);
    if (!o.cache_in.empty()) records = io::load_records(o.cache_in, cache_params);
    const std::size_t loaded = records.size();

    io::run_report report;
    report.technique = "ic_splatting";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = o.interp.starts_with("octree") ? "cpu-" + o.interp : o.interp == "splat-gl" ? "gl" : "cpu";
    report.parameters = {{"a", o.a}, {"weight", o.weight}, {"gradients", o.gradients}, {"sampler", o.sampler},
                         {"falloff_kappa", o.falloff_kappa}, {"plane_turn", o.plane_turn}, {"hashed_turn", o.hashed_turn},
                         {"shadow_resolution", o.shadow_resolution},
                         {"interp", o.interp}, {"record_samples", o.record_samples}, {"reference_spp", o.ref_spp},
                         {"min_pixels", o.min_pixels}, {"max_pixels", o.max_pixels},
                         {"neighbour_clamp", o.neighbour_clamp}, {"gradient_limit", o.gradient_limit},
                         {"max_extrapolation", o.max_extrapolation},
                         {"front_tolerance", o.front_tolerance},
                         {"min_weight", o.min_weight > 0.f ? o.min_weight : o.a}, {"progressive", o.progressive},
                         {"fill_holes", o.progressive > 0 ? o.fill_holes : 0.f},
                         {"scan", o.scan}, {"scan_batch", ctx.batch.max_records}, {"scan_order", scan_order},
                         {"embree_config", bvh.owner().config()}};

    auto reference_for = [&](const camera& cam) {
        bool hit = false;
        auto ref = study::cached_reference(bvh, scene, cam, o.width, o.height, reference_settings_for(o.ref_spp, 1),
                                            study::default_cache_dir(), &hit);
        fmt::print(stderr, "reference {}x{} at {} spp: {}\n", o.width, o.height, o.ref_spp, hit ? "from cache" : "computed");
        return ref;
    };

    // Error is measured where the frame's G-buffer sees what the reference saw.
    const float scene_size = glm::length(scene.bounds().second - scene.bounds().first);
    auto mask_for = [&](const gbuffer<float>& g, const camera& cam) {
        if (o.interp != "splat-gl") return coverage_mask(g);
        return comparable_mask(g, embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height), scene_size);
    };

    nlohmann::ordered_json extra = nlohmann::ordered_json::object();
    io::stage_timer timer;

    if (o.progressive > 0) {
        // Progressive mode: records are view-independent, so each frame of the camera path
        // reuses the cache and adds at most N records.
        nlohmann::ordered_json frames = nlohmann::ordered_json::array();
        const camera_path path(bvh, scene.camera, o.frames);
        for (std::size_t f = 0; f < o.frames; ++f) {
            const camera cam = path.at(f);
            io::stage_timer ft;
            const auto t0 = clock_type::now();
            const auto fr = frame(cam, o.a, ft, o.progressive);
            const double frame_ms = ms_since(t0);
            const auto ref = reference_for(cam);
            const auto err = io::compare_luminance(fr.indirect.view(), ref.indirect.view(), mask_for(fr.g, cam).view());
            fmt::print("frame {:2}: {:5} records (+{:3}), {:8.1f} ms ({:5.2f} fps), indirect rel_rms {:.4f}\n", f,
                       records.size(), fr.new_records, frame_ms, 1000.0 / frame_ms, err.rel_rms);
            frames.push_back({{"frame", f}, {"records", records.size()}, {"new_records", fr.new_records},
                              {"ms", frame_ms}, {"fps", 1000.0 / frame_ms}, {"rel_rms", err.rel_rms}});
            for (const auto& s : ft.stages()) timer.add_sample(s, ft.median_ms(s));
            timer.add_sample("total", frame_ms);
        }
        extra["frames"] = frames;
        report.set_timings(timer);
        report.set_count("records", records.size());
    } else {
        const camera& cam = scene.camera;
        const auto ref = reference_for(cam);
        frame_result fr;
        const std::vector<float> as = o.a_sweep.empty() ? std::vector<float>{o.a} : o.a_sweep;
        nlohmann::ordered_json sweep = nlohmann::ordered_json::array();
        image<float> mask;
        for (float a : as) {
            io::stage_timer at;
            // Each repeat starts from the same cache: what was loaded, or what earlier
            // sweep entries built (records are valid for every a).
            const std::vector<irradiance_record> start = records;
            for (int r = 0; r < o.repeat; ++r) {
                records = start;
#ifdef BOUNCE_IC_WITH_GL
                if (gl_frames) {  // the GPU copy restarts from the same cache
                    gl_state->splats.upload(records);
                    gl_state->on_gpu = records.size();
                }
#endif
                const auto t0 = clock_type::now();
                fr = frame(cam, a, at, std::size_t(-1));
                at.add_sample("total", ms_since(t0));
            }
            mask = mask_for(fr.g, cam);
            const auto err = io::compare_luminance(fr.indirect.view(), ref.indirect.view(), mask.view());
            fmt::print("a = {:.3f}: {:6} records (+{:5}), total {:9.1f} ms (interpolate {:8.2f}, records {:9.1f}), "
                       "indirect rel_rms {:.4f}\n",
                       a, records.size(), fr.new_records, at.median_ms("total"), at.median_ms("interpolate"),
                       at.median_ms("compute_records"), err.rel_rms);
            nlohmann::ordered_json entry = {{"a", a}, {"records", records.size()}, {"new_records", fr.new_records},
                                            {"timings_ms", nlohmann::ordered_json::object()}, {"error", error_json(err)}};
            for (const auto& s : at.stages()) entry["timings_ms"][s] = at.median_ms(s);
            sweep.push_back(entry);
            timer = at;
            report.error = err;
        }
        if (!o.a_sweep.empty()) extra["a_sweep"] = sweep;
        report.set_timings(timer);
        report.set_count("records", records.size());
        if (fr.measured > 0) {
            // The batched scan's guesses: measured, and dropped because covered by then.
            report.set_count("records_measured", fr.measured);
            report.set_count("records_wasted", fr.wasted);
        }

        if (o.mc_compare) {
            // Brute-force Monte Carlo indirect light at doubling sample counts (an independent
            // seed), until its error reaches this run's: the time it needs at equal error.
            nlohmann::ordered_json mc = nlohmann::ordered_json::array();
            const double target = report.error->rel_rms;
            for (std::uint32_t spp = 1; spp <= o.ref_spp / 2; spp *= 2) {
                const embree::reference_integrator mci(bvh, scene, reference_settings_for(spp, 99));
                const auto t0 = clock_type::now();
                const auto ind = mci.indirect_image(fr.g.view());
                const double ms = ms_since(t0);
                const auto err = io::compare_luminance(ind.view(), ref.indirect.view(), mask.view());
                fmt::print("monte carlo {:4} spp: {:9.1f} ms, indirect rel_rms {:.4f}\n", spp, ms, err.rel_rms);
                mc.push_back({{"spp", spp}, {"ms", ms}, {"rel_rms", err.rel_rms}});
                if (err.rel_rms <= target) {
                    // The sample count that reaches the target exactly, interpolating the last
                    // two points in log-log (error ~ spp^-1/2 away from the reference's floor),
                    // and its time (proportional to spp): doubling alone would overstate it.
                    double equal_spp = spp, equal_ms = ms;
                    if (mc.size() >= 2) {
                        const auto& prev = mc[mc.size() - 2];
                        const double s1 = prev["spp"].get<double>(), e1 = prev["rel_rms"].get<double>();
                        const double t = (std::log(target) - std::log(e1)) / (std::log(err.rel_rms) - std::log(e1));
                        equal_spp = std::exp(std::log(s1) + t * (std::log(double(spp)) - std::log(s1)));
                        equal_ms = ms * equal_spp / spp;
                    }
                    const double speedup = equal_ms / timer.median_ms("total");
                    extra["mc_equal_error"] = {{"spp", equal_spp}, {"ms", equal_ms}, {"rel_rms", target},
                                               {"measured_spp", spp}, {"measured_ms", ms},
                                               {"measured_rel_rms", err.rel_rms}, {"speedup", speedup}};
                    fmt::print("at equal error Monte Carlo needs ~{:.0f} spp, {:.1f} ms: {:.1f}x the cache's {:.1f} ms\n",
                               equal_spp, equal_ms, speedup, timer.median_ms("total"));
                    break;
                }
            }
            if (!extra.contains("mc_equal_error") && !mc.empty()) {
                // Monte Carlo did not reach the cache's error below half the reference's
                // samples (beyond that it would be measured against its own kind of noise):
                // its last time is a lower bound on the time it needs.
                const double ms = mc.back()["ms"].get<double>();
                extra["mc_equal_error"] = {{"rel_rms", target}, {"lower_bound", true},
                                           {"measured_spp", mc.back()["spp"]}, {"measured_ms", ms},
                                           {"measured_rel_rms", mc.back()["rel_rms"]},
                                           {"speedup", ms / timer.median_ms("total")}};
                fmt::print("Monte Carlo stays above the cache's error up to {} spp ({:.1f} ms): at least {:.1f}x the cache's time\n",
                           mc.back()["spp"].get<int>(), ms, ms / timer.median_ms("total"));
            }
            extra["mc_sweep"] = mc;
        }

        if (!o.out.empty() || !o.exr.empty()) {
            image<glm::vec3> combined(o.width, o.height);
            if (fr.combined) combined = *fr.combined;
            else cpu::compose(ref.direct.view(), fr.indirect.view(), combined.view());
            if (!o.exr.empty()) io::write_exr(o.exr, combined.view());
            if (!o.out.empty()) io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), mask.view()));
        }
        if (!o.indirect_exr.empty()) io::write_exr(o.indirect_exr, fr.indirect.view());
        if (!o.indirect_out.empty()) {
            // The indirect images side by side with one exposure: the cache's, the reference's.
            image<glm::vec3> pair(2 * o.width, o.height);
            for (std::size_t y = 0; y < o.height; ++y)
                for (std::size_t x = 0; x < o.width; ++x) {
                    pair(x, y) = fr.indirect(x, y);
                    pair(o.width + x, y) = ref.indirect(x, y);
                }
            io::write_png(o.indirect_out, pair.view(), io::auto_exposure(ref.indirect.view(), mask.view()));
        }
    }

    if (!o.cache_out.empty()) io::save_records(o.cache_out, records, cache_params);
    if (loaded) report.set_count("records_loaded", loaded);
    fmt::print("{} records; total {:.1f} ms", records.size(), timer.median_ms("total"));
    if (report.error) fmt::print("; indirect rel_rms {:.4f}", report.error->rel_rms);
    fmt::print("\n");
    if (!o.json.empty()) {
        auto j = report.to_json();
        j["timings_ms"]["bvh"] = setup.median_ms("bvh");
        for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
        std::ofstream(o.json) << j.dump(2) << '\n';
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: irradiance caching by splatting (Gautron, SIGGRAPH 2008 course, ch. 8)"};
    options o;
    std::string gradients = "on";
    app.add_option("--scene", o.scene, "cornell, a scene.json, its folder, an .obj, or a name under the scenes folder")->capture_default_str();
    app.add_option("--width", o.width, "image width")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--height", o.height, "image height")->check(CLI::Range(1, 16384))->capture_default_str();
    app.add_option("--a", o.a, "accuracy a (Eq. 8.3); smaller means more records")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--weight", o.weight, "ward | ward-smooth | ward-gpu | ward-gpu-shader | tabellion")
        ->check(CLI::IsMember({"ward", "ward-smooth", "ward-gpu", "ward-gpu-shader", "tabellion"}))->capture_default_str();
    app.add_option("--gradients", gradients, "on | off")->check(CLI::IsMember({"on", "off"}))->capture_default_str();
    app.add_option("--sampler", o.sampler, "record sampler: embree | raster")->check(CLI::IsMember({"embree", "raster"}))->capture_default_str();
    app.add_option("--falloff-kappa", o.falloff_kappa,
                   "raster sampler: fall-off stretching with this band factor (hemisphere_study's falloff_kappa for the "
                   "scene); 1: border stretching")
        ->check(examples::unit_interval)
        ->capture_default_str();
    app.add_option("--plane-turn", o.plane_turn,
                   "raster sampler: turn of every plane about its normal from orthonormal_basis(n), degrees in [0, 90)")
        ->check(examples::quarter_turn_deg)
        ->capture_default_str();
    app.add_flag("--hashed-turn", o.hashed_turn,
                 "raster sampler: also turn each plane by its own angle in [0, 90) degrees, hashed from its point");
    app.add_option("--shadow-resolution", o.shadow_resolution,
                   "GL: texels per side of the shadow maps (raster sampler's records, splat-gl's direct light)")
        ->check(CLI::Range(64, 8192))
        ->capture_default_str();
    app.add_option("--interp", o.interp,
                   "splat-cpu | splat-gl | octree (classical, one record at a time) | octree-lanes (four at a time)")
        ->check(CLI::IsMember({"splat-cpu", "splat-gl", "octree", "octree-lanes"}))->capture_default_str();
    app.add_option("--progressive", o.progressive, "at most N new records per frame over a camera path (0: two-pass quality mode)");
    app.add_option("--fill-holes", o.fill_holes,
                   "progressive: fill pixels no zone reaches from a splat with a this many times wider (0: off)")
        ->check(examples::finite_non_negative)
        ->capture_default_str();
    app.add_option("--frames", o.frames, "frames of the progressive camera path")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--a-sweep", o.a_sweep, "comma-separated a values rendered from one growing cache")
        ->delimiter(',')
        ->check(examples::finite_positive);
    app.add_option("--record-samples", o.record_samples, "hemisphere rays per record")->check(CLI::Range(4u, 1u << 20))->capture_default_str();
    app.add_option("--ref-spp", o.ref_spp, "reference integrator samples per pixel")->check(CLI::Range(1u, 1u << 20))->capture_default_str();
    app.add_option("--min-pixels", o.min_pixels, "record radius at least this many pixel footprints")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--max-pixels", o.max_pixels, "record radius at most this many pixel footprints")->check(examples::finite_positive)->capture_default_str();
    app.add_option("--scan", o.scan, "batched: measure records ahead in parallel (same result); sequential: one at a time")
        ->check(CLI::IsMember({"batched", "sequential"}))
        ->capture_default_str();
    app.add_option("--scan-order", o.scan_order,
                   "cache-miss scan order: linear | coarse-to-fine (default: linear; coarse-to-fine when progressive)")
        ->check(CLI::IsMember({"linear", "coarse-to-fine"}));
    app.add_option("--scan-batch", o.scan_batch, "records measured together by the batched scan (0: one per thread; 16 planes per atlas for --sampler raster)")
        ->check(CLI::Range(0, 4096))
        ->capture_default_str();
    app.add_flag("--neighbour-clamp", o.neighbour_clamp, "clamp radii to neighbours (R_i <= R_j + |p_i - p_j|)");
    app.add_flag("!--no-gradient-limit", o.gradient_limit, "do not limit R by E / |grad_t E|");
    app.add_option("--max-extrapolation", o.max_extrapolation, "gradient term clamped to this times E_k")->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--front-tolerance", o.front_tolerance,
                   "skip records whose tangent plane the point lies this fraction of the zone behind (Ward's in-front test; 1: off)")
        ->check(examples::unit_interval)->capture_default_str();
    app.add_option("--min-weight", o.min_weight, "cache-miss threshold on the weight sum (default: a, the seed's Eq. 8.8)")->check(examples::finite_non_negative);
    app.add_option("--repeat", o.repeat, "repeats per measurement (timings are medians)")->check(CLI::Range(1, 1000))->capture_default_str();
    app.add_flag("--mc-compare", o.mc_compare, "also time brute-force Monte Carlo indirect light at equal error");
    app.add_option("--json", o.json, "write the run report here");
    app.add_option("--out", o.out, "write the final image (direct + indirect) as PNG");
    app.add_option("--exr", o.exr, "write the final image as EXR");
    app.add_option("--indirect-out", o.indirect_out, "write the indirect image beside the reference's as PNG");
    app.add_option("--indirect-exr", o.indirect_exr, "write the indirect image alone as EXR (linear, for error maps)");
    app.add_option("--cache-in", o.cache_in, "start from the records saved in this file");
    app.add_option("--cache-out", o.cache_out, "save the records to this file");
    CLI11_PARSE(app, argc, argv);
    o.gradients = gradients == "on";
    try {
        return run(o);
    } catch (const bounce::error& e) {
        fmt::print(stderr, "ic_splatting: {}\n", e.what());
        return 2;
    }
}
