// GL irradiance splatting against the CPU reference (cpu::splat_records) on the same records
// and the same analytic G-buffer: every weighting policy, gradients on and off, random and
// adversarial records; appending and splatting only the new records; normalization and
// composition on the GPU; bad input.
//
// Why the two agree so closely: both evaluate the same kernel (splat_contribution, emitted
// for GL) on the same float inputs, and GL's float blending adds each pixel's terms in
// primitive order, i.e. record order, which is the CPU's order too. What remains is the
// rounding of the kernels' operations (GLSL's sqrt, division and fused multiply-adds may
// differ from the CPU's by an ulp or two each) and, for Ward's plain weight, the jump at the
// zone border. Tolerance per pixel and component, derived from that:
//   |gl - cpu| <= 1e-4 |cpu| + slack,
// where 1e-4 is the required relative agreement, far above the few-ulp (1e-6) relative
// error of a sum of positive terms, and `slack` is the part of a term's rounding that the
// kernel's own conditioning amplifies beyond a few ulps, summed over the records whose
// sphere of influence holds the pixel's point:
//  - differences of nearly equal numbers near the border of a zone: the smoothed Ward weight
//    1/inv_w - 1/a and Tabellion's 1 - e/a carry an absolute error of a few ulps of 1/a
//    (>= 1 for a <= 1); 16 ulps (16 * 2^-24 = 9.5e-7) / a per record;
//  - the normal term sqrt(1 - n.nk) for nearly parallel normals: n.nk of two unit float
//    vectors is off by up to dx = 4 ulps of 1 (four roundings; with or without fused
//    multiply-adds), and the square root turns that into min(sqrt(dx), dx / (2 sqrt(x)))
//    at x = 1 - n.nk (dx = 0 when n_k = (0, 0, +-1): then n.nk = +-n.z is exact on both
//    sides, and so is 1 - n.z by Sterbenz's lemma); Ward's weight 1/inv_w passes it on as d_inv / inv_w^2, Tabellion's
//    as d_div / (a sqrt(1 - cos 10 deg)).
// Each rgb component gets the weight's slack times rho_d E_k (1 + max_extrapolation) / pi.
// The test also counts the pixels where the slack is below the relative bound, so that the
// 1e-4 bound is what decides for most of them.
// Ward's plain weight (and the GPU forms of it) jumps from 1/a to 0 at inv_w = a, so a pixel
// whose point lies within float rounding of some record's border may legitimately be in on
// one side and out on the other: exactly those pixels are excluded, namely those with
// |inv_w - a| < 1e-5 a + d_div for some record (inv_w computed in double, d_div the
// normal term's rounding above). The smoothed and
// Tabellion weights are continuous and exclude nothing.
#include "../gl/shared_context.hpp"

#include "../owned_scene.hpp"

#include <bounce/cpu/splatting.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/sampling.hpp>


#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)
#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <limits>
#include <numbers>
#include <vector>

using namespace bounce;

namespace {

constexpr std::size_t W = 64, H = 48;

// The plane z = 0, limited to |x|, |y| <= 1.6 (other pixels see nothing), seen obliquely
// from above. Normals are tilted at random by up to about 1 degree (Tabellion's weight
// reaches zero at 10 a degrees of divergence, so larger tilts would zero it everywhere) and
// reflectances vary per pixel, so every term of the kernel changes from pixel to pixel.
struct plane_view {
    camera cam;
    gbuffer<float> gb{W, H};
    plane_view() {
        cam.position = {0.3f, -0.2f, 4.f};
        cam.look_at = {0.f, 0.f, 0.f};
        cam.up = {0, 1, 0};
        cam.fov_y_deg = 60.f;
        const glm::vec3 f = cam.forward();
        pcg32 rng(2024);
        for (std::size_t y = 0; y < H; ++y)
            for (std::size_t x = 0; x < W; ++x) {
                const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, W, H);
                const float t = -cam.position.z / d.z;
                const glm::vec3 p = cam.position + t * d;
                const glm::vec3 tilt(0.02f * (rng.next_float() - 0.5f), 0.02f * (rng.next_float() - 0.5f), 1.f);
                const glm::vec3 albedo(0.1f + 0.9f * rng.next_float(), 0.1f + 0.9f * rng.next_float(),
                                       0.1f + 0.9f * rng.next_float());
                if (std::abs(p.x) > 1.6f || std::abs(p.y) > 1.6f) continue;
                gb.position(x, y) = p;
                gb.normal(x, y) = glm::normalize(tilt);
                gb.albedo(x, y) = albedo;
                gb.depth(x, y) = glm::dot(p - cam.position, f);
            }
    }
};

