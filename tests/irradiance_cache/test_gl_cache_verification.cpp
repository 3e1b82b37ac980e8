// The verification pass in the GL frame (gl::irradiance_splatter::frame and render() around
// cpu::irradiance_cache::scan_and_verify): the probes and the residual test run on the CPU on
// the splat buffer the GPU splatted and the scan read back, and each round's records are
// splatted again on the GPU (resplat). It must make the CPU frame's records and image: on
// the strip plane of strip_plane.hpp (a strip no record sampled, found by the probes) and on
// the Cornell box with Embree records and probes.
#include "strip_plane.hpp"

#include "../gl/shared_context.hpp"

#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

using namespace bounce;

namespace {

bool same_records(const std::vector<irradiance_record>& a, const std::vector<irradiance_record>& b) {
    return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(irradiance_record)) == 0;
}

// The largest difference relative to max(|cpu|, floor) over every pixel and channel: the
// GPU's splat sums differ from the CPU's by float rounding in another order (the existing
// CPU/GL frame agreement test's 1e-4).
double worst_relative(const image<glm::vec3>& cpu, const image<glm::vec3>& gpu, double floor) {
    double worst = 0;
    for (std::size_t y = 0; y < cpu.height(); ++y)
        for (std::size_t x = 0; x < cpu.width(); ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = cpu(x, y)[c], g = gpu(x, y)[c];
                worst = std::max(worst, std::abs(g - v) / std::max(std::abs(v), floor));
            }
    return worst;
}

}  // namespace

TEST_CASE("the GL splatter's verification finds the sub-pixel strip as the CPU frame does",
          "[irradiance_cache][verification][gl]") {
    using namespace strip_test;
    gl_test::shared_context();
    plane_view v;
    const gl::gbuffer_upload uploaded(v.g.view());
    const gl::gbuffer_textures tex = uploaded.textures();
    const auto run_gl = [&](std::uint32_t rounds, image<glm::vec3>& out) {
        cpu::irradiance_cache<ward_smooth_weight> cache(glm::vec3(-1.f), glm::vec3(1.f), strip_options(rounds));
        cache.set_probe(noisy_probe);
        strip_sampler sampler;
        gl::irradiance_splatter splatter({cache.options().splat, weighting_kind::ward_smooth, 0.f, false});
        cpu::cache_frame_stats stats;
        splatter.render(tex, v.cam, cache.records(), [&](gbuffer_view<float> g, image_view<glm::vec4> splat) {
            stats = cache.scan_and_verify(g, v.cam, sampler, splat, [&](image_view<glm::vec4> s) {
                splatter.resplat(tex, v.cam, cache.records(), s);
            });
        });  // irradiance, render()'s default: the scan's G-buffer has the albedo of pi the splat weighs
        splatter.read_indirect(out.view());
        CHECK(cache.last_stats().verify_tiles == stats.verify_tiles);
        return std::pair{cache.records(), stats};
    };
    image<glm::vec3> scanned(size, size), verified(size, size);
    const auto [scan_records, scan_stats] = run_gl(0, scanned);
    const auto [records, stats] = run_gl(2, verified);
    const strip_errors before = errors_of(v.g, scanned), after = errors_of(v.g, verified);
    REQUIRE(after.strip_pixels == 128);
    // As the CPU test asks of the CPU frame (test_cache_verification.cpp).
    CHECK(scan_stats.verify_tiles == 0);
    CHECK(before.strip > 0.3);
    CHECK(stats.verify_disagreed > 0);
    CHECK(stats.verify_shrunk > 0);
    CHECK(records.size() > scan_records.size());
    CHECK(after.strip < 0.25 * before.strip);
    CHECK(after.strip < 0.08);
    CHECK(after.rest < 0.02);

    // The CPU frame on the same G-buffer: the same records, the same image to rounding.
    cpu::irradiance_cache<ward_smooth_weight> cpu_cache(glm::vec3(-1.f), glm::vec3(1.f), strip_options(2));
    cpu_cache.set_probe(noisy_probe);
    strip_sampler sampler;
    image<glm::vec3> cpu_out(size, size);
    const cpu::cache_frame_stats cpu_stats = cpu_cache.render(v.g.view(), v.cam, sampler, cpu_out.view());
    CHECK(cpu_stats.verify_disagreed == stats.verify_disagreed);
    CHECK(cpu_stats.verify_shrunk == stats.verify_shrunk);
    CHECK(same_records(records, cpu_cache.records()));
    CHECK(worst_relative(cpu_out, verified, 1e-3) <= 1e-4);
}

