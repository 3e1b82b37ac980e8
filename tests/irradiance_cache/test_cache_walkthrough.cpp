// The cache's frame loops as library functions: cpu::render_frame and cpu::walkthrough must
// give exactly what calling the cache frame by frame gives (the grown cache, and the fresh
// frames from an empty one); gl::irradiance_splatter::frame must make the CPU frame's records
// on its own G-buffer and follow a cache whose records were replaced without being told.
// Then the study side (bounce::study's cache studies): error reports, the walkthrough's
// bookkeeping and the a sweep, on the built-in Cornell box at 32 x 32.
#include <bounce/cpu/cache_walkthrough.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/study/cache_study.hpp>
#include <bounce/study/camera_path.hpp>
#include <bounce/study/frame_comparison.hpp>
#include <bounce/study/noisy_error_report.hpp>
#ifdef BOUNCE_WITH_GL
#include "../gl/shared_context.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#endif

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <limits>
#include <vector>

#include <unistd.h>

using namespace bounce;

namespace {

constexpr std::size_t width = 32, height = 32;

struct box_fixture {
    io::scene scene = io::cornell_box();
    embree::accel bvh{scene};
    embree::reference_integrator integrator{bvh, scene, {}};
    radius_limits limits{};
    embree::record_sampler sampler{integrator, embree::hemisphere_grid_for(64), limits};
    study::camera_path path{bvh, scene.camera, 4};

    gbuffer<float> ray_cast(const camera& cam) const { return embree::ray_cast_gbuffer(bvh, scene, cam, width, height); }
    cpu::irradiance_cache<ward_smooth_weight> cache() const {
        cpu::irradiance_cache_options o;
        o.splat.a = 0.3f;
        o.neighbour_clamp = true;  // the per-frame clamp of earlier frames' records is part of the loop
        const auto [lo, hi] = scene.bounds();
        return cpu::irradiance_cache<ward_smooth_weight>(lo, hi, o);
    }
};

box_fixture& fixture() {
    static box_fixture f;
    return f;
}

bool same_records(const std::vector<irradiance_record>& a, const std::vector<irradiance_record>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(irradiance_record)) == 0;
}

bool same_image(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    return a.width() == b.width() && a.height() == b.height() &&
           std::memcmp(a.data(), b.data(), a.width() * a.height() * sizeof(glm::vec3)) == 0;
}

// The cache rendered camera by camera by hand: each frame's image and the records after it.
struct by_hand {
    std::vector<image<glm::vec3>> images;
    std::vector<std::vector<irradiance_record>> records;
    std::vector<std::size_t> new_records;
};

by_hand frames_by_hand(box_fixture& f) {
    by_hand h;
    auto cache = f.cache();
    for (std::size_t k = 0; k < f.path.frames(); ++k) {
        const camera cam = f.path.at(k);
        gbuffer<float> g = f.ray_cast(cam);
        image<glm::vec3> indirect(width, height);
        const auto stats = cache.render(g.view(), cam, f.sampler, indirect.view(), output_quantity::radiance);
        h.new_records.push_back(stats.new_records);
        h.images.push_back(std::move(indirect));
        h.records.push_back(cache.records());
    }
    return h;
}

// A temporary reference cache folder for the study tests, removed at the end.
struct temp_cache {
    std::filesystem::path dir =
        std::filesystem::temp_directory_path() / ("bounce-test-cache-study-" + std::to_string(::getpid()));
    ~temp_cache() {
        std::error_code ec;
        std::filesystem::remove_all(dir, ec);
    }
};

study::cache_study_settings study_settings(const temp_cache& t) {
    study::cache_study_settings s;
    s.width = width;
    s.height = height;
    s.reference_spp = 16;
    s.mc_max_spp = 8;
    s.cache_dir = t.dir;
    s.log = nullptr;
    return s;
}

}  // namespace

