// rsm_sii: one-bounce indirect light from reflective shadow maps, by the RSM gather
// (Dachsbacher and Stamminger 2005) or by splatting indirect illumination (Dachsbacher and
// Stamminger 2006), optionally interleaved (Keller and Heidrich 2001; Segovia et al. 2006)
// with energy-correct weights, through the library's cpu::indirect_renderer on maps that
// embree::rsm_ray_caster casts; errors against embree's references with and without
// indirect visibility, and against the same technique without interleaving (Hahn 2012's
// metric).
//
//   build/bin/rsm_sii --scene cornell --technique sii --vpls 1024 --pattern 4x4 --json r.json
//   build/bin/rsm_sii --study --json build/runs/rsm_sii-cornell.json     (Hahn 2012's grid)
//
// timings_ms: rsm (casting the maps, per frame), split, shade, gather, blur, upsample and
// total = split + shade + gather + blur + upsample (the frame after the maps exist, as Hahn
// 2012 section 5.1 times it); medians of --repeat renders.
#include <bounce/cpu/indirect_renderer.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/embree/rsm_ray_cast.hpp>
#include <bounce/embree/rsm_unoccluded_reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/lights.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/study/stage_timer.hpp>
#ifdef BOUNCE_RSM_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/splat_pass.hpp>
#endif

#include "options.hpp"

#include <fmt/core.h>
#include <nlohmann/json.hpp>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

using namespace bounce;
using namespace bounce::examples;
using json = nlohmann::ordered_json;

