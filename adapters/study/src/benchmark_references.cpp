// The benchmark's references, each in two halves and cached, and each quantity's Monte Carlo
// sweep on the same estimator.
#include <bounce/study/benchmark_parts.hpp>

#include <bounce/embree/multi_bounce_reference.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/embree/rsm_unoccluded_reference.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/study/content_hash.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/image_entry.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/multi_bounce_cache.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/stage_timer.hpp>

#include <glm/geometric.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

namespace bounce::study::bench {

namespace fs = std::filesystem;

namespace {

// The seed every Monte Carlo sweep uses: independent of the references' (1, and the
// halves' hashed seeds), as monte_carlo_at_equal_error's.
constexpr std::uint64_t monte_carlo_seed = 99;

// An estimator's default settings with `spp` samples (the field `count` names) and the
// sweeps' seed.
template <class Settings>
Settings monte_carlo_settings(std::uint32_t Settings::*count, std::uint32_t spp) {
    Settings settings;
    settings.*count = spp;
    settings.seed = monte_carlo_seed;
    return settings;
}

// A row-progress callback that reports at most every five seconds.
std::function<void(std::size_t, std::size_t)> rows_progress(const scene_setup& s, std::string stage) {
    return [&clock = s.clock, stage = std::move(stage), last = std::chrono::steady_clock::now()](std::size_t done,
                                                                                             std::size_t total) mutable {
        if (ms_since(last) < 5000) return;
        last = std::chrono::steady_clock::now();
        clock.report("reference", stage + ": " + std::to_string(done * 100 / std::max<std::size_t>(total, 1)) + "% of the rows");
    };
}

double noise_of(const halves_reference& r, const image<float>& mask) {
    return compare_luminance_debiased(r.mean.view(), r.a.view(), r.b.view(), mask.view()).reference_noise_rel_rms;
}

image<glm::vec3> mean_of(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    image<glm::vec3> m(a.width(), a.height());
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) m(x, y) = 0.5f * (a(x, y) + b(x, y));
    return m;
}

// Halves of `spp` samples in all: each half's sample count.
std::uint32_t half_of(std::uint32_t spp) {
    require(spp >= 2 && spp % 2 == 0, "reference spp", "must be even and at least 2 (two halves)");
    return spp / 2;
}

}  // namespace

std::string halves_cache_key(const scene_setup& s, const std::string& kind, std::uint32_t spp,
                             const std::string& settings_text) {
    fnv1a_hash h;
    h.text("benchmark halves v1");
    hash_scene_view(h, s.scene, s.scene.camera, s.g.width(), s.g.height());
    h.text(kind);
    h.value(spp);
    h.text(settings_text);
    h.text(s.bvh.owner().config());
    return view_cache_key(s.scene.name, s.g.width(), s.g.height(), std::to_string(spp) + "spp-" + kind + "-", h);
}

halves_reference cached_halves(const scene_setup& s, const std::string& key, std::uint32_t spp,
                               const std::function<image<glm::vec3>(int half)>& render) {
    halves_reference r;
    r.spp = spp;
    if (auto images = load_image_entry(s.cache_dir, key, {".a.exr", ".b.exr"}, s.g.width(), s.g.height())) {
        r.a = std::move((*images)[0]);
        r.b = std::move((*images)[1]);
        r.cached = true;
    } else {
        const auto t0 = std::chrono::steady_clock::now();
        r.a = render(0);
        r.b = render(1);
        r.ms = ms_since(t0);
        store_image_entry(s.cache_dir, key, {{".a.exr", &r.a}, {".b.exr", &r.b}},
                          ojson{{"key", key}, {"spp", spp}, {"ms", r.ms}, {"halves", 2}}.dump(2) + "\n");
    }
    r.mean = mean_of(r.a, r.b);
    r.noise_rel_rms = noise_of(r, s.mask);
    return r;
}

halves_reference one_bounce_reference(const scene_setup& s) {
    embree::reference_settings rs;
    rs.hemisphere_samples = s.settings.one_bounce.reference;
    rs.seed = 1;
    rs.progress = rows_progress(s, "one_bounce");
    bool hit = false;
    const auto t0 = std::chrono::steady_clock::now();
    reference_halves h = cached_reference_halves(s.bvh, s.scene, s.scene.camera, s.g.width(), s.g.height(), rs,
                                                 s.cache_dir, &hit);
    halves_reference r;
    r.spp = rs.hemisphere_samples;
    r.cached = hit;
    r.ms = hit ? 0.0 : ms_since(t0);
    r.a = std::move(h.indirect_a);
    r.b = std::move(h.indirect_b);
    r.mean = std::move(h.whole.indirect);
    r.noise_rel_rms = noise_of(r, s.mask);
    return r;
}

halves_reference unoccluded_reference(const scene_setup& s) {
    const std::uint32_t spp = s.settings.unoccluded.reference;
    embree::unoccluded_reference_settings us;
    us.hemisphere_samples = half_of(spp);
    const std::string text = "max_surfaces " + std::to_string(us.max_surfaces) + " seed 1";
    return cached_halves(s, halves_cache_key(s, "unoccluded", spp, text), spp, [&](int half) {
        s.clock.report("reference", "unoccluded, half " + std::string(half == 0 ? "A" : "B"));
        embree::unoccluded_reference_settings h = us;
        h.seed = half_seed(1, half);
        return embree::unoccluded_reference(s.bvh, s.scene, h).indirect_image(s.g.view());
    });
}

