// The frame drivers as library types: cpu::irradiance_cache (and, with GL, the splatter
// around its scan) on a small Cornell box. The cache must make exactly the records and
// image that Algorithm 5's steps give when composed by hand from the CPU passes, for every
// scan policy, and the GL frame the same records as the CPU frame.
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>
#ifdef BOUNCE_WITH_GL
#include "../gl/shared_context.hpp"

#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/irradiance_splatter.hpp>
#endif

#include <catch2/catch.hpp>

#include <cstring>
#include <vector>

using namespace bounce;

namespace {

constexpr std::size_t width = 40, height = 40;

// Everything a frame needs: the box, its BVH, a 64-ray record sampler, the ray-cast G-buffer.
struct box_fixture {
    io::scene scene = io::cornell_box();
    embree::accel bvh{scene};
    embree::reference_integrator integrator{bvh, scene, {}};
    radius_limits limits{};
    embree::record_sampler sampler{integrator, embree::hemisphere_grid_for(64), limits};
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, width, height);
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

cpu::irradiance_cache_options options_with(cpu::scan_kind scan, cpu::scan_order order = cpu::scan_order::linear) {
    cpu::irradiance_cache_options o;
    o.splat.a = 0.3f;
    o.scan = scan;
    o.order = order;
    return o;
}

}  // namespace

TEST_CASE("the cache's frame is Algorithm 5 composed by hand from the CPU passes", "[irradiance_cache]") {
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const camera& cam = f.scene.camera;
    const auto gv = f.g.view();

    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, options_with(cpu::scan_kind::sequential));
    image<glm::vec3> indirect(width, height);
    const auto stats = cache.render(gv, cam, f.sampler, indirect.view(), output_quantity::radiance);

    // By hand: splat nothing, scan with the sampler one pixel at a time, splat all, normalize.
    std::vector<irradiance_record> records;
    image<glm::vec4> splat(width, height, glm::vec4(0.f));
    const auto create = [&](std::size_t x, std::size_t y) {
        return f.sampler(gv.position(x, y), gv.normal(x, y), cam.pixel_footprint(gv.depth(x, y), height));
    };
    const std::size_t created =
        cpu::scan_cache_misses<ward_smooth_weight>(gv, cam, cache.options().splat, 0.3f, create, records, splat.view());
    std::fill(splat.data(), splat.data() + width * height, glm::vec4(0.f));
    cpu::splat_records<ward_smooth_weight>(gv, cam, records, cache.options().splat, splat.view());
    image<glm::vec3> by_hand(width, height);
    cpu::normalize_splats(splat.view(), by_hand.view());

    REQUIRE(created > 10);
    CHECK(stats.new_records == created);
    CHECK(same_records(cache.records(), records));
    CHECK(same_image(indirect, by_hand));

    // A second frame from the same camera finds no miss and leaves the image as it was.
    image<glm::vec3> again(width, height);
    CHECK(cache.render(gv, cam, f.sampler, again.view(), output_quantity::radiance).new_records == 0);
    CHECK(same_image(again, indirect));
}

TEST_CASE("the cache's irradiance is its radiance divided by rho over pi, with the same records",
          "[irradiance_cache][outputs]") {
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const auto gv = f.g.view();
    cpu::irradiance_cache<ward_smooth_weight> by_e(lo, hi, options_with(cpu::scan_kind::batched));
    cpu::irradiance_cache<ward_smooth_weight> by_l(lo, hi, options_with(cpu::scan_kind::batched));
    image<glm::vec3> e(width, height), l(width, height);
    by_e.render(gv, f.scene.camera, f.sampler, e.view());  // the default: irradiance
    by_l.render(gv, f.scene.camera, f.sampler, l.view(), output_quantity::radiance);
    CHECK(same_records(by_e.records(), by_l.records()));
    std::size_t lit = 0;
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x) {
            const glm::vec3 expected = lambertian_radiance<float, glm::vec3>(gv.albedo(x, y), e(x, y));
            for (int c = 0; c < 3; ++c) CHECK(l(x, y)[c] == Approx(expected[c]).epsilon(1e-5).margin(1e-7));
            lit += e(x, y).x > 0.f ? 1 : 0;
        }
    CHECK(lit > width * height / 2);
}