glm::vec3 random_unit_near_z(pcg32& rng, float spread) {
    return glm::normalize(glm::vec3(spread * (2.f * rng.next_float() - 1.f), spread * (2.f * rng.next_float() - 1.f), 1.f));
}
glm::vec3 random_vec(pcg32& rng, float scale) {
    return scale * glm::vec3(2.f * rng.next_float() - 1.f, 2.f * rng.next_float() - 1.f, 2.f * rng.next_float() - 1.f);
}

// Two records in three have the plane's normal (0, 0, 1), as records on a flat floor do,
// the others are up to about 20 degrees off (they reach pixels under Ward's weights, few
// under Tabellion's).
irradiance_record random_record(pcg32& rng) {
    irradiance_record r;
    r.position = {4.f * rng.next_float() - 2.f, 4.f * rng.next_float() - 2.f, 0.2f * rng.next_float() - 0.1f};
    r.normal = rng.next_float() < 2.f / 3.f ? glm::vec3(0, 0, 1) : random_unit_near_z(rng, 0.35f);
    r.irradiance = {2.f * rng.next_float(), 2.f * rng.next_float(), 2.f * rng.next_float()};
    for (int c = 0; c < 3; ++c) {
        r.rotation[std::size_t(c)] = random_vec(rng, 1.f);
        r.translation[std::size_t(c)] = random_vec(rng, 1.5f);
    }
    r.radius = 0.05f * std::pow(40.f, rng.next_float());  // 0.05 .. 2, log-uniform
    return r;
}

// A few hundred random records and the adversarial ones.
std::vector<irradiance_record> test_records(plane_view& v) {
    pcg32 rng(77);
    std::vector<irradiance_record> recs;
    for (int i = 0; i < 300; ++i) recs.push_back(random_record(rng));
    const glm::vec3 eye = v.cam.position, f = v.cam.forward();
    auto special = [&](glm::vec3 p, float radius, glm::vec3 n = {0, 0, 1}) {
        irradiance_record r = random_record(rng);
        r.position = p;
        r.radius = radius;
        r.normal = glm::normalize(n);
        recs.push_back(r);
    };
    special(eye, 40.f);                                   // contains the eye, reaches the plane
    special(eye + 0.005f * f, 30.f);                      // centre in front of the eye, nearer than the near plane
    special(eye + 0.5f * f, 12.f);                        // sphere crossing the near plane
    special(eye - 1.f * f, 50.f);                         // centre behind the camera, reaching the plane
    special(eye - 1.f * f, 0.5f);                         // behind the camera, invisible
    special({0.f, 0.f, 0.f}, 1e4f);                       // huge
    special({40.f, 0.f, 0.f}, 0.5f);                      // far off screen
    special({0.1f, 0.1f, 0.f}, 1e-4f);                    // tiny, covers no pixel centre
    special({0.2f, 0.f, 0.f}, 0.8f, {0.f, 0.f, -1.f});    // opposite normal: no weight anywhere
    special({-0.3f, 0.4f, 0.f}, 0.6f, {1.f, 0.f, 0.05f}); // grazing normal
    // Records exactly at pixels' G-buffer points: p = pk, the singularity clamped by the
    // inverse-weight floor (w = 1e4 for Ward), one of them with the pixel's own normal.
    for (auto [x, y] : {std::pair{32, 24}, std::pair{10, 40}, std::pair{50, 7}}) {
        if (!v.gb.view().covered(std::size_t(x), std::size_t(y))) continue;
        special(v.gb.position(std::size_t(x), std::size_t(y)), 0.3f, v.gb.normal(std::size_t(x), std::size_t(y)));
        special(v.gb.position(std::size_t(x), std::size_t(y)), 1e-4f);
    }
    return recs;
}