TEST_CASE("render_frame is the cache's render on the G-buffer made for the camera, stage by stage",
          "[irradiance_cache][walkthrough]") {
    auto& f = fixture();
    const camera& cam = f.scene.camera;
    auto a = f.cache();
    const cache_frame frame = cpu::render_frame(a, cam, [&](const camera& c) { return f.ray_cast(c); }, f.sampler);

    auto b = f.cache();
    gbuffer<float> g = f.ray_cast(cam);
    image<glm::vec3> indirect(width, height);
    const auto stats = b.render(g.view(), cam, f.sampler, indirect.view(), output_quantity::radiance);

    CHECK(same_image(frame.indirect, indirect));
    CHECK(same_records(a.records(), b.records()));
    CHECK(frame.new_records == stats.new_records);
    CHECK(frame.new_records > 0);
    CHECK(frame.measured == stats.measured);
    CHECK(frame.g.width() == width);
    CHECK_FALSE(frame.combined);
    std::vector<std::string> names;
    for (const auto& [name, ms] : frame.stages_ms) {
        names.push_back(name);
        CHECK(ms >= 0.0);
    }
    CHECK(names == std::vector<std::string>{"gbuffer", "splat_existing", "scan", "compute_records", "interpolate",
                                            "normalize"});
    CHECK(frame.ms("nothing") == 0.0);
}

TEST_CASE("a walkthrough's frames are the cache's frames camera by camera, with or without fresh twins",
          "[irradiance_cache][walkthrough]") {
    auto& f = fixture();
    const by_hand h = frames_by_hand(f);
    REQUIRE(h.records.back().size() > h.records.front().size());  // the cache grows along the path

    for (const bool fresh : {false, true}) {
        CAPTURE(fresh);
        auto cache = f.cache();
        std::vector<cpu::walkthrough_step> steps;
        cpu::walkthrough(cache, f.path, [&](const camera& c) { return f.ray_cast(c); }, f.sampler,
                         cpu::walkthrough_options{fresh}, [&](cpu::walkthrough_step&& s) {
                             // The cache the step left: its records are the grown ones, fresh or not.
                             CHECK(same_records(cache.records(), h.records[s.index]));
                             steps.push_back(std::move(s));
                         });
        REQUIRE(steps.size() == f.path.frames());
        for (std::size_t k = 0; k < steps.size(); ++k) {
            CAPTURE(k);
            const auto& s = steps[k];
            CHECK(s.index == k);
            CHECK(s.cam.position == f.path.at(k).position);
            CHECK(same_image(s.frame.indirect, h.images[k]));
            CHECK(s.frame.new_records == h.new_records[k]);
            CHECK(s.records == h.records[k].size());
            CHECK(s.ms > 0.0);
            CHECK(s.fresh.has_value() == fresh);
            if (!fresh) continue;
            // The fresh twin is the camera rendered by a new cache.
            auto empty = f.cache();
            gbuffer<float> g = f.ray_cast(s.cam);
            image<glm::vec3> indirect(width, height);
            empty.render(g.view(), s.cam, f.sampler, indirect.view(), output_quantity::radiance);
            CHECK(same_image(s.fresh->indirect, indirect));
            CHECK(s.fresh_records == empty.records().size());
        }
    }
}

