// vk::irradiance_splatter against cpu::splat_records and cpu::normalize_splats, on lavapipe:
// a tilted plane's exact G-buffer with a hole, 80 records with gradients on it (reaching over a
// third of the pixels), every
// weighting, gradients and the in-front test on and off, irradiance and radiance, and the
// hole-filling normalization.
//
// Tolerance: 1e-5 relative per pixel and channel, |gpu - cpu| <= 1e-5 |cpu|. Every term of
// a pixel's sum is non-negative (w >= 0, and E_k(p) is clamped to [0, 2 E_k]) and both sides
// add the same terms in the same order (record order, onto what the buffer held), so the
// only differences are the kernels' own rounding (fused multiply-adds, built-ins), a few
// ulps of each term: far below 1e-5 of the sum. A pixel where one side's weight rounds to
// zero and the other's does not would break the bound; none occurs here.
#include "../cpu/plane_view.hpp"
#include "../skip.hpp"
#include "vulkan_device.hpp"

#include <bounce/cache/record_std430.hpp>
#include <bounce/cpu/splatting.hpp>
#include <bounce/sampling.hpp>
#include <bounce/vk/irradiance_splatter.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {

std::unique_ptr<vk_test::test_device> device_or_skip() {
    auto d = vk_test::test_device::create();
    if (!d) test::skip("no Vulkan 1.2 device with a compute queue (Debian: mesa-vulkan-drivers gives lavapipe)");
    return d;
}

std::vector<irradiance_record> records_on(const gbuffer<float>& g, std::size_t count, std::uint64_t seed) {
    pcg32 rng(seed);
    std::vector<irradiance_record> out;
    const auto f = [&] { return rng.next_float(); };
    while (out.size() < count) {
        const std::size_t x = std::size_t(f() * float(g.width())), y = std::size_t(f() * float(g.height()));
        if (x >= g.width() || y >= g.height() || !std::isfinite(g.depth(x, y))) continue;
        irradiance_record r;
        r.position = g.position(x, y);
        r.normal = glm::normalize(g.normal(x, y) + 0.2f * glm::vec3(f() - 0.5f, f() - 0.5f, f() - 0.5f));
        r.irradiance = glm::vec3(1.f + 3.f * f(), 1.f + 3.f * f(), 1.f + 3.f * f());
        for (int c = 0; c < 3; ++c) {
            r.rotation[std::size_t(c)] = 2.f * glm::vec3(f() - 0.5f, f() - 0.5f, f() - 0.5f);
            r.translation[std::size_t(c)] = 4.f * glm::vec3(f() - 0.5f, f() - 0.5f, f() - 0.5f);
        }
        r.radius = 0.5f + 1.5f * f();
        out.push_back(r);
    }
    return out;
}

template <class T>
std::span<T> all(image<T>& i) {
    return {i.data(), i.width() * i.height()};
}

// The G-buffer as the Vulkan pass reads it: vec4 rows, top first.
struct gpu_gbuffer {
    std::vector<glm::vec4> position_depth, normal, albedo;
    explicit gpu_gbuffer(const gbuffer<float>& g) {
        for (std::size_t y = 0; y < g.height(); ++y)
            for (std::size_t x = 0; x < g.width(); ++x) {
                position_depth.emplace_back(g.position(x, y), g.depth(x, y));
                normal.emplace_back(g.normal(x, y), 0.f);
                albedo.emplace_back(g.albedo(x, y), 0.f);
            }
    }
};

// Worst |gpu - cpu| / |cpu| over every pixel and channel, checking the bound.
double check_relative(const std::vector<glm::vec4>& gpu, const image<glm::vec4>& cpu, int channels) {
    REQUIRE(gpu.size() == cpu.width() * cpu.height());
    double worst = 0;
    for (std::size_t y = 0; y < cpu.height(); ++y)
        for (std::size_t x = 0; x < cpu.width(); ++x)
            for (int c = 0; c < channels; ++c) {
                const double g = gpu[y * cpu.width() + x][c], e = cpu(x, y)[c], d = std::abs(g - e);
                if (d > 0) worst = std::max(worst, d / std::abs(e));
                if (!(d <= 1e-5 * std::abs(e))) {
                    INFO("pixel (" << x << ", " << y << ") channel " << c << ": gpu " << g << ", cpu " << e);
                    CHECK(d <= 1e-5 * std::abs(e));
                }
            }
    return worst;
}

}  // namespace