const char* kind_name(weighting_kind k) {
    return with_weighting(k, [](auto w) { return decltype(w)::name; });
}

// Per-pixel tolerances (see the header comment) and Ward's border exclusion.
struct pixel_bounds {
    image<glm::vec4> slack;
    image<unsigned char> excluded;
};

pixel_bounds bounds_for(const gbuffer_view<float>& gb, const std::vector<irradiance_record>& recs, weighting_kind kind,
                        const gl::splat_params& sp) {
    pixel_bounds b{image<glm::vec4>(W, H, glm::vec4(0.f)), image<unsigned char>(W, H, 0)};
    const bool tabellion = kind == weighting_kind::tabellion;
    const bool jumps = !tabellion && kind != weighting_kind::ward_smooth;
    const double normal_scale = kind == weighting_kind::ward_scaled_normal ? ward_scaled_normal_weight::normal_scale : 1.0;
    const double ulp = std::ldexp(1.0, -24), a = sp.a;
    const double tabellion_limit = std::sqrt(1.0 - std::cos(10.0 * std::numbers::pi / 180.0));
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            if (!gb.covered(x, y)) continue;
            const glm::dvec3 p = gb.position(x, y), n = gb.normal(x, y), rho = gb.albedo(x, y);
            for (const auto& r : recs) {
                const double dist = glm::length(p - glm::dvec3(r.position));
                if (dist > a * r.radius * (1 + 1e-5)) continue;  // every policy's zone is the sphere of radius a R
                const double one_minus_dot = std::max(0.0, 1.0 - glm::dot(n, glm::dvec3(r.normal)));
                const double dx = r.normal.x == 0.f && r.normal.y == 0.f ? 0.0 : 4 * ulp;
                const double d_div = std::sqrt(normal_scale) *
                                     (one_minus_dot > 0 ? std::min(std::sqrt(dx), dx / (2 * std::sqrt(one_minus_dot)))
                                                        : std::sqrt(dx));
                // What the policy tests against a: Ward's inverse weight, Tabellion's e.
                const double div = std::sqrt(normal_scale * one_minus_dot);
                const double reach = tabellion ? std::max(dist / r.radius, div / tabellion_limit) : dist / r.radius + div;
                const double d_reach = tabellion ? d_div / tabellion_limit : d_div;
                if (reach - d_reach > a * (1 + 1e-5)) continue;  // no weight on either side
                const double inv_w = std::max(inverse_weight_floor, reach);
                const double w_slack = 16 * ulp / a + (tabellion ? d_reach / a : d_div / (inv_w * inv_w));
                const glm::dvec3 e = glm::dvec3(r.irradiance) * (1.0 + sp.max_extrapolation) / std::numbers::pi;
                b.slack(x, y) += glm::vec4(glm::vec3(w_slack * rho * e), float(w_slack));
                if (jumps && std::abs(reach - a) < 1e-5 * a + d_reach) b.excluded(x, y) = 1;
                // Ward's in-front test cuts every policy: pixels whose height below the
                // record's plane is within rounding of the cut may fall either side.
                if (sp.front_test()) {
                    const double height = glm::dot(p - glm::dvec3(r.position), n + glm::dvec3(r.normal)) / r.radius;
                    const double rounding = 64 * ulp * (glm::length(p) + glm::length(glm::dvec3(r.position)) + 1) / r.radius;
                    if (std::abs(height + 2 * sp.front_tolerance * a) <= rounding) b.excluded(x, y) = 1;
                }
            }
        }
    return b;
}