TEST_CASE("a walkthrough verifies every frame of a cache with the pass and a probe, and keeps the pass's records",
          "[irradiance_cache][walkthrough][verification]") {
    auto& f = fixture();
    // The pass as ic_splatting runs it by default (two rounds, 8-ray probes), with a test loose
    // enough (k = 1, no floor on the frame's scale) that tiles disagree on 32 x 32 pixels.
    const embree::irradiance_probe probe(f.integrator, 8);
    const auto verified_cache = [&] {
        auto c = f.cache();
        auto o = c.options();
        o.verify = {2, 4, 1.f, 0.f};
        c.set_options(o);
        c.set_probe(std::cref(probe));
        return c;
    };
    // By hand: the cache's render camera by camera, with the pass.
    auto hand = verified_cache();
    std::vector<image<glm::vec3>> images;
    std::vector<std::vector<irradiance_record>> records;
    std::vector<cpu::cache_frame_stats> stats;
    for (std::size_t k = 0; k < f.path.frames(); ++k) {
        const camera cam = f.path.at(k);
        gbuffer<float> g = f.ray_cast(cam);
        image<glm::vec3> indirect(width, height);
        stats.push_back(hand.render(g.view(), cam, f.sampler, indirect.view(), output_quantity::radiance));
        images.push_back(std::move(indirect));
        records.push_back(hand.records());
    }
    auto cache = verified_cache();
    std::size_t disagreed = 0;
    cpu::walkthrough(cache, f.path, [&](const camera& c) { return f.ray_cast(c); }, f.sampler, {},
                     [&](cpu::walkthrough_step&& s) {
                         const std::size_t k = s.index;
                         CAPTURE(k);
                         CHECK(same_image(s.frame.indirect, images[k]));
                         CHECK(same_records(cache.records(), records[k]));
                         // Every frame ran the pass (both rounds over every tile) and says so.
                         CHECK(s.frame.verify_tiles == stats[k].verify_tiles);
                         CHECK(s.frame.verify_tiles >= 2 * (width / 4) * (height / 4));
                         CHECK(s.frame.verify_disagreed == stats[k].verify_disagreed);
                         CHECK(s.frame.verify_shrunk == stats[k].verify_shrunk);
                         CHECK(s.frame.reclamped == stats[k].reclamped);
                         CHECK(s.frame.ms("verify") > 0.0);
                         disagreed += s.frame.verify_disagreed;
                         // The records of the frames before are kept (radii may shrink, nothing moves).
                         if (k > 0)
                             for (std::size_t i = 0; i < records[k - 1].size(); ++i)
                                 CHECK(cache.records()[i].position == records[k - 1][i].position);
                     });
    REQUIRE(disagreed > 0);
    // The pass's records change the walk: a cache without it ends elsewhere.
    const by_hand plain = frames_by_hand(f);
    CHECK(cache.records().size() != plain.records.back().size());
}

TEST_CASE("the cache's generation changes when its records are replaced or shrunk, and only then",
          "[irradiance_cache][walkthrough]") {
    auto& f = fixture();
    auto cache = f.cache();
    const auto g0 = cache.generation();
    image<glm::vec3> indirect(width, height);
    gbuffer<float> g = f.ray_cast(f.scene.camera);
    cache.render(g.view(), f.scene.camera, f.sampler, indirect.view());
    CHECK(cache.generation() == g0);  // appended records keep the generation
    const auto kept = cache.records();
    cache.assign(kept);
    CHECK(cache.generation() == g0 + 1);
    // A record far larger than its neighbours allow is shrunk by the next clamp.
    auto big = kept;
    big[0].radius *= 1000.f;
    cache.assign(big);
    const auto g1 = cache.generation();
    CHECK(cache.clamp_to_neighbours() > 0);
    CHECK(cache.generation() == g1 + 1);
    CHECK(cache.clamp_to_neighbours() == 0);
    CHECK(cache.generation() == g1 + 1);
}