namespace {

using clock_type = std::chrono::steady_clock;
double ms_since(clock_type::time_point t0) {
    return std::chrono::duration<double, std::milli>(clock_type::now() - t0).count();
}

// ---- the backend, chosen in one place -----------------------------------------------------
// Both backends take the same bounce::indirect_options and report bounce::indirect_timings
// (include/bounce/indirect_options.hpp): a run's options reach either unchanged.

/// Renders one frame of indirect irradiance with the given options into `out`.
class frame_backend {
public:
    virtual ~frame_backend() = default;
    virtual indirect_timings render(const indirect_options& options, image_view<glm::vec3> out) = 0;
    virtual std::string gl_renderer() const { return {}; }
};

/// Whether two option sets make the same frames (a backend keeps its renderer between them).
bool same_frames(const indirect_options& a, const indirect_options& b) {
    return a.technique == b.technique && a.count == b.count && a.pattern.n == b.pattern.n &&
           a.pattern.m == b.pattern.m && a.assignment == b.assignment && a.blur == b.blur &&
           a.energy_correct == b.energy_correct && a.selection == b.selection && a.r_max == b.r_max &&
           a.light.offset == b.light.offset && a.light.min_distance2 == b.light.min_distance2 && a.seed == b.seed &&
           a.shift == b.shift && a.sii_cutoff == b.sii_cutoff && a.low_resolution == b.low_resolution &&
           a.disc == b.disc;
}

/// cpu::indirect_renderer on the ray-cast G-buffer and maps; one renderer per options, so
/// its scratch buffers live across the repeats of a run.
class cpu_backend final : public frame_backend {
public:
    cpu_backend(const gbuffer_view<float>& g, const camera& cam, std::span<const rsm_view> maps)
        : g_(g), cam_(cam), maps_(maps) {}
    indirect_timings render(const indirect_options& options, image_view<glm::vec3> out) override {
        if (!renderer_ || !same_frames(renderer_->options(), options)) renderer_.emplace(options);
        return renderer_->render(g_, cam_, maps_, out);
    }

private:
    gbuffer_view<float> g_;
    camera cam_;
    std::span<const rsm_view> maps_;
    std::optional<cpu::indirect_renderer> renderer_;
};

#ifdef BOUNCE_RSM_WITH_GL
/// gl::indirect_renderer in an EGL context of its own, on the ray-cast G-buffer and maps
/// uploaded as RGBA32F textures (what a GL renderer's own passes would have drawn); the
/// stage times are the GPU's (time_stages: a glFinish after each stage); the read-back of the
/// result is not timed.
class gl_backend final : public frame_backend {
public:
    gl_backend(const gbuffer_view<float>& g, const camera& cam, const std::vector<embree::reflective_shadow_map>& maps)
        : gb_(g), cam_(cam), out_(gl::texel_format::rgba32f, g.width(), g.height()) {
        for (const auto& m : maps) {
            textures_.push_back(upload(m.position));
            textures_.push_back(upload(m.normal));
            textures_.push_back(upload(m.flux));
        }
        for (std::size_t i = 0; i < maps.size(); ++i)
            refs_.push_back({textures_[3 * i], textures_[3 * i + 1], textures_[3 * i + 2], maps[i].light_view_projection});
    }
    indirect_timings render(const indirect_options& o, image_view<glm::vec3> out) override {
        if (!renderer_ || !same_frames(renderer_->options(), o)) {
            renderer_.reset();
            renderer_.emplace(o, /*time_stages=*/true);
        }
        const indirect_timings t = renderer_->render(gb_.textures(), cam_, refs_, out_);
        gl::read_texture(out_, out);
        return t;
    }
    std::string gl_renderer() const override { return context_.renderer(); }

private:
    static gl::texture upload(const image<glm::vec3>& img) {
        gl::texture t(gl::texel_format::rgba32f, img.width(), img.height());
        image<glm::vec4> padded(img.width(), img.height());
        for (std::size_t y = 0; y < img.height(); ++y)
            for (std::size_t x = 0; x < img.width(); ++x) padded(x, y) = glm::vec4(img(x, y), 0.f);
        gl::write_texture(t, padded.view());
        return t;
    }
    gl::context context_;  // first: everything below needs it current
    gl::gbuffer_upload gb_;
    camera cam_;
    gl::texture out_;
    std::vector<gl::texture> textures_;
    std::vector<gl::rsm_textures> refs_;
    std::optional<gl::indirect_renderer> renderer_;
};
#endif

std::unique_ptr<frame_backend> make_backend(const std::string& name, const gbuffer_view<float>& g, const camera& cam,
                                            const embree::rsm_ray_caster& caster) {
    if (name == "cpu") return std::make_unique<cpu_backend>(g, cam, caster.views());
#ifdef BOUNCE_RSM_WITH_GL
    if (name == "gl") return std::make_unique<gl_backend>(g, cam, caster.maps());
#endif
    throw parameter_error("--backend", "'" + name + "': this build has no GL adapter; use --backend cpu");
}

// ---- references --------------------------------------------------------------------------

struct references {
    embree::reference_images full;  ///< with indirect visibility (reference.hpp)
    image<glm::vec3> unoccluded;    ///< without it (rsm_unoccluded_reference.hpp), radiance
    double unoccluded_noise = 0;    ///< its measured relative RMS noise
    std::uint32_t spp = 0;
};

/// The unoccluded reference from the reference cache's folder, or rendered and stored there,
/// keyed like the full reference plus "-unoccluded".
references reference_images(const embree::accel& bvh, const io::scene& scene, const camera& cam,
                            const gbuffer_view<float>& g, std::uint32_t spp) {
    references r;
    r.spp = spp;
    embree::reference_settings rs;
    rs.hemisphere_samples = spp;
    bool hit = false;
    const auto dir = study::default_cache_dir();
    r.full = study::cached_reference(bvh, scene, cam, g.width(), g.height(), rs, dir, &hit);
    fmt::print(stderr, "reference {}x{} at {} spp: {}\n", g.width(), g.height(), spp, hit ? "from cache" : "computed");
    const std::string key =
        study::reference_cache_key(scene, cam, g.width(), g.height(), rs, bvh.owner().config()) + "-unoccluded-v1";
    const auto exr = dir / (key + ".exr"), meta = dir / (key + ".json");
    if (std::filesystem::exists(exr) && std::filesystem::exists(meta)) {
        try {
            image<glm::vec3> img = io::read_rgb(exr);
            const auto m = nlohmann::json::parse(std::ifstream(meta));
            if (img.width() == g.width() && img.height() == g.height()) {
                r.unoccluded = std::move(img);
                r.unoccluded_noise = m.at("noise_rel_rms").get<double>();
                fmt::print(stderr, "unoccluded reference at {} spp: from cache (noise {:.4f})\n", spp, r.unoccluded_noise);
                return r;
            }
        } catch (const std::exception&) {
            // An unreadable entry is recomputed.
        }
    }
    const auto t0 = clock_type::now();
    embree::unoccluded_reference_settings us;
    us.hemisphere_samples = spp;
    auto u = embree::render_unoccluded_reference(bvh, scene, g, us);
    r.unoccluded = std::move(u.indirect);
    r.unoccluded_noise = u.noise_rel_rms;
    fmt::print(stderr, "unoccluded reference at {} spp: computed in {:.1f} s (noise {:.4f})\n", spp,
               ms_since(t0) / 1000.0, r.unoccluded_noise);
    std::filesystem::create_directories(dir);
    io::write_exr(exr, r.unoccluded.view());
    std::ofstream(meta) << json{{"scene", scene.name}, {"width", g.width()}, {"height", g.height()},
                                {"samples", u.samples}, {"noise_rel_rms", u.noise_rel_rms}}
                               .dump(2)
                        << '\n';
    return r;
}

// ---- figures -------------------------------------------------------------------------------

/// Outgoing radiance rho / pi E of the irradiance image (what the references hold).
image<glm::vec3> radiance_of(const gbuffer_view<float>& g, image_view<const glm::vec3> e) {
    image<glm::vec3> out(g.width(), g.height());
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x)
            out(x, y) = lambertian_radiance<float, glm::vec3>(g.albedo(x, y), e(x, y));
    return out;
}