// Compares two splat buffers with the bounds; returns the number of pixels compared.
std::size_t compare(const image<glm::vec4>& gl_buf, const image<glm::vec4>& cpu_buf, const pixel_bounds& b,
                    double& worst_relative, std::size_t& well_conditioned) {
    std::size_t compared = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            if (b.excluded(x, y)) continue;
            ++compared;
            well_conditioned += cpu_buf(x, y).w > 0.f && b.slack(x, y).w < 1e-4 * cpu_buf(x, y).w;
            for (int c = 0; c < 4; ++c) {
                const double g = gl_buf(x, y)[c], r = cpu_buf(x, y)[c];
                const double bound = 1e-4 * std::abs(r) + b.slack(x, y)[c];
                if (!(std::abs(g - r) <= bound)) {
                    INFO("pixel (" << x << ", " << y << ") component " << c << ": gl " << g << " cpu " << r << " bound " << bound);
                    REQUIRE(std::abs(g - r) <= bound);
                }
                if (b.slack(x, y)[c] < 1e-4 * std::abs(r))
                    worst_relative = std::max(worst_relative, std::abs(g - r) / std::abs(r));
            }
        }
    return compared;
}

}  // namespace

TEST_CASE("GL and CPU splat buffers agree for every weighting policy, with and without gradients",
          "[gl][splat][agreement]") {
    gl_test::shared_context();
    static plane_view v;
    static const auto recs = test_records(v);
    const auto kind = GENERATE(weighting_kind::ward, weighting_kind::ward_smooth, weighting_kind::ward_early_reject,
                               weighting_kind::ward_scaled_normal, weighting_kind::tabellion);
    const bool gradients = GENERATE(true, false);
    const float a = GENERATE(0.15f, 0.4f);
    // Ward's in-front test off, and on: the records sit up to 0.1 off the plane, so it cuts.
    const float front_tolerance = GENERATE(1.f, 0.05f);
    INFO("weighting " << kind_name(kind) << ", gradients " << gradients << ", a = " << a << ", front tolerance "
                      << front_tolerance);

    splat_params gp;  // gl::splat_params and cpu::splat_params are one type
    gp.a = a;
    gp.gradients = gradients;
    gp.max_extrapolation = 0.8f;
    gp.front_tolerance = front_tolerance;
    const splat_params& cp = gp;

    image<glm::vec4> cpu_buf(W, H, glm::vec4(0.f));
    with_weighting(kind, [&](auto w) {
        cpu::splat_records<decltype(w)>(v.gb.view(), v.cam, recs, cp, cpu_buf.view());
    });

    const gl::gbuffer_upload gbuf(v.gb.view());
    gl::splat_pass pass;
    pass.upload(recs);
    pass.clear(W, H);
    pass.splat(gbuf.textures(), v.cam, gp, kind);
    const auto gl_buf = pass.read_splat();

    const auto b = bounds_for(v.gb.view(), recs, kind, gp);
    double worst = 0;
    std::size_t well_conditioned = 0;
    const auto compared = compare(gl_buf, cpu_buf, b, worst, well_conditioned);
    // Ward's exclusions are a thin set (pixels within 1e-5 a of a border).
    CHECK(compared >= W * H * 95 / 100);
    // The comparison is not vacuous: most covered pixels received weight.
    std::size_t weighted = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) weighted += cpu_buf(x, y).w > 0.f;
    CHECK(weighted > W * H / 4);
    // The relative bound, not the slack, decides for most weighted pixels.
    CHECK(well_conditioned > weighted / 2);
    if (cp.front_test()) {  // and the in-front test removed weight from many pixels
        splat_params off = cp;
        off.front_tolerance = 1.f;
        image<glm::vec4> uncut(W, H, glm::vec4(0.f));
        with_weighting(kind, [&](auto w) { cpu::splat_records<decltype(w)>(v.gb.view(), v.cam, recs, off, uncut.view()); });
        std::size_t cut = 0;
        for (std::size_t y = 0; y < H; ++y)
            for (std::size_t x = 0; x < W; ++x) cut += cpu_buf(x, y).w < uncut(x, y).w;
        CHECK(cut > W * H / 10);
    }
    WARN("worst relative difference where well conditioned " << worst << "; " << well_conditioned << " of " << weighted
                                                            << " weighted pixels well conditioned");
}