TEST_CASE("the walkthrough's study measures each frame against its own reference", "[study][walkthrough]") {
    auto& f = fixture();
    const temp_cache t;
    const study::cache_frame_study measure(f.bvh, f.scene, study_settings(t));
    study::walkthrough_report report(measure, f.path.frames(), 2);
    study::stage_timer timer;
    auto cache = f.cache();
    std::vector<study::noisy_error> by_hand_errors;
    cpu::walkthrough(cache, f.path, [&](const camera& c) { return f.ray_cast(c); }, f.sampler,
                     cpu::walkthrough_options{true}, [&](cpu::walkthrough_step&& s) {
                         report.add(s, timer);
                         const auto ref = measure.reference(s.cam);
                         by_hand_errors.push_back(
                             study::measure_error(s.frame.indirect.view(), ref, study::coverage_mask(s.frame.g.view()).view()));
                     });
    const auto j = report.json();
    REQUIRE(j["frames"].size() == f.path.frames());
    CHECK(j["frames_count"] == f.path.frames());
    double sum = 0;
    for (std::size_t k = 0; k < f.path.frames(); ++k) {
        CAPTURE(k);
        const auto& e = j["frames"][k];
        CHECK(e["rel_rms"].get<double>() == by_hand_errors[k].raw.rel_rms);
        CHECK(e["rel_rms_debiased"].get<double>() == by_hand_errors[k].debiased.rel_rms_debiased);
        CHECK(e.contains("fresh"));
        CHECK(e.contains("mc_equal_error") == (k % 2 == 0));  // every second frame
        sum += by_hand_errors[k].raw.rel_rms;
    }
    CHECK(j["mean_rel_rms"].get<double>() == Approx(sum / double(f.path.frames())));
    CHECK(j["mc_equal_error"]["frames_measured"].get<std::size_t>() +
              j["mc_equal_error"]["frames_skipped"].get<std::size_t>() ==
          2);
    CHECK(timer.samples("total").size() == f.path.frames());
    REQUIRE(report.last());
    CHECK(report.last()->frame.new_records == j["frames"][f.path.frames() - 1]["new_records"].get<std::size_t>());
    CHECK(report.mean_reference_noise() > 0.0);
}

TEST_CASE("an a sweep renders each a from the records before it, repeat after repeat", "[study][walkthrough]") {
    auto& f = fixture();
    const temp_cache t;
    const study::cache_frame_study measure(f.bvh, f.scene, study_settings(t));
    const camera& cam = f.scene.camera;
    const auto ray_cast = [&](const camera& c) { return f.ray_cast(c); };
    auto cache = f.cache();
    const std::vector<float> as{0.4f, 0.2f};
    const auto frame = [&](const camera& c) { return cpu::render_frame(cache, c, ray_cast, f.sampler); };
    const study::a_sweep_result r = study::a_sweep(cache, std::span(as), 2, cam, frame, measure);

    // By hand: a = 0.4 from nothing, then a = 0.2 from its records.
    auto hand = f.cache();
    for (const float a : as) {
        auto o = hand.options();
        o.splat.a = a;
        hand.set_options(o);
        gbuffer<float> g = f.ray_cast(cam);
        image<glm::vec3> indirect(width, height);
        hand.render(g.view(), cam, f.sampler, indirect.view(), output_quantity::radiance);
        if (a == as.back()) CHECK(same_image(r.last.frame.indirect, indirect));
    }
    CHECK(same_records(cache.records(), hand.records()));
    REQUIRE(r.entries.size() == 2);
    CHECK(r.entries[1]["a"].get<float>() == 0.2f);
    CHECK(r.entries[1]["records"].get<std::size_t>() == hand.records().size());
    CHECK(r.timer.samples("total").size() == 2);  // the repeats of the last a
    CHECK(r.entries[1]["error"]["rel_rms"].get<double>() == r.last.error.raw.rel_rms);
    const std::vector<float> none;
    CHECK_THROWS_AS(study::a_sweep(cache, std::span(none), 1, cam, frame, measure), parameter_error);
    CHECK_THROWS_AS(study::a_sweep(cache, std::span(as), 0, cam, frame, measure), parameter_error);
}

