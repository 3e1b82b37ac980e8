// The four-lane instantiation of the splat kernel computes, bit for bit, what the scalar
// float instantiation computes, and the CPU splat (lanes, tight boxes) equals the scalar
// kernel summed over every pixel of the image.
#include "plane_view.hpp"

#include <bounce/cpu/lanes.hpp>
#include <bounce/cpu/splatting.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <bit>
#include <cstdint>
#include <limits>
#include <vector>

using namespace bounce;
using cpu::lanes::f32x4;
using cpu::lanes::vec3x4;

namespace {

glm::vec3 unit(pcg32& rng) {
    const glm::vec3 h = uniform_hemisphere<float, glm::vec3, glm::vec2>({rng.next_float(), rng.next_float()});
    return rng.next_u32() & 1 ? h : -h;
}

// One lane's inputs: random, or one of the hard cases of cache/weighting.hpp.
struct lane_input {
    glm::vec3 p, n, albedo, pk, nk, e, rot[3], tr[3];
    float inv_r;
};

lane_input make_input(pcg32& rng, int kind) {
    lane_input in;
    in.pk = {4 * rng.next_float() - 2, 4 * rng.next_float() - 2, 4 * rng.next_float() - 2};
    in.nk = unit(rng);
    in.inv_r = 1.f / (0.01f + 3 * rng.next_float());
    in.p = in.pk + 0.5f * unit(rng) * rng.next_float();
    in.n = glm::normalize(in.nk + 0.6f * unit(rng));
    switch (kind) {
        case 0: in.p = in.pk; in.n = in.nk; break;                         // the record's own point
        case 1: in.n = in.nk * (1.f + 3e-7f); break;                       // n.nk just above 1
        case 2: in.n = glm::normalize(glm::cross(in.nk, unit(rng))); break;  // grazing: n perpendicular to nk
        case 3: in.p = in.pk + 1e-7f * unit(rng); break;                   // a rounding away from pk
        default: break;                                                    // random
    }
    in.albedo = {rng.next_float(), rng.next_float(), rng.next_float()};
    in.e = {10 * rng.next_float(), rng.next_float(), 1e-3f * rng.next_float()};
    for (auto& g : in.rot) g = (rng.next_float() - 0.5f) * 4.f * unit(rng);
    for (auto& g : in.tr) g = (rng.next_float() - 0.5f) * 20.f * unit(rng);
    return in;
}

template <class W, bool G, bool F>
void check_lanes(const lane_input (&in)[4], float a, float max_extrapolation, float front_tolerance) {
    auto gather = [&](auto member) {
        return vec3x4::gather(in[0].*member, in[1].*member, in[2].*member, in[3].*member);
    };
    auto gather_g = [&](glm::vec3 (lane_input::*member)[3], int c) {
        return vec3x4::gather((in[0].*member)[c], (in[1].*member)[c], (in[2].*member)[c], (in[3].*member)[c]);
    };
    const f32x4 inv_r(in[0].inv_r, in[1].inv_r, in[2].inv_r, in[3].inv_r);
    const auto lanes = splat_contribution<W, G, F, f32x4, vec3x4>(
        gather(&lane_input::p), gather(&lane_input::n), gather(&lane_input::albedo), gather(&lane_input::pk),
        gather(&lane_input::nk), inv_r, f32x4(a), gather(&lane_input::e), gather_g(&lane_input::rot, 0),
        gather_g(&lane_input::rot, 1), gather_g(&lane_input::rot, 2), gather_g(&lane_input::tr, 0),
        gather_g(&lane_input::tr, 1), gather_g(&lane_input::tr, 2), f32x4(max_extrapolation),
        f32x4(front_tolerance));
    for (int i = 0; i < 4; ++i) {
        const lane_input& s = in[i];
        const auto scalar = splat_contribution<W, G, F, float, glm::vec3>(s.p, s.n, s.albedo, s.pk, s.nk, s.inv_r, a, s.e,
                                                                      s.rot[0], s.rot[1], s.rot[2], s.tr[0], s.tr[1],
                                                                      s.tr[2], max_extrapolation, front_tolerance);
        for (int c = 0; c < 4; ++c) {
            INFO("lane " << i << " component " << c << ": " << lanes[c][i] << " vs " << scalar[c]);
            REQUIRE(std::bit_cast<std::uint32_t>(lanes[c][i]) == std::bit_cast<std::uint32_t>(scalar[c]));
        }
    }
}

template <class W>
void check_policy(const lane_input (&in)[4], float a, float max_extrapolation, float front_tolerance) {
    check_lanes<W, true, true>(in, a, max_extrapolation, front_tolerance);
    check_lanes<W, false, true>(in, a, max_extrapolation, front_tolerance);
    check_lanes<W, true, false>(in, a, max_extrapolation, front_tolerance);
    check_lanes<W, false, false>(in, a, max_extrapolation, front_tolerance);
}

}  // namespace