TEST_CASE("appending records and splatting only them on top of an uploaded buffer equals splatting all at once",
          "[gl][splat][append]") {
    gl_test::shared_context();
    plane_view v;
    const auto recs = test_records(v);
    const std::size_t half = recs.size() / 2;
    const gl::gbuffer_upload gbuf(v.gb.view());
    gl::splat_params sp;
    sp.a = 0.3f;
    const auto kind = GENERATE(weighting_kind::ward, weighting_kind::ward_smooth);

    gl::splat_pass all;
    all.upload(recs);
    all.clear(W, H);
    all.splat(gbuf.textures(), v.cam, sp, kind);
    const auto at_once = all.read_splat();

    // Algorithm 5: the old records are splatted, the buffer goes to the CPU and back, the
    // new records are appended and only they are splatted on top.
    gl::splat_pass grown;
    grown.upload(std::span(recs).first(half));
    grown.clear(W, H);
    grown.splat(gbuf.textures(), v.cam, sp, kind);
    const auto first_half = grown.read_splat();
    grown.clear(W, H);
    grown.upload_splat(first_half.view());
    grown.append(std::span(recs).subspan(half));
    REQUIRE(grown.record_count() == recs.size());
    grown.splat(gbuf.textures(), v.cam, sp, kind, half);
    const auto in_two_steps = grown.read_splat();

    // The same float additions in the same order per pixel: identical bits.
    CHECK(std::memcmp(at_once.data(), in_two_steps.data(), W * H * sizeof(glm::vec4)) == 0);
    // And the split was not trivial: the second half changed the buffer.
    CHECK(std::memcmp(first_half.data(), in_two_steps.data(), W * H * sizeof(glm::vec4)) != 0);

    // Appending one record at a time (the cache grows every frame) gives the same buffer.
    gl::splat_pass one_by_one;
    one_by_one.clear(W, H);
    for (std::size_t i = 0; i < recs.size(); ++i) {
        one_by_one.append(std::span(recs).subspan(i, 1));
        one_by_one.splat(gbuf.textures(), v.cam, sp, kind, i, 1);
    }
    CHECK(std::memcmp(at_once.data(), one_by_one.read_splat().data(), W * H * sizeof(glm::vec4)) == 0);
}

TEST_CASE("the splat pass takes the weighting as a policy object as well as a kind", "[gl][splat][weighting]") {
    gl_test::shared_context();
    plane_view v;
    const auto recs = test_records(v);
    const gl::gbuffer_upload gbuf(v.gb.view());
    gl::splat_params sp;
    sp.a = 0.3f;
    gl::splat_pass pass;
    pass.upload(recs);
    auto splat_with = [&](auto weighting) {
        pass.clear(W, H);
        pass.splat(gbuf.textures(), v.cam, sp, weighting);
        return pass.read_splat();
    };
    for (const weighting_kind kind : weighting_kinds) {
        INFO("weighting " << kind_name(kind));
        const auto by_kind = splat_with(kind);
        const auto by_policy = with_weighting(kind, [&](auto w) { return splat_with(w); });
        CHECK(std::memcmp(by_kind.data(), by_policy.data(), W * H * sizeof(glm::vec4)) == 0);
    }
    // The policy chose the program: two policies give two different buffers.
    const auto ward = splat_with(ward_weight{}), tabellion = splat_with(tabellion_weight{});
    CHECK(std::memcmp(ward.data(), tabellion.data(), W * H * sizeof(glm::vec4)) != 0);
}