TEST_CASE("batched and sequential scans, in either order, agree with each other record for record",
          "[irradiance_cache]") {
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const auto gv = f.g.view();
    for (const auto order : {cpu::scan_order::linear, cpu::scan_order::coarse_to_fine}) {
        cpu::irradiance_cache<ward_weight> sequential(lo, hi, options_with(cpu::scan_kind::sequential, order));
        cpu::irradiance_cache<ward_weight> batched(lo, hi, options_with(cpu::scan_kind::batched, order));
        image<glm::vec3> a(width, height), b(width, height);
        sequential.render(gv, f.scene.camera, f.sampler, a.view());
        const auto stats = batched.render(gv, f.scene.camera, f.sampler, b.view());
        CHECK(same_records(sequential.records(), batched.records()));
        CHECK(same_image(a, b));
        CHECK(stats.measured == stats.new_records + stats.wasted);
    }
}

TEST_CASE("a budget caps each frame's records, and assign() restarts neighbour clamping from the given records",
          "[irradiance_cache]") {
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const auto gv = f.g.view();
    auto o = options_with(cpu::scan_kind::batched, cpu::scan_order::coarse_to_fine);
    o.neighbour_clamp = true;
    o.max_new_records = 25;
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, o);
    image<glm::vec3> first(width, height), replay(width, height);
    CHECK(cache.render(gv, f.scene.camera, f.sampler, first.view()).new_records == 25);
    const std::vector<irradiance_record> after_one = cache.records();
    CHECK(cache.render(gv, f.scene.camera, f.sampler, replay.view()).new_records == 25);
    // Back to no records: the clamp index must forget the 50 it saw, or the replay's radii
    // would be clamped by records the cache no longer has.
    cache.assign({});
    cache.render(gv, f.scene.camera, f.sampler, replay.view());
    CHECK(same_records(cache.records(), after_one));
    CHECK(same_image(replay, first));
}

TEST_CASE("the octree cache, scalar or four lanes, finds the same misses and leaves no covered pixel dark",
          "[irradiance_cache]") {
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const auto gv = f.g.view();
    auto o = options_with(cpu::scan_kind::batched);
    o.interpolation = cpu::cache_interpolation::octree;
    cpu::irradiance_cache<ward_weight> tree(lo, hi, o);
    o.interpolation = cpu::cache_interpolation::octree_lanes;
    cpu::irradiance_cache<ward_weight> lanes(lo, hi, o);
    image<glm::vec3> a(width, height), b(width, height);
    tree.render(gv, f.scene.camera, f.sampler, a.view());
    lanes.render(gv, f.scene.camera, f.sampler, b.view());
    // Scalar and four-lane evaluation differ in rounding only, so the same misses are found.
    REQUIRE(tree.records().size() == lanes.records().size());
    std::size_t dark = 0;
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x)
            if (gv.covered(x, y) && !(a(x, y).x + a(x, y).y + a(x, y).z > 0.f)) ++dark;
    CHECK(dark == 0);  // every covered pixel meets a record after the scan
}

TEST_CASE("the cache refuses options outside their domains, naming them", "[irradiance_cache][bad-input]") {
    const auto refuses = [](cpu::irradiance_cache_options o, const char* name) {
        INFO(name);
        CHECK_THROWS_MATCHES((cpu::irradiance_cache<ward_weight>(glm::vec3(0.f), glm::vec3(1.f), o)), parameter_error,
                             Catch::Predicate<parameter_error>([&](const parameter_error& e) { return e.parameter() == name; }));
    };
    cpu::irradiance_cache_options o;
    o.splat.a = 0.f;
    refuses(o, "a");
    o = {};
    o.min_weight = -1.f;
    refuses(o, "min_weight");
    o = {};
    o.fill_holes = std::numeric_limits<float>::quiet_NaN();
    refuses(o, "fill_holes");
    o = {};
    o.max_new_records = 0;
    refuses(o, "max_new_records");
    o = {};
    o.max_new_records = 10;
    o.interpolation = cpu::cache_interpolation::octree;
    refuses(o, "fill_holes");
    // A scan on a splat buffer exists for splatting only.
    o = {};
    o.interpolation = cpu::cache_interpolation::octree;
    cpu::irradiance_cache<ward_weight> tree(glm::vec3(0.f), glm::vec3(1.f), o);
    auto& f = fixture();
    image<glm::vec4> splat(width, height);
    CHECK_THROWS_AS(tree.scan(f.g.view(), f.scene.camera, f.sampler, splat.view()), parameter_error);
}