/// Hahn 2012 section 5.2: sum over pixels of the squared difference of intensity
/// 0.2989 R + 0.5870 G + 0.1140 B.
double ssd_intensity(image_view<const glm::vec3> a, image_view<const glm::vec3> b, image_view<const float> mask) {
    double sum = 0;
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) {
            if (mask(x, y) == 0.f) continue;
            const glm::dvec3 d = glm::dvec3(a(x, y)) - glm::dvec3(b(x, y));
            const double i = 0.2989 * d.x + 0.5870 * d.y + 0.1140 * d.z;
            sum += i * i;
        }
    return sum;
}

json error_json(const study::error_figures& e) {
    return {{"rel_rms", e.rel_rms}, {"max_abs", e.max_abs}, {"sum_sq", e.sum_sq}, {"pixels", e.pixels}};
}

/// What one measured run gives.
struct run_result {
    std::string technique;
    std::size_t count = 0;
    interleave_pattern pattern{1, 1};
    bool thesis_weights = false;
    study::stage_timer timer;
    indirect_timings last;
    image<glm::vec3> radiance;
    study::error_figures vs_unoccluded, vs_full;
    std::optional<study::error_figures> vs_plain;
    double plain_ssd = 0;
    double plain_total_ms = 0;
};

std::string pattern_name(interleave_pattern p) { return std::to_string(p.n) + "x" + std::to_string(p.m); }

struct context {
    const options& o;
    gbuffer_view<float> g;
    frame_backend& backend;
    const references& refs;
    image<float> mask;
    float clamp_distance;
    double rsm_ms;
};

run_result measure(context& c, const std::string& technique, std::size_t count, interleave_pattern pattern,
                   bool thesis_weights, const image<glm::vec3>* plain, double plain_total_ms, int repeat) {
    options o = c.o;
    o.thesis_weights = thesis_weights;
    const indirect_options opts = indirect_options_for(o, technique, count, pattern, c.clamp_distance);
    run_result r;
    r.technique = technique;
    r.count = count;
    r.pattern = pattern;
    r.thesis_weights = thesis_weights;
    image<glm::vec3> e(c.g.width(), c.g.height());
    for (int i = 0; i < repeat; ++i) {
        r.timer.add_sample("rsm", c.rsm_ms);
        r.last = c.backend.render(opts, e.view());
        r.timer.add_sample("split", r.last.split_ms);
        r.timer.add_sample("shade", r.last.shade_ms);
        r.timer.add_sample("gather", r.last.gather_ms);
        r.timer.add_sample("blur", r.last.blur_ms);
        r.timer.add_sample("upsample", r.last.upsample_ms);
        r.timer.add_sample("total", r.last.total_ms());
    }
    r.radiance = radiance_of(c.g, e.view());
    r.vs_unoccluded = study::compare_luminance(r.radiance.view(), c.refs.unoccluded.view(), c.mask.view());
    r.vs_full = study::compare_luminance(r.radiance.view(), c.refs.full.indirect.view(), c.mask.view());
    if (plain) {
        r.vs_plain = study::compare_luminance(r.radiance.view(), plain->view(), c.mask.view());
        r.plain_ssd = ssd_intensity(r.radiance.view(), plain->view(), c.mask.view());
        r.plain_total_ms = plain_total_ms;
    }
    fmt::print("{:3} {:5} {:>3} {:5}: total {:9.1f} ms (shade {:9.1f}), rel_rms {:.4f}, occluded {:.4f}", technique,
               count, pattern_name(pattern), thesis_weights ? "thesis" : "", r.timer.median_ms("total"),
               r.timer.median_ms("shade"), r.vs_unoccluded.rel_rms, r.vs_full.rel_rms);
    if (r.vs_plain) fmt::print(", vs plain {:.4f} (ssd {:.4g})", r.vs_plain->rel_rms, r.plain_ssd);
    fmt::print("\n");
    return r;
}