TEST_CASE("normalization and composition on the GPU equal cpu::normalize_splats and cpu::compose",
          "[gl][splat][compose]") {
    gl_test::shared_context();
    plane_view v;
    const auto recs = test_records(v);
    cpu::splat_params sp;
    sp.a = 0.25f;
    image<glm::vec4> splat(W, H, glm::vec4(0.f));
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, recs, sp, splat.view());
    // Adversarial pixels: no weight, a tiny weight, a huge weight.
    splat(0, 0) = glm::vec4(0.f);
    splat(1, 0) = {1e-30f, 2e-30f, 0.f, 1e-30f};
    splat(2, 0) = {3e7f, 1e7f, 2e7f, 1e4f};
    pcg32 rng(5);
    image<glm::vec3> direct(W, H);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) direct(x, y) = {rng.next_float(), 2.f * rng.next_float(), 0.f};

    image<glm::vec3> expected(W, H), expected_indirect(W, H);
    cpu::normalize_splats(splat.view(), expected_indirect.view());
    cpu::compose(direct.view(), expected_indirect.view(), expected.view());

    gl::texture splat_tex(gl::texel_format::rgba32f, W, H);
    gl::write_texture(splat_tex, splat.view());
    gl::compose_pass pass;
    image<glm::vec3> got(W, H), got_indirect(W, H);
    pass.compose(splat_tex, direct.view());
    pass.read(got.view());
    pass.compose(splat_tex);
    pass.read(got_indirect.view());

    // One division (GLSL allows 2.5 ulp) and one addition: 4 ulps (2.4e-7) relative to the
    // larger of the operands bounds the difference.
    const double ulp4 = 4.0 * std::ldexp(1.0, -24);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c) {
                const double scale = std::abs(expected_indirect(x, y)[c]) + std::abs(direct(x, y)[c]);
                REQUIRE(std::abs(double(got(x, y)[c]) - expected(x, y)[c]) <= ulp4 * scale);
                REQUIRE(std::abs(double(got_indirect(x, y)[c]) - expected_indirect(x, y)[c]) <=
                        ulp4 * std::abs(expected_indirect(x, y)[c]));
            }
    CHECK(got_indirect(0, 0) == glm::vec3(0.f));
    CHECK(got(0, 0) == direct(0, 0));
}

TEST_CASE("hole filling on the GPU equals cpu::normalize_splats with a wide splat", "[gl][splat][compose]") {
    gl_test::shared_context();
    plane_view v;
    const auto recs = test_records(v);
    cpu::splat_params sp, wide_sp;
    sp.a = 0.1f;  // small zones leave holes
    wide_sp.a = 0.4f;
    image<glm::vec4> splat(W, H, glm::vec4(0.f)), wide(W, H, glm::vec4(0.f));
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, std::span(recs).first(recs.size() / 4), sp, splat.view());
    cpu::splat_records<ward_smooth_weight>(v.gb.view(), v.cam, std::span(recs).first(recs.size() / 4), wide_sp, wide.view());
    std::size_t holes = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) holes += splat(x, y).w == 0.f && wide(x, y).w > 0.f;
    REQUIRE(holes > 10);  // the case hole filling is for
    const float lambda = 1e-3f;
    image<glm::vec3> expected(W, H), got(W, H);
    cpu::normalize_splats(splat.view(), wide.view(), lambda, expected.view());

    gl::texture splat_tex(gl::texel_format::rgba32f, W, H), wide_tex(gl::texel_format::rgba32f, W, H);
    gl::write_texture(splat_tex, splat.view());
    gl::write_texture(wide_tex, wide.view());
    gl::compose_pass pass;
    pass.compose(splat_tex, nullptr, &wide_tex, lambda);
    pass.read(got.view());
    // Two multiply-adds, one division (GLSL: 2.5 ulp): 8 ulps of the result bound the gap.
    const double ulp8 = 8.0 * std::ldexp(1.0, -24);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x)
            for (int c = 0; c < 3; ++c)
                REQUIRE(std::abs(double(got(x, y)[c]) - expected(x, y)[c]) <= ulp8 * std::abs(expected(x, y)[c]) + 1e-30);
    gl::texture small(gl::texel_format::rgba32f, 2, 2);
    CHECK_THROWS_AS(pass.compose(splat_tex, nullptr, &small, lambda), parameter_error);
    CHECK_THROWS_AS(pass.compose(splat_tex, nullptr, &wide_tex, 0.f), parameter_error);
}