#ifdef BOUNCE_WITH_GL
TEST_CASE("the GL splatter around the cache's scan makes the CPU frame's records and image",
          "[irradiance_cache][gl]") {
    gl_test::shared_context();
    auto& f = fixture();
    const auto [lo, hi] = f.scene.bounds();
    const camera& cam = f.scene.camera;

    // The GL frame on the G-buffer the renderer drew itself.
    gl::scene_mesh mesh(f.scene);
    gl::gbuffer_pass pass;
    pass.render(mesh, cam, width, height);
    gbuffer<float> raster = pass.read();
    gl::irradiance_splatter_options so;
    so.splat.a = 0.3f;
    so.weighting = weighting_kind::ward_smooth;
    gl::irradiance_splatter splatter(so);
    cpu::irradiance_cache<ward_smooth_weight> gl_cache(lo, hi, options_with(cpu::scan_kind::batched));
    const auto st = splatter.render(gl::textures_of(pass), cam, gl_cache.records(),
                                    [&](gbuffer_view<float> g, image_view<glm::vec4> splat) {
                                        gl_cache.scan(g, cam, f.sampler, splat);
                                    });
    image<glm::vec3> gl_indirect(width, height);
    splatter.read_indirect(gl_indirect.view());

    // The CPU frame on the same (read-back) G-buffer.
    cpu::irradiance_cache<ward_smooth_weight> cpu_cache(lo, hi, options_with(cpu::scan_kind::batched));
    image<glm::vec3> cpu_indirect(width, height);
    cpu_cache.render(raster.view(), cam, f.sampler, cpu_indirect.view());

    CHECK(st.new_records == gl_cache.records().size());
    CHECK(same_records(gl_cache.records(), cpu_cache.records()));
    // Each pixel is a normalized weighted mean of the same records: the GPU's sums differ
    // from the CPU's by float rounding in another order, a few ulps (the splat tests' 1e-4).
    double worst = 0;
    for (std::size_t y = 0; y < height; ++y)
        for (std::size_t x = 0; x < width; ++x)
            for (int c = 0; c < 3; ++c) {
                const double v = cpu_indirect(x, y)[c], g = gl_indirect(x, y)[c];
                worst = std::max(worst, std::abs(g - v) / std::max(std::abs(v), 1e-3));
            }
    CHECK(worst <= 1e-4);

    // Replacing the records (a restart) needs reset(); a shrunk list without it is refused.
    gl_cache.assign({});
    CHECK_THROWS_AS(splatter.render(gl::textures_of(pass), cam, gl_cache.records(), [](auto, auto) {}), parameter_error);
    splatter.reset();
    CHECK_NOTHROW(splatter.render(gl::textures_of(pass), cam, gl_cache.records(), [](auto, auto) {}));

    // Both made irradiance (the default); compose adds direct radiance, so it wants radiance.
    CHECK(splatter.output() == output_quantity::irradiance);
    gl::texture direct(gl::texel_format::rgba32f, width, height);
    try {
        splatter.compose(direct);
        FAIL("compose added radiance to irradiance");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "output");
    }
    splatter.render(gl::textures_of(pass), cam, gl_cache.records(), [](auto, auto) {}, output_quantity::radiance);
    CHECK_NOTHROW(splatter.compose(direct));
}
#endif