json timings_json(const study::stage_timer& t) {
    json j = json::object();
    for (const auto& s : t.stages()) j[s] = t.median_ms(s);
    return j;
}

json run_json(const run_result& r) {
    json j = {{"technique", r.technique},
              {"vpls", r.count},
              {"pattern", pattern_name(r.pattern)},
              {"energy_correct", !r.thesis_weights},
              {"vpls_used", r.last.vpls},
              {"timings_ms", timings_json(r.timer)},
              {"error", error_json(r.vs_unoccluded)}};
    j["error"]["rel_rms_occluded"] = r.vs_full.rel_rms;
    if (r.vs_plain) {
        j["error"]["vs_plain"] = {{"ssd_intensity", r.plain_ssd}, {"rel_rms", r.vs_plain->rel_rms}};
        j["speedup_vs_plain"] = r.plain_total_ms / r.timer.median_ms("total");
    }
    return j;
}

json parameters_json(const options& o, float clamp_distance, std::size_t maps) {
    return {{"technique", o.technique},     {"vpls", o.vpls},
            {"pattern", o.pattern},         {"assign", o.assign},
            {"selection", o.selection},     {"rsm_resolution", o.rsm_resolution},
            {"maps", maps},                 {"r_max", o.r_max},
            {"clamp", clamp_distance},      {"offset", o.offset},
            {"blur", o.blur},               {"energy_correct", !o.thesis_weights},
            {"seed", o.seed},               {"reference_spp", o.ref_spp}};
}

// ---- the study ------------------------------------------------------------------------------