TEST_CASE("each lane of the four-lane splat kernel is bitwise the scalar float kernel", "[lanes][cpu]") {
    const auto seed = GENERATE(range(0, 300));
    pcg32 rng(std::uint64_t(seed) * 7919 + 1);
    lane_input in[4];
    for (int i = 0; i < 4; ++i) in[i] = make_input(rng, int(rng.next_u32() % 6));
    const float a = 0.05f + 0.6f * rng.next_float(), max_extrapolation = 2 * rng.next_float();
    // Ward's in-front test off (1), at its edge (0: any depth below the mean plane) or between.
    const float front = seed % 3 == 0 ? 1.f : seed % 3 == 1 ? 0.f : 0.3f * rng.next_float();
    check_policy<ward_weight>(in, a, max_extrapolation, front);
    check_policy<ward_smooth_weight>(in, a, max_extrapolation, front);
    check_policy<ward_early_reject_weight<>>(in, a, max_extrapolation, front);
    check_policy<ward_scaled_normal_weight>(in, a, max_extrapolation, front);
    check_policy<tabellion_weight>(in, a, max_extrapolation, front);
}

TEST_CASE("the lane vocabulary follows the scalar one at its edges", "[lanes][cpu]") {
    using cpu::lanes::max;
    using cpu::lanes::min;
    using cpu::lanes::select;
    using cpu::lanes::sqrt;
    const f32x4 x(-0.f, 0.f, 1e-38f, 4.f), y(0.f, -0.f, -1e-38f, 4.f);
    for (int i = 0; i < 4; ++i) {
        // min/max pick as bounce::min/max do (b < a ? b : a), signed zeros included.
        CHECK(std::bit_cast<std::uint32_t>(min(x, y)[i]) == std::bit_cast<std::uint32_t>(bounce::min(x[i], y[i])));
        CHECK(std::bit_cast<std::uint32_t>(max(x, y)[i]) == std::bit_cast<std::uint32_t>(bounce::max(x[i], y[i])));
    }
    CHECK(sqrt(f32x4(2.f))[1] == std::sqrt(2.f));
    const auto s = select(x < y, f32x4(1.f), f32x4(2.f));
    CHECK((s[0] == 2.f && s[1] == 2.f && s[2] == 2.f && s[3] == 2.f));
    CHECK(select(x <= y, f32x4(1.f), f32x4(2.f))[3] == 1.f);
}

TEST_CASE("packed loads and the transpose move the same floats as the scalar gathers", "[lanes][cpu]") {
    // 16 packed vec3s with every float distinct (NaN and signed zeros included: bits move,
    // nothing is computed), read from each of the first four offsets.
    std::vector<glm::vec3> row(16);
    for (std::size_t i = 0; i < row.size(); ++i) row[i] = {float(3 * i) + 0.25f, -float(3 * i + 1), float(3 * i + 2) * 1e-3f};
    row[5].y = -0.f;
    row[6].z = std::numeric_limits<float>::quiet_NaN();
    const auto same = [](float a, float b) { return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b); };
    for (std::size_t o = 0; o < 4; ++o) {
        const vec3x4 packed = vec3x4::load_packed(&row[o].x);
        const vec3x4 gathered = vec3x4::gather(row[o], row[o + 1], row[o + 2], row[o + 3]);
        for (int i = 0; i < 4; ++i) {
            CHECK(same(packed.x[i], gathered.x[i]));
            CHECK(same(packed.y[i], gathered.y[i]));
            CHECK(same(packed.z[i], gathered.z[i]));
        }
    }
    const f32x4 r(1.f, 2.f, 3.f, 4.f), g(5.f, 6.f, 7.f, 8.f), b(9.f, 10.f, 11.f, 12.f), w(13.f, 14.f, 15.f, 16.f);
    const auto t = cpu::lanes::transpose(r, g, b, w);
    for (int i = 0; i < 4; ++i) {
        CHECK(t[std::size_t(i)][0] == r[i]);
        CHECK(t[std::size_t(i)][1] == g[i]);
        CHECK(t[std::size_t(i)][2] == b[i]);
        CHECK(t[std::size_t(i)][3] == w[i]);
    }
    float out[4];
    t[2].store(out);
    CHECK((out[0] == 3.f && out[1] == 7.f && out[2] == 11.f && out[3] == 15.f));
}