halves_reference all_bounces_reference(const scene_setup& s) {
    // Each half is a multi-bounce view of its own seed, cached by the library as radiosity's
    // whole reference is (multi_bounce_cache.hpp; the seed is part of the key).
    halves_reference r;
    r.spp = s.settings.all_bounces.reference;
    embree::multi_bounce_settings ms;
    ms.paths = half_of(r.spp);
    r.cached = true;
    const auto t0 = std::chrono::steady_clock::now();
    for (int half = 0; half < 2; ++half) {
        ms.seed = half_seed(1, half);
        ms.progress = rows_progress(s, std::string("all_bounces, half ") + (half == 0 ? "A" : "B"));
        bool hit = false;
        image<glm::vec3> img = cached_multi_bounce(s.bvh, s.scene, s.scene.camera, s.g.width(), s.g.height(), ms,
                                                   s.cache_dir, &hit)
                                   .radiance;
        r.cached = r.cached && hit;
        (half == 0 ? r.a : r.b) = std::move(img);
    }
    r.ms = r.cached ? 0.0 : ms_since(t0);
    r.mean = mean_of(r.a, r.b);
    r.noise_rel_rms = noise_of(r, s.mask);
    return r;
}

gbuffer<float> volume_points(const scene_setup& s) {
    const gbuffer_view<float> g = s.g.view();
    gbuffer<float> p(g.width(), g.height());
    const float offset = float(s.settings.volume_offset) * s.diagonal;
    const float eps = s.bvh.ray_epsilon();
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) {
            if (!g.covered(x, y)) continue;
            const glm::vec3 q = g.position(x, y), n = g.normal(x, y);
            // As far as `offset` along the normal, but no more than half way to what is there.
            embree::ray r;
            r.origin = q + eps * n;
            r.direction = n;
            r.tfar = offset;
            const embree::hit h = s.bvh.intersect(r);
            const float d = h.found() ? 0.5f * h.t : offset;
            p.position(x, y) = q + d * n;
            p.normal(x, y) = n;
            p.albedo(x, y) = g.albedo(x, y);
            p.depth(x, y) = g.depth(x, y);
        }
    return p;
}

halves_reference volume_points_reference(const scene_setup& s, const gbuffer_view<float>& points) {
    const std::uint32_t spp = s.settings.volume_points.reference;
    const std::string text = "offset " + std::to_string(s.settings.volume_offset) + " seed 1";
    return cached_halves(s, halves_cache_key(s, "volume-points", spp, text), spp, [&](int half) {
        embree::reference_settings rs;
        rs.hemisphere_samples = half_of(spp);
        rs.seed = half_seed(1, half);
        rs.progress = rows_progress(s, std::string("volume_points, half ") + (half == 0 ? "A" : "B"));
        return embree::reference_integrator(s.bvh, s.scene, rs).indirect_image(points);
    });
}

mc_sweep quantity_monte_carlo(const scene_setup& s, bench_quantity q, const halves_reference& ref,
                              const gbuffer_view<float>* points) {
    const std::uint32_t max_spp = s.settings.samples_of(q).mc_max;
    const std::string name(quantity_name(q));
    require(q != bench_quantity::volume_points || points != nullptr, "points",
            "the volume's points are needed for their Monte Carlo");
    const gbuffer_view<float> g = q == bench_quantity::volume_points ? *points : s.g.view();
    const auto before = [&](std::uint32_t spp) { s.clock.report("monte carlo", name + " " + std::to_string(spp) + " spp"); };
    std::function<image<glm::vec3>(std::uint32_t)> render;
    switch (q) {
        case bench_quantity::one_bounce:
        case bench_quantity::volume_points:
            render = [&](std::uint32_t spp) {
                const auto rs = monte_carlo_settings(&embree::reference_settings::hemisphere_samples, spp);
                return embree::reference_integrator(s.bvh, s.scene, rs).indirect_image(g);
            };
            break;
        case bench_quantity::unoccluded:
            render = [&](std::uint32_t spp) {
                const auto us = monte_carlo_settings(&embree::unoccluded_reference_settings::hemisphere_samples, spp);
                return embree::unoccluded_reference(s.bvh, s.scene, us).indirect_image(g);
            };
            break;
        case bench_quantity::all_bounces:
            render = [&](std::uint32_t spp) {
                const auto ms = monte_carlo_settings(&embree::multi_bounce_settings::paths, spp);
                return embree::multi_bounce_reference(s.bvh, s.scene, ms).render(s.scene.camera, g.width(), g.height()).radiance;
            };
            break;
    }
    // The unoccluded estimator needs two samples at least (its stratified grid).
    const std::uint32_t first = q == bench_quantity::unoccluded ? 2 : 1;
    return monte_carlo_sweep(render, ref, s.mask.view(), std::max(first, max_spp), before, first);
}

scene_setup make_scene_setup(const io::scene& scene, const embree::accel& bvh, const benchmark_settings& settings,
                             run_clock& clock) {
    scene_setup s{scene, bvh, settings, clock, {}, {}, 0.f, settings.cache_dir.empty() ? default_cache_dir() : settings.cache_dir};
    s.g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, settings.width, settings.height);
    s.mask = coverage_mask(s.g.view());
    const auto [lo, hi] = scene.bounds();
    s.diagonal = glm::length(hi - lo);
    return s;
}

}  // namespace bounce::study::bench