/// Hahn 2012's grid (section 5: VPLs 64 ... 1024 by patterns none, 2x2, 2x4, 4x4, 8x8, both
/// techniques), plus what the targets need: plain runs at 16, 32 and 4096 (equal-time
/// partners of 8x8 and 4x4 at 1024, and convergence), and SII with the thesis's weight 1.
json run_study(context& c) {
    const std::vector<std::size_t> counts{64, 128, 256, 512, 768, 1024};
    const std::vector<interleave_pattern> patterns{{2, 2}, {2, 4}, {4, 4}, {8, 8}};
    json grid = json::array();
    std::map<std::pair<std::string, std::size_t>, run_result> plain;
    std::map<std::tuple<std::string, std::size_t, int, int>, run_result> inter;
    for (const std::string technique : {"rsm", "sii"}) {
        for (std::size_t k : {16, 32}) grid.push_back(run_json(measure(c, technique, k, {1, 1}, false, nullptr, 0, c.o.repeat)));
        for (std::size_t k : counts) {
            run_result p = measure(c, technique, k, {1, 1}, false, nullptr, 0, c.o.repeat);
            grid.push_back(run_json(p));
            for (const auto& pat : patterns) {
                run_result r = measure(c, technique, k, pat, false, &p.radiance, p.timer.median_ms("total"), c.o.repeat);
                grid.push_back(run_json(r));
                inter.emplace(std::make_tuple(technique, k, pat.n, pat.m), std::move(r));
            }
            plain.emplace(std::make_pair(technique, k), std::move(p));
        }
        grid.push_back(run_json(measure(c, technique, 4096, {1, 1}, false, nullptr, 0, 1)));
        if (technique == "sii")
            for (std::size_t k : {128ul, 1024ul})
                grid.push_back(run_json(measure(c, technique, k, {4, 4}, true, &plain.at({technique, k}).radiance,
                                                plain.at({technique, k}).timer.median_ms("total"), c.o.repeat)));
    }
    // The targets, from this one run.
    auto total = [](const run_result& r) { return r.timer.median_ms("total"); };
    const auto& rsm88 = inter.at({"rsm", 1024, 8, 8});
    const auto& sii88 = inter.at({"sii", 1024, 8, 8});
    const auto& sii44_1024 = inter.at({"sii", 1024, 4, 4});
    const auto& sii44_128 = inter.at({"sii", 128, 4, 4});
    const auto& rsm44_1024 = inter.at({"rsm", 1024, 4, 4});
    json targets;
    targets["rsm_speedup_8x8_1024"] = total(plain.at({"rsm", 1024})) / total(rsm88);
    targets["sii_speedup_8x8_1024"] = total(plain.at({"sii", 1024})) / total(sii88);
    targets["sii_vs_plain_rel_rms_4x4"] = {{"128", sii44_128.vs_plain->rel_rms}, {"1024", sii44_1024.vs_plain->rel_rms}};
    targets["sii_vs_plain_ssd_4x4"] = {{"128", sii44_128.plain_ssd}, {"1024", sii44_1024.plain_ssd}};
    targets["sii_over_rsm_vs_plain_rel_rms_4x4_1024"] = sii44_1024.vs_plain->rel_rms / rsm44_1024.vs_plain->rel_rms;
    targets["sii_over_rsm_vs_plain_ssd_4x4_1024"] = sii44_1024.plain_ssd / rsm44_1024.plain_ssd;
    for (const auto& j : grid)
        if (j["vpls"] == 4096) targets[j["technique"].get<std::string>() + "_rel_rms_plain_4096"] = j["error"]["rel_rms"];
    // Equal time: each interleaved run against the plain run with N M times fewer lights.
    json equal = json::array();
    for (const auto& [key, r] : inter) {
        const auto& [technique, k, n, m] = key;
        const std::size_t fewer = k / std::size_t(n * m);
        const run_result* partner = nullptr;
        if (plain.count({technique, fewer})) partner = &plain.at({technique, fewer});
        if (!partner) {
            for (const auto& j : grid)
                if (j["technique"] == technique && j["vpls"] == fewer && j["pattern"] == "1x1") {
                    equal.push_back({{"technique", technique}, {"vpls", k}, {"pattern", pattern_name(r.pattern)},
                                     {"total_ms", total(r)}, {"rel_rms", r.vs_unoccluded.rel_rms},
                                     {"plain_vpls", fewer}, {"plain_total_ms", j["timings_ms"]["total"]},
                                     {"plain_rel_rms", j["error"]["rel_rms"]}});
                    break;
                }
            continue;
        }
        equal.push_back({{"technique", technique}, {"vpls", k}, {"pattern", pattern_name(r.pattern)},
                         {"total_ms", total(r)}, {"rel_rms", r.vs_unoccluded.rel_rms}, {"plain_vpls", fewer},
                         {"plain_total_ms", total(*partner)}, {"plain_rel_rms", partner->vs_unoccluded.rel_rms}});
    }
    targets["equal_time"] = equal;
    return {{"grid", grid}, {"targets", targets}};
}

// ---- the program ------------------------------------------------------------------------------