TEST_CASE("the noisy-error report: JSON keys, nulls for infinities, resolved and unresolved text", "[study]") {
    CHECK(study::finite_or_null(std::numeric_limits<double>::infinity()).is_null());
    CHECK(study::finite_or_null(0.5).get<double>() == 0.5);
    study::noisy_error e;
    e.raw.rel_rms = 0.0312;
    e.debiased.rel_sq_debiased = 0.0290 * 0.0290;
    e.debiased.rel_sq_debiased_se = 1e-5;
    e.debiased.rel_rms_debiased = 0.0290;
    e.debiased.rel_rms_debiased_se = 0.0011;
    e.debiased.reference_noise_rel_rms = std::numeric_limits<double>::infinity();
    REQUIRE(e.debiased.resolved());
    CHECK(study::error_text(e) == "0.0312 (debiased 0.0290 +- 0.0011)");
    CHECK(e.target(study::error_measure::raw) == 0.0312);
    CHECK(e.target(study::error_measure::debiased) == 0.0290);
    const auto j = study::error_json(e);
    std::vector<std::string> keys;
    for (auto it = j.begin(); it != j.end(); ++it) keys.push_back(it.key());
    CHECK(keys == std::vector<std::string>{"rel_rms", "max_abs", "sum_sq", "pixels", "rel_rms_debiased",
                                           "rel_rms_debiased_se", "rel_sq_debiased", "rel_sq_debiased_se",
                                           "debiased_resolved", "reference_noise_rel_rms"});
    CHECK(j["reference_noise_rel_rms"].is_null());
    e.debiased.rel_sq_debiased = 1e-6;
    e.debiased.rel_sq_debiased_se = 1e-5;  // within two standard errors of 0
    CHECK(study::error_text(e) == "0.0312 (debiased < " + std::string("0.0046") + ", unresolved)");
}

#ifdef BOUNCE_WITH_GL
TEST_CASE("the GL frame makes the CPU frame's records and follows a cache whose records were replaced",
          "[irradiance_cache][walkthrough][gl]") {
    gl_test::shared_context();
    auto& f = fixture();
    const camera& cam = f.scene.camera;
    gl::scene_mesh mesh(f.scene);
    gl::gbuffer_pass pass;
    gl::direct_light light(f.scene, mesh, 256);
    const gl::splatting_passes passes{mesh, pass, light};
    gl::irradiance_splatter splatter({{}, weighting_kind::ward_smooth, 0.f, false});

    auto gl_cache = f.cache();
    const cache_frame first = splatter.frame(passes, gl_cache, cam, width, height, f.sampler);
    REQUIRE(first.combined);
    CHECK(first.new_records == gl_cache.records().size());
    CHECK(splatter.options().splat.a == 0.3f);  // the cache's a
    std::vector<std::string> names;
    for (const auto& s : first.stages_ms) names.push_back(s.first);
    CHECK(names == std::vector<std::string>{"gbuffer", "direct", "splat_existing", "readback", "scan",
                                            "compute_records", "interpolate", "normalize"});

    // The CPU frame on the frame's own (rasterized, read-back) G-buffer makes the same records.
    auto cpu_cache = f.cache();
    gbuffer<float> raster = first.g;
    image<glm::vec3> cpu_indirect(width, height);
    cpu_cache.render(raster.view(), cam, f.sampler, cpu_indirect.view(), output_quantity::radiance);
    CHECK(same_records(gl_cache.records(), cpu_cache.records()));

    // Replaced records (a restart from empty): the splatter follows without reset(), and the
    // frame is the first frame again.
    gl_cache.assign({});
    const cache_frame again = splatter.frame(passes, gl_cache, cam, width, height, f.sampler);
    CHECK(same_image(again.indirect, first.indirect));
    CHECK(same_records(gl_cache.records(), cpu_cache.records()));

    // A walkthrough through the GL frame: its fresh twins restart the GPU's copy each frame,
    // and the grown frames still match a splatter that never saw them.
    auto walked = f.cache();
    std::vector<cpu::walkthrough_step> steps;
    cpu::walkthrough(
        walked, f.path, [&](const camera& c) { return splatter.frame(passes, walked, c, width, height, f.sampler); },
        cpu::walkthrough_options{true}, [&](cpu::walkthrough_step&& s) { steps.push_back(std::move(s)); });
    gl::irradiance_splatter plain({{}, weighting_kind::ward_smooth, 0.f, false});
    auto grown = f.cache();
    for (std::size_t k = 0; k < f.path.frames(); ++k) {
        CAPTURE(k);
        const cache_frame fr = plain.frame(passes, grown, f.path.at(k), width, height, f.sampler);
        CHECK(same_image(fr.indirect, steps[k].frame.indirect));
    }
    CHECK(same_records(walked.records(), grown.records()));
}
#endif