TEST_CASE("the GL frame with the verification pass makes the CPU frame's records and image, and keeps its GPU copy",
          "[irradiance_cache][verification][gl]") {
    gl_test::shared_context();
    constexpr std::size_t width = 40, height = 40;
    const io::scene scene = io::cornell_box();
    const embree::accel bvh(scene);
    const embree::reference_integrator integrator(bvh, scene, {});
    const radius_limits limits{};
    const embree::record_sampler sampler(integrator, embree::hemisphere_grid_for(64), limits);
    const embree::irradiance_probe probe(integrator, 8);
    const auto [lo, hi] = scene.bounds();
    const camera& cam = scene.camera;
    cpu::irradiance_cache_options o;
    o.splat.a = 0.3f;
    o.neighbour_clamp = true;
    o.verify.rounds = 2;
    const auto make_cache = [&] {
        cpu::irradiance_cache<ward_smooth_weight> c(lo, hi, o);
        c.set_probe(std::cref(probe));
        return c;
    };

    gl::scene_mesh mesh(scene);
    gl::gbuffer_pass pass;
    gl::direct_light light(scene, mesh, 256);
    const gl::splatting_passes passes{mesh, pass, light};
    gl::irradiance_splatter splatter({{}, weighting_kind::ward_smooth, 0.f, false});
    auto gl_cache = make_cache();
    const cache_frame first = splatter.frame(passes, gl_cache, cam, width, height, sampler);
    INFO("tiles " << first.verify_tiles << ", disagreed " << first.verify_disagreed << ", shrunk "
                  << first.verify_shrunk << ", records " << gl_cache.records().size());
    CHECK(first.verify_tiles == 100 + 121);  // 10 x 10 tiles of 4 pixels, then 11 x 11 shifted by half a tile
    CHECK(first.verify_disagreed > 0);       // the rounds ran: records measured, splatted again on the GPU
    CHECK(first.verify_shrunk > 0);
    std::vector<std::string> names;
    for (const auto& s : first.stages_ms) names.push_back(s.first);
    CHECK(names == std::vector<std::string>{"gbuffer", "direct", "splat_existing", "readback", "scan",
                                            "compute_records", "verify", "interpolate", "normalize"});

    // The CPU frame on the GL frame's own (rasterized, read-back) G-buffer.
    auto cpu_cache = make_cache();
    gbuffer<float> raster = first.g;
    image<glm::vec3> cpu_indirect(width, height);
    const cpu::cache_frame_stats cs =
        cpu_cache.render(raster.view(), cam, sampler, cpu_indirect.view(), output_quantity::radiance);
    CHECK(cs.verify_disagreed == first.verify_disagreed);
    CHECK(cs.verify_shrunk == first.verify_shrunk);
    CHECK(cs.new_records == first.new_records);
    CHECK(same_records(gl_cache.records(), cpu_cache.records()));
    CHECK(worst_relative(cpu_indirect, first.indirect, 1e-3) <= 1e-4);

    // A cache grown by a frame without the pass, then verified: the rounds shrink records the
    // GPU already held, so its copy must be uploaded again before the round's scan.
    o.verify.rounds = 0;
    auto grown_gl = make_cache(), grown_cpu = make_cache();
    gl::irradiance_splatter grower({{}, weighting_kind::ward_smooth, 0.f, false});
    grower.frame(passes, grown_gl, cam, width, height, sampler);
    grown_cpu.render(raster.view(), cam, sampler, cpu_indirect.view(), output_quantity::radiance);
    REQUIRE(same_records(grown_gl.records(), grown_cpu.records()));
    o.verify.rounds = 2;
    grown_gl.set_options(o);
    grown_cpu.set_options(o);
    const cache_frame verified = grower.frame(passes, grown_gl, cam, width, height, sampler);
    const cpu::cache_frame_stats vs =
        grown_cpu.render(raster.view(), cam, sampler, cpu_indirect.view(), output_quantity::radiance);
    CHECK(verified.verify_shrunk > 0);
    CHECK(vs.verify_shrunk == verified.verify_shrunk);
    CHECK(same_records(grown_gl.records(), grown_cpu.records()));
    CHECK(worst_relative(cpu_indirect, verified.indirect, 1e-3) <= 1e-4);

    // The next frame: the splatter kept the radii the verification left on the GPU (no
    // restart: without neighbour clamping the frame's start shrinks nothing, so only the
    // splatter's own record of the cache's generation decides), so it equals a fresh
    // splatter's frame of the same cache.
    o.neighbour_clamp = false;
    gl_cache.set_options(o);
    auto copy = gl_cache;
    const cache_frame again = splatter.frame(passes, gl_cache, cam, width, height, sampler);
    gl::irradiance_splatter fresh({{}, weighting_kind::ward_smooth, 0.f, false});
    const cache_frame from_scratch = fresh.frame(passes, copy, cam, width, height, sampler);
    CHECK(same_records(gl_cache.records(), copy.records()));
    CHECK(std::memcmp(again.indirect.data(), from_scratch.indirect.data(), width * height * sizeof(glm::vec3)) == 0);
}