int run(const options& o) {
    const interleave_pattern pattern = parse_pattern(o.pattern);
    for (const auto& p : {o.json, o.out, o.indirect_out})
        if (!p.empty() && p.has_parent_path())
            require(std::filesystem::is_directory(p.parent_path()), "--json/--out/--indirect-out",
                    ("folder of '" + p.string() + "' does not exist").c_str());
    if (o.study) require(!o.json.empty(), "--study", "needs --json for the study's report");
    const io::scene scene = io::load_scene_arg(o.scene);
    for (const auto& w : scene.warnings) fmt::print(stderr, "{}: {}\n", scene.name, w);
    require(!scene.lights.empty(), "--scene",
            "has no point, spot or directional light: reflective shadow maps need one");
    const embree::accel bvh(scene);
    const camera& cam = scene.camera;
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, cam, o.width, o.height);
    const float clamp_distance =
        o.clamp >= 0.f ? o.clamp : 0.01f * glm::length(scene.bounds().second - scene.bounds().first);
    require(std::isfinite(clamp_distance), "--clamp", "must be finite");
    // Checks the options before the references take minutes.
    (void)indirect_options_for(o, o.technique, o.vpls, pattern, clamp_distance);

    embree::rsm_ray_cast_settings rs;
    rs.resolution = o.rsm_resolution;
    embree::rsm_ray_caster caster(bvh, scene, rs);
    study::stage_timer rsm_timer;
    for (int i = 0; i < std::max(3, o.repeat); ++i) rsm_timer.time("rsm", [&] { caster.render(); });
    const double rsm_ms = rsm_timer.median_ms("rsm");
    fmt::print(stderr, "{} maps of {}^2 texels cast in {:.1f} ms\n", caster.maps().size(), o.rsm_resolution, rsm_ms);

    auto backend = make_backend(o.backend, g.view(), cam, caster);
    const references refs = reference_images(bvh, scene, cam, g.view(), o.ref_spp);
    context c{o, g.view(), *backend, refs, study::coverage_mask(g.view()), clamp_distance, rsm_ms};

    study::run_report report;
    report.technique = o.study ? "rsm_sii_study" : "rsm_sii";
    report.scene = scene.name;
    report.width = o.width;
    report.height = o.height;
    report.backend = o.backend;
    report.gl_renderer = backend->gl_renderer();
    report.parameters = parameters_json(o, clamp_distance, caster.maps().size());
    report.parameters["embree_config"] = bvh.owner().config();
    json extra = json::object();
    extra["references"] = {{"spp", refs.spp},
                           {"unoccluded_noise_rel_rms", refs.unoccluded_noise},
                           {"occluded_vs_unoccluded_rel_rms",
                            study::compare_luminance(refs.full.indirect.view(), refs.unoccluded.view(), c.mask.view()).rel_rms}};

    std::optional<run_result> single;
    if (o.study) {
        report.repeat = std::size_t(o.repeat);
        extra.update(run_study(c));
    } else {
        std::optional<run_result> plain;
        if (pattern.cells() > 1) plain = measure(c, o.technique, o.vpls, {1, 1}, false, nullptr, 0, o.repeat);
        single = measure(c, o.technique, o.vpls, pattern, o.thesis_weights, plain ? &plain->radiance : nullptr,
                         plain ? plain->timer.median_ms("total") : 0, o.repeat);
        report.set_timings(single->timer);
        report.error = single->vs_unoccluded;
        report.set_count("vpls", single->last.vpls);
        report.set_count("maps", caster.maps().size());
        const json r = run_json(*single);
        extra["error_extra"] = r["error"];
        if (r.contains("speedup_vs_plain")) extra["speedup_vs_plain"] = r["speedup_vs_plain"];
    }

    if (single && (!o.out.empty() || !o.indirect_out.empty())) {
        if (!o.out.empty()) {
            image<glm::vec3> combined(o.width, o.height);
            for (std::size_t y = 0; y < o.height; ++y)
                for (std::size_t x = 0; x < o.width; ++x) combined(x, y) = refs.full.direct(x, y) + single->radiance(x, y);
            io::write_png(o.out, combined.view(), io::auto_exposure(combined.view(), c.mask.view()));
        }
        if (!o.indirect_out.empty()) {
            // The technique's indirect light beside the unoccluded reference, one exposure.
            image<glm::vec3> pair(2 * o.width, o.height);
            for (std::size_t y = 0; y < o.height; ++y)
                for (std::size_t x = 0; x < o.width; ++x) {
                    pair(x, y) = single->radiance(x, y);
                    pair(o.width + x, y) = refs.unoccluded(x, y);
                }
            io::write_png(o.indirect_out, pair.view(), io::auto_exposure(refs.unoccluded.view(), c.mask.view()));
        }
    }

    if (!o.json.empty()) {
        json j = report.to_json();
        if (j.contains("error") && extra.contains("error_extra")) {
            j["error"]["rel_rms_occluded"] = extra["error_extra"]["rel_rms_occluded"];
            if (extra["error_extra"].contains("vs_plain")) j["error"]["vs_plain"] = extra["error_extra"]["vs_plain"];
        }
        extra.erase("error_extra");
        for (auto it = extra.begin(); it != extra.end(); ++it) j[it.key()] = it.value();
        std::ofstream(o.json) << j.dump(2) << '\n';
    }
    return 0;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce: reflective shadow maps, splatting indirect illumination and interleaved sampling (Hahn 2012)"};
    options o;
    add_options(app, o);
    CLI11_PARSE(app, argc, argv);
    try {
        return run(o);
    } catch (const bounce::error& e) {
        fmt::print(stderr, "rsm_sii: {}\n", e.what());
        return 2;
    }
}