TEST_CASE("the splat pass refuses bad records, parameters and sizes, naming them", "[gl][splat][bad-input]") {
    gl_test::shared_context();
    plane_view v;
    const gl::gbuffer_upload gbuf(v.gb.view());
    gl::splat_pass pass;
    irradiance_record good;
    good.radius = 0.5f;
    std::vector<irradiance_record> recs(3, good);
    for (float r : {0.f, -1.f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()}) {
        recs[2].radius = r;
        try {
            pass.upload(recs);
            FAIL("accepted radius " << r);
        } catch (const parameter_error& e) {
            CHECK(e.parameter() == "records[2]");
        }
    }
    recs[2] = good;
    recs[1].irradiance.y = std::numeric_limits<float>::quiet_NaN();
    CHECK_THROWS_AS(pass.append(recs), parameter_error);
    CHECK(pass.record_count() == 0);  // nothing half-uploaded
    recs[1] = good;
    pass.upload(recs);

    gl::splat_params sp;
    CHECK_THROWS_AS(pass.splat(gbuf.textures(), v.cam, sp, weighting_kind::ward), parameter_error);  // no buffer yet
    pass.clear(W, H);
    for (float a : {0.f, -0.1f, std::numeric_limits<float>::quiet_NaN()}) {
        sp.a = a;
        try {
            pass.splat(gbuf.textures(), v.cam, sp, weighting_kind::ward);
            FAIL("accepted a = " << a);
        } catch (const parameter_error& e) {
            CHECK(e.parameter() == "a");
        }
    }
    sp.a = 0.2f;
    try {
        pass.splat(gbuf.textures(), v.cam, sp, weighting_kind::ward, 4);
        FAIL("accepted first past the end");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "first");
    }
    pass.clear(W / 2, H);
    CHECK_THROWS_AS(pass.splat(gbuf.textures(), v.cam, sp, weighting_kind::ward), parameter_error);
    CHECK_THROWS_AS(pass.clear(0, H), parameter_error);
    image<glm::vec4> wrong(3, 3);
    CHECK_THROWS_AS(pass.read_splat(wrong.view()), parameter_error);
}

TEST_CASE("the splat pass leaves the caller's GL state as it found it", "[gl][splat][state]") {
    gl_test::shared_context();
    plane_view v;
    const gl::gbuffer_upload gbuf(v.gb.view());
    gl::texture mine(gl::texel_format::rgba32f, 4, 4);
    gl::framebuffer fb;
    fb.attach_color(0, mine);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, fb.id());
    glViewport(1, 2, 3, 4);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    glBindTextureUnit(1, mine.id());

    gl::splat_pass pass;
    pass.upload(test_records(v));
    pass.clear(W, H);
    pass.splat(gbuf.textures(), v.cam, gl::splat_params{}, weighting_kind::tabellion);

    GLint value = 0, viewport[4] = {};
    glGetIntegerv(GL_DRAW_FRAMEBUFFER_BINDING, &value);
    CHECK(GLuint(value) == fb.id());
    glGetIntegerv(GL_VIEWPORT, viewport);
    CHECK((viewport[0] == 1 && viewport[1] == 2 && viewport[2] == 3 && viewport[3] == 4));
    CHECK(glIsEnabled(GL_BLEND) == GL_TRUE);
    glGetIntegerv(GL_BLEND_SRC_RGB, &value);
    CHECK(value == GL_SRC_ALPHA);
    glGetIntegerv(GL_BLEND_DST_ALPHA, &value);
    CHECK(value == GL_ONE_MINUS_SRC_ALPHA);
    glActiveTexture(GL_TEXTURE1);
    glGetIntegerv(GL_TEXTURE_BINDING_2D, &value);
    CHECK(GLuint(value) == mine.id());
    glActiveTexture(GL_TEXTURE0);
    glDisable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ZERO);
    glBindTextureUnit(1, 0);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
}