TEST_CASE("the CPU splat is the scalar kernel summed over every pixel, bit for bit", "[lanes][splat][cpu]") {
    // A tilted plane (depth varies across the image) with a hole; zones from a fraction of
    // a pixel to a third of the image, records on and off the plane, normals near and far.
    const glm::vec3 plane_n = glm::normalize(glm::vec3(0.3f, -0.2f, 1.f));
    cpu_test::plane_view v(97, 61, plane_n, true);
    const auto seed = GENERATE(range(0, 12));
    pcg32 rng(std::uint64_t(seed) + 100);
    cpu::splat_params sp;
    sp.a = 0.05f + 0.5f * rng.next_float();
    sp.gradients = seed % 3 != 0;
    std::vector<irradiance_record> recs(200);
    for (auto& r : recs) {
        const std::size_t x = rng.next_u32() % 97, y = rng.next_u32() % 61;
        r.position = v.gb.depth(x, y) < 1e30f ? v.gb.position(x, y) : glm::vec3(rng.next_float(), rng.next_float(), 0.f);
        if (rng.next_u32() % 4 == 0) r.position += 0.05f * unit(rng);
        r.normal = rng.next_u32() % 3 ? plane_n : glm::normalize(plane_n + 0.5f * unit(rng));
        r.radius = 0.02f * std::pow(500.f, rng.next_float());
        r.irradiance = {rng.next_float(), rng.next_float(), rng.next_float()};
        r.rotation[0] = 0.1f * unit(rng);
        r.translation[1] = unit(rng);
    }
    auto brute = [&]<class W>(W) {
        image<glm::vec4> out(97, 61, glm::vec4(0.f));
        for (const auto& r : recs) {
            const float cull2 = cpu::detail::culling_radius2<W>(r, sp.a);
            for (std::size_t y = 0; y < 61; ++y)
                for (std::size_t x = 0; x < 97; ++x)
                    if (v.gb.depth(x, y) < 1e30f) {
                        const glm::vec4 c = cpu::detail::contribution<W>(r, v.gb.position(x, y), v.gb.normal(x, y),
                                                                         v.gb.albedo(x, y), sp, cull2);
                        if (c.w > 0.f) out(x, y) += c;
                    }
        }
        return out;
    };
    auto check = [&]<class W>(W w) {
        const image<glm::vec4> expected = brute(w);
        image<glm::vec4> tiled(97, 61, glm::vec4(0.f)), one_by_one(97, 61, glm::vec4(0.f));
        cpu::splat_records<W>(v.gb.view(), v.cam, recs, sp, tiled.view(), 16);
        for (const auto& r : recs) cpu::splat_record<W>(v.gb.view(), v.cam, r, sp, one_by_one.view());
        std::size_t reached = 0;
        for (std::size_t y = 0; y < 61; ++y)
            for (std::size_t x = 0; x < 97; ++x) {
                reached += expected(x, y).w > 0.f;
                for (int c = 0; c < 4; ++c) {
                    INFO(W::name << " pixel " << x << "," << y);
                    REQUIRE(std::bit_cast<std::uint32_t>(tiled(x, y)[c]) == std::bit_cast<std::uint32_t>(expected(x, y)[c]));
                    REQUIRE(std::bit_cast<std::uint32_t>(one_by_one(x, y)[c]) ==
                            std::bit_cast<std::uint32_t>(expected(x, y)[c]));
                }
            }
        CHECK(reached > 97 * 61 / 4);  // the records do reach the image
    };
    check(ward_weight{});
    check(ward_smooth_weight{});
    check(tabellion_weight{});
}