TEST_CASE("the Vulkan splat and normalization agree with the CPU's to 1e-5 relative", "[vk][splat]") {
    const auto dev = device_or_skip();
    if (!dev) return;
    cpu_test::plane_view v(40, 32, glm::normalize(glm::vec3(0.3f, -0.2f, 1.f)), true);
    pcg32 rng(5);
    for (std::size_t y = 0; y < v.gb.height(); ++y)
        for (std::size_t x = 0; x < v.gb.width(); ++x) v.gb.albedo(x, y) = {rng.next_float(), rng.next_float(), rng.next_float()};
    gbuffer<float> pi_albedo = v.gb;  // what the CPU splats for irradiance (rho = pi)
    for (auto& a : all(pi_albedo.albedo)) a = glm::vec3(float(std::numbers::pi));
    const auto records = records_on(v.gb, 80, 6);
    std::vector<std430_record> packed;
    for (std::size_t i = 0; i < records.size(); ++i) packed.push_back(pack_std430(records[i], i));
    const std::size_t w = v.gb.width(), h = v.gb.height(), pixels = w * h;
    const gpu_gbuffer g(v.gb);
    auto rec = dev->buffer<std430_record>(packed.size(), packed);
    auto pos = dev->buffer<glm::vec4>(pixels, g.position_depth), nor = dev->buffer<glm::vec4>(pixels, g.normal),
         alb = dev->buffer<glm::vec4>(pixels, g.albedo);
    auto splat = dev->buffer<glm::vec4>(pixels), wide = dev->buffer<glm::vec4>(pixels), out = dev->buffer<glm::vec4>(pixels);
    // What the buffer holds before: the splat adds to it, as the CPU's does.
    image<glm::vec4> before(w, h);
    for (auto& p : all(before)) p = glm::vec4(rng.next_float(), rng.next_float(), rng.next_float(), rng.next_float()) * 0.01f;
    vk::irradiance_splatter splatter(dev->ref());
    double worst = 0;
    for (const weighting_kind kind : weighting_kinds)
        for (const bool gradients : {false, true})
            for (const float front : {1.f, 0.3f})
                for (const output_quantity q : {output_quantity::irradiance, output_quantity::radiance}) {
                    INFO(weighting_name(kind) << (gradients ? ", gradients" : "") << ", front tolerance " << front
                                              << (q == output_quantity::irradiance ? ", irradiance" : ", radiance"));
                    vk::splat_job job{w, h, 0, records.size(), {0.3f, gradients, 1.f, front}, kind, q};
                    image<glm::vec4> cpu = before;
                    auto& gb = q == output_quantity::irradiance ? pi_albedo : v.gb;
                    with_weighting(kind, [&](auto policy) {
                        cpu::splat_records<decltype(policy)>(gb.view(), v.cam, records, job.params, cpu.view());
                    });
                    splat->write(std::span<const glm::vec4>(all(before)));
                    // Radiance reads the albedo; irradiance may leave it out.
                    const vk::buffer_range albedo = q == output_quantity::radiance ? alb->range() : vk::buffer_range{};
                    splatter.splat({rec->range(), pos->range(), nor->range(), albedo, splat->range()}, job);
                    worst = std::max(worst, check_relative(splat->read<glm::vec4>(pixels), cpu, 4));
                    // Normalized: sum / weight where a record reached, 0 elsewhere.
                    image<glm::vec3> indirect(w, h);
                    cpu::normalize_splats(cpu.view(), indirect.view());
                    image<glm::vec4> expected(w, h);
                    for (std::size_t i = 0; i < pixels; ++i) all(expected)[i] = glm::vec4(all(indirect)[i], 1.f);
                    splatter.normalize(splat->range(), out->range(), pixels);
                    worst = std::max(worst, check_relative(out->read<glm::vec4>(pixels), expected, 4));
                }
    // Hole filling: the same records at 4a into a second buffer, blended with lambda 1e-3.
    vk::splat_job job{w, h, 0, records.size(), {0.3f, true, 1.f, 1.f}, weighting_kind::ward_smooth, output_quantity::radiance};
    image<glm::vec4> cpu(w, h), cpu_wide(w, h);
    splat->write(std::span<const glm::vec4>(all(cpu)));  // zeros
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, records, job.params, cpu.view());
    splatter.splat({rec->range(), pos->range(), nor->range(), alb->range(), splat->range()}, job);
    // The records reach a good part of the picture (the comparison is not of empty buffers).
    CHECK(std::count_if(all(cpu).begin(), all(cpu).end(), [](const glm::vec4& p) { return p.w > 0.f; }) > long(pixels / 3));
    job.params.a *= 4;
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, records, job.params, cpu_wide.view());
    splatter.splat({rec->range(), pos->range(), nor->range(), alb->range(), wide->range()}, job);
    image<glm::vec3> indirect(w, h);
    cpu::normalize_splats(cpu.view(), cpu_wide.view(), 1e-3f, indirect.view());
    image<glm::vec4> expected(w, h);
    for (std::size_t i = 0; i < pixels; ++i) all(expected)[i] = glm::vec4(all(indirect)[i], 1.f);
    splatter.normalize(splat->range(), wide->range(), 1e-3f, out->range(), pixels);
    worst = std::max(worst, check_relative(out->read<glm::vec4>(pixels), expected, 4));
    WARN("worst relative difference on " << dev->name() << ": " << worst);
}

TEST_CASE("the Vulkan splatter refuses bad jobs and names failed Vulkan calls", "[vk][splat]") {
    CHECK_THROWS_AS(vk::submitter(vk::device_ref{}), parameter_error);
    try {
        vk::check(VK_ERROR_DEVICE_LOST, "vkQueueSubmit");
        FAIL("no exception");
    } catch (const vk::vulkan_error& e) {
        CHECK(e.call() == "vkQueueSubmit");
        CHECK(e.result() == VK_ERROR_DEVICE_LOST);
        CHECK(std::string(e.what()) == "vkQueueSubmit failed: VK_ERROR_DEVICE_LOST (-4)");
    }
    vk::splat_job job;
    CHECK_THROWS_WITH(job.validate(), Catch::Contains("width/height"));
    job.width = job.height = 4;
    job.params.a = 0.f;
    CHECK_THROWS_WITH(job.validate(), Catch::Contains("a"));
    const auto dev = device_or_skip();
    if (!dev) return;
    vk::irradiance_splatter splatter(dev->ref());
    auto b = dev->buffer<glm::vec4>(16);
    CHECK_THROWS_WITH(splatter.normalize(b->range(), b->range(), 0.f, b->range(), 16), Catch::Contains("lambda"));
}