TEST_CASE("splatting from the raster G-buffer's textures equals splatting its read-back, and the CPU splat of it",
          "[gl][splat][gbuffer]") {
    gl_test::shared_context();
    // A floor and a tilted panel, rendered by gbuffer_pass: normals and reflectances change
    // across the image and some pixels see nothing.
    test::owned_scene s;
    s.materials.push_back({glm::vec3(0.6f, 0.5f, 0.4f), glm::vec3(0.f)});
    s.materials.push_back({glm::vec3(0.2f, 0.7f, 0.3f), glm::vec3(0.f)});
    const glm::vec3 floor_n(0, 0, 1), panel_n = glm::normalize(glm::vec3(-1, 0, 1));
    for (const glm::vec3 c : {glm::vec3(-1.5f, -1.5f, 0), glm::vec3(1.5f, -1.5f, 0), glm::vec3(1.5f, 1.5f, 0), glm::vec3(-1.5f, 1.5f, 0)}) {
        s.positions.push_back(c);
        s.normals.push_back(floor_n);
    }
    for (const glm::vec3 c : {glm::vec3(0.5f, -0.8f, 0.2f), glm::vec3(1.3f, -0.8f, 1.0f), glm::vec3(1.3f, 0.8f, 1.0f), glm::vec3(0.5f, 0.8f, 0.2f)}) {
        s.positions.push_back(c);
        s.normals.push_back(panel_n);
    }
    s.triangles = {{0, 1, 2}, {0, 2, 3}, {4, 5, 6}, {4, 6, 7}};
    s.material_of = {0, 0, 1, 1};
    camera cam;
    cam.position = {-0.5f, -3.f, 3.f};
    cam.look_at = {0.2f, 0.f, 0.3f};
    cam.fov_y_deg = 50.f;
    const gl::scene_mesh mesh(s);
    gl::gbuffer_pass gpass;
    gpass.render(mesh, cam, W, H);
    auto gb = gpass.read();

    // Records where the G-buffer says, with its normals: the records a scan would make.
    pcg32 rng(31);
    std::vector<irradiance_record> recs;
    for (int i = 0; i < 5000 && recs.size() < 150; ++i) {
        const std::size_t x = rng.next_u32() % W, y = rng.next_u32() % H;
        if (!gb.view().covered(x, y)) continue;
        irradiance_record r = random_record(rng);
        r.position = gb.position(x, y);
        r.normal = gb.normal(x, y);
        recs.push_back(r);
    }
    REQUIRE(recs.size() == 150);
    gl::splat_params sp;
    sp.a = 0.3f;
    gl::splat_pass pass;
    pass.upload(recs);
    pass.clear(W, H);
    pass.splat(gl::textures_of(gpass), cam, sp, weighting_kind::ward_smooth);
    const auto from_textures = pass.read_splat();
    const gl::gbuffer_upload uploaded(gb.view());
    pass.clear(W, H);
    pass.splat(uploaded.textures(), cam, sp, weighting_kind::ward_smooth);
    // The read-back holds the textures' exact floats: the same splat, bit for bit.
    CHECK(std::memcmp(from_textures.data(), pass.read_splat().data(), W * H * sizeof(glm::vec4)) == 0);

    // And the CPU splat of the read-back agrees within the bounds of the header comment
    // (records on the G-buffer with its own normals: n.nk is not exact here, the slack says
    // where that matters).
    cpu::splat_params cp;
    cp.a = sp.a;
    cp.gradients = sp.gradients;
    cp.max_extrapolation = sp.max_extrapolation;
    image<glm::vec4> cpu_buf(W, H, glm::vec4(0.f));
    cpu::splat_records<ward_smooth_weight>(gb.view(), cam, recs, cp, cpu_buf.view());
    double worst = 0;
    std::size_t well_conditioned = 0, weighted = 0;
    compare(from_textures, cpu_buf, bounds_for(gb.view(), recs, weighting_kind::ward_smooth, sp), worst, well_conditioned);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) weighted += cpu_buf(x, y).w > 0.f;
    CHECK(weighted > W * H / 4);

}
