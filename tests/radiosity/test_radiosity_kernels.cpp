// Properties of the radiosity kernels (include/bounce/radiosity/kernels.hpp) against closed forms.
#include <bounce/radiosity/kernels.hpp>
#include <bounce/sampling.hpp>

#include <catch2/catch.hpp>

#include <cmath>
#include <numbers>

#include <glm/glm.hpp>

using namespace bounce;

namespace {

// Random unit vectors on the upper hemisphere (fixed seed), poles and horizon included.
std::vector<glm::dvec3> upper_directions(std::uint64_t seed, int count) {
    std::vector<glm::dvec3> d = {{0, 0, 1}, {1, 0, 0}, {0, 1, 0}, {-1, 0, 0}, {0, -1, 0},
                                 {1, 1, 1e-9}, {0.6, 0.8, 0}, {1, 1, 1}, {-1, 1, 1}, {1, -1, 1}};
    pcg32 rng(seed);
    for (int i = 0; i < count; ++i) {
        const double z = rng.next_float(), phi = 2 * std::numbers::pi * rng.next_float();
        const double r = std::sqrt(std::max(0.0, 1 - z * z));
        d.emplace_back(r * std::cos(phi), r * std::sin(phi), z);
    }
    for (auto& v : d) v = glm::normalize(v);
    return d;
}

}  // namespace

TEST_CASE("the disc form factor is exact on the axis of a facing disc", "[radiosity][kernel]") {
    // A disc of radius R seen on its axis from distance d by a parallel facing differential
    // area: F = R^2 / (d^2 + R^2) (Cohen and Wallace 1993, Table 4.1), which is
    // A / (pi d^2 + A) with A = pi R^2: the oriented-disc formula is exact there.
    for (double d : {0.01, 0.1, 0.5, 1.0, 3.0, 100.0})
        for (double radius : {0.01, 0.2, 1.0, 5.0}) {
            const double area = std::numbers::pi * radius * radius;
            const double f = disc_form_factor<double, glm::dvec3>({0, 0, 0}, {0, 0, 1}, {0, 0, d}, {0, 0, -1}, area);
            CHECK(f == Approx(radius * radius / (d * d + radius * radius)).epsilon(1e-14));
        }
}

TEST_CASE("far from the shooter the disc form factor is the point form factor", "[radiosity][kernel]") {
    // F = A cos_r cos_s / (pi d^2 + A) differs from A cos_r cos_s / (pi d^2) by the factor
    // 1 / (1 + A / (pi d^2)): relative difference A / (pi d^2) at most.
    const auto dirs = upper_directions(11, 200);
    for (const auto& n_s : dirs) {
        const glm::dvec3 shooter(0.3, -0.2, 0.1), receiver(4.0, 5.0, 6.0);
        const glm::dvec3 r = shooter - receiver;
        const double d2 = glm::dot(r, r);
        const glm::dvec3 n_r = glm::normalize(r + glm::dvec3(1, 0, 0));
        const double area = 0.01;
        const double cos_r = std::max(0.0, glm::dot(n_r, r) / std::sqrt(d2));
        const double cos_s = std::max(0.0, -glm::dot(n_s, r) / std::sqrt(d2));
        const double point = area * cos_r * cos_s / (std::numbers::pi * d2);
        const double f = disc_form_factor<double, glm::dvec3>(receiver, n_r, shooter, n_s, area);
        CHECK(std::abs(f - point) <= point * area / (std::numbers::pi * d2) + 1e-18);
    }
}

TEST_CASE("each cosine of the disc form factor is clamped on its own (Listing 39-4 clamps the product)",
          "[radiosity][kernel]") {
    // Receiver and shooter both facing away: cos_r, cos_s < 0, product > 0. No energy flows.
    const double f = disc_form_factor<double, glm::dvec3>({0, 0, 0}, {0, 0, -1}, {0, 0, 1}, {0, 0, 1}, 0.1);
    CHECK(f == 0.0);
    // Only one facing: none either.
    CHECK(disc_form_factor<double, glm::dvec3>({0, 0, 0}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}, 0.1) == 0.0);
    CHECK(disc_form_factor<double, glm::dvec3>({0, 0, 0}, {0, 0, -1}, {0, 0, 1}, {0, 0, -1}, 0.1) == 0.0);
}

TEST_CASE("disc form factors of equal areas are reciprocal and below one", "[radiosity][kernel]") {
    // A_r F_{r->s} = A_s F_{s->r} holds exactly for the formula when A_r = A_s (the geometry
    // is symmetric in the two ends); and F < 1 always, since A / (pi d^2 + A) < 1.
    const auto dirs = upper_directions(12, 300);
    pcg32 rng(13);
    for (std::size_t i = 0; i + 1 < dirs.size(); ++i) {
        const glm::dvec3 p(rng.next_float(), rng.next_float(), rng.next_float());
        const glm::dvec3 q = p + glm::dvec3(rng.next_float() - 0.5, rng.next_float() - 0.5, rng.next_float() - 0.5);
        const double area = 0.5 * rng.next_float();
        const double f_pq = disc_form_factor<double, glm::dvec3>(p, dirs[i], q, dirs[i + 1], area);
        const double f_qp = disc_form_factor<double, glm::dvec3>(q, dirs[i + 1], p, dirs[i], area);
        CHECK(f_pq == Approx(f_qp).epsilon(1e-12).margin(1e-300));
        CHECK(f_pq >= 0.0);
        CHECK(f_pq < 1.0);
    }
}

TEST_CASE("coincident points give a zero, finite form factor", "[radiosity][kernel]") {
    const float f = disc_form_factor<float, glm::vec3>({1, 2, 3}, {0, 0, 1}, {1, 2, 3}, {0, 0, -1}, 0.1f);
    CHECK(f == 0.f);
    const glm::vec3 gain =
        shot_radiosity<float, glm::vec3>({1, 2, 3}, {0, 0, 1}, glm::vec3(0.5f), {1, 2, 3}, {0, 0, -1}, 0.1f,
                                          glm::vec3(10.f), 1.f);
    CHECK(gain == glm::vec3(0.f));
}

TEST_CASE("a shot adds rho times the shooter's unshot radiosity times F times visibility", "[radiosity][kernel]") {
    const glm::dvec3 pr(0, 0, 0), nr(0, 0, 1), ps(0.2, 0.1, 1.5), ns = glm::normalize(glm::dvec3(0.1, 0, -1));
    const glm::dvec3 rho(0.2, 0.5, 0.8), unshot(3, 5, 7);
    const double area = 0.04;
    const double f = disc_form_factor<double, glm::dvec3>(pr, nr, ps, ns, area);
    REQUIRE(f > 0.0);
    for (double v : {0.0, 0.25, 1.0}) {
        const glm::dvec3 gain = shot_radiosity<double, glm::dvec3>(pr, nr, rho, ps, ns, area, unshot, v);
        for (int c = 0; c < 3; ++c) CHECK(gain[c] == Approx(rho[c] * unshot[c] * f * v).epsilon(1e-15).margin(0));
    }
    // The chapter's form, dB_s rho A_s cos cos / (pi d^2 + A_s), is the same number.
    const glm::dvec3 r = ps - pr;
    const double d2 = glm::dot(r, r), cos_r = glm::dot(nr, r) / std::sqrt(d2), cos_s = -glm::dot(ns, r) / std::sqrt(d2);
    CHECK(f == Approx(area * cos_r * cos_s / (std::numbers::pi * d2 + area)).epsilon(1e-14));
}

TEST_CASE("the ambient term adds rho times the ambient radiosity", "[radiosity][kernel]") {
    const glm::dvec3 b(1, 2, 3), rho(0.5, 0.25, 0), amb(4, 4, 4);
    CHECK(radiosity_with_ambient<double, glm::dvec3>(b, rho, amb) == glm::dvec3(3, 3, 3));
}

TEST_CASE("the stereographic projection maps the upper hemisphere onto the unit disc and back", "[radiosity][kernel]") {
    // Round trip: w -> q -> w. In double the error is a few ulps of 1.
    for (const auto& w : upper_directions(21, 2000)) {
        const glm::dvec2 q = stereographic_project<double, glm::dvec3, glm::dvec2>(w * 3.7);
        CHECK(glm::length(q) <= 1.0 + 1e-15);
        const glm::dvec3 back = stereographic_direction<double, glm::dvec3, glm::dvec2>(q);
        CHECK(glm::length(back - w) < 1e-14);
    }
    // The normal lands at the centre, the horizon on the unit circle.
    CHECK(glm::length(stereographic_project<double, glm::dvec3, glm::dvec2>({0, 0, 2})) == 0.0);
    CHECK(glm::length(stereographic_project<double, glm::dvec3, glm::dvec2>({0.6, 0.8, 0})) == Approx(1.0).epsilon(1e-15));
    // Texture coordinates: the square [-1, 1]^2 onto [0, 1]^2.
    const glm::dvec2 uv = stereographic_item_coords<double, glm::dvec3, glm::dvec2>({1, 0, 0});
    CHECK(uv.x == Approx(1.0));
    CHECK(uv.y == Approx(0.5));
}

TEST_CASE("stereographic projection is conformal: a small circle of directions stays a circle", "[radiosity][kernel]") {
    // Directions at angle eps around w project onto a curve whose radius varies by O(eps)
    // relative (a conformal map is a similarity to first order); the orthographic projection
    // of Listing 39-2 would squash it by cos(theta) across the radial direction.
    const double eps = 1e-4;
    for (const auto& w : upper_directions(22, 100)) {
        if (w.z < 0.05) continue;
        const auto tb = orthonormal_basis<double, glm::dvec3>(w);
        const glm::dvec2 c = stereographic_project<double, glm::dvec3, glm::dvec2>(w);
        double lo = 1e300, hi = 0;
        for (int k = 0; k < 16; ++k) {
            const double a = 2 * std::numbers::pi * k / 16;
            const glm::dvec3 v = w + eps * (std::cos(a) * tb[0] + std::sin(a) * tb[1]);
            const double r = glm::length(stereographic_project<double, glm::dvec3, glm::dvec2>(v) - c);
            lo = std::min(lo, r);
            hi = std::max(hi, r);
        }
        // Second-order terms: relative spread of a few eps / w.z.
        CHECK((hi - lo) / hi < 10 * eps / w.z);
    }
}

TEST_CASE("hemicube face coordinates invert and cover every face", "[radiosity][kernel]") {
    int per_face[5] = {0, 0, 0, 0, 0};
    for (const auto& w : upper_directions(31, 5000)) {
        const glm::dvec3 f = hemicube_face_coords<double, glm::dvec3>(w * 2.5);
        const int face = int(f.x);
        REQUIRE(face >= 0);
        REQUIRE(face <= 4);
        ++per_face[face];
        CHECK(f.y >= 0.0);
        CHECK(f.y <= 1.0);
        CHECK(f.z >= 0.0);
        CHECK(f.z <= 1.0);
        // The inverse points the same way: parallel and on the same side.
        const glm::dvec3 d = hemicube_direction<double, glm::dvec3>(f.x, f.y, f.z);
        CHECK(glm::length(glm::cross(glm::normalize(d), w)) < 1e-12);
        CHECK(glm::dot(d, w) > 0.0);
    }
    for (int k = 0; k < 5; ++k) CHECK(per_face[k] > 100);
    // Face centres: the top face's middle is the normal; a side face's bottom middle is its
    // axis on the horizon.
    CHECK(hemicube_face_coords<double, glm::dvec3>({0, 0, 1}) == glm::dvec3(0, 0.5, 0.5));
    CHECK(hemicube_face_coords<double, glm::dvec3>({1, 0, 0}) == glm::dvec3(1, 0.5, 0));
    CHECK(hemicube_face_coords<double, glm::dvec3>({-1, 0, 0}) == glm::dvec3(2, 0.5, 0));
    CHECK(hemicube_face_coords<double, glm::dvec3>({0, 1, 0}) == glm::dvec3(3, 0.5, 0));
    CHECK(hemicube_face_coords<double, glm::dvec3>({0, -1, 0}) == glm::dvec3(4, 0.5, 0));
    // The edge between the top face and a side face: ties go to the top.
    CHECK(hemicube_face_coords<double, glm::dvec3>({1, 0, 1}).x == 0.0);
}

TEST_CASE("a hemicube face's axes, texel map and clip position are hemicube_face_coords' on that face",
          "[radiosity][kernel]") {
    // The table the passes draw a face with (hemicube_face_axes) is the one the lookup's
    // selects encode: a direction's coordinates in its face's frame give back, exactly, the
    // lookup's (face, u, v); the clip position a rasterizer draws it at lands on (u, v).
    for (const auto& w : upper_directions(41, 3000)) {
        const glm::dvec3 l = w * 1.7;
        const glm::dvec3 f = hemicube_face_coords<double, glm::dvec3>(l);
        const auto axes = hemicube_face_axes<glm::dvec3>(int(f.x));
        const glm::dvec3 q = frame_coords<double, glm::dvec3>(l, axes[0], axes[1], axes[2]);
        REQUIRE(q.z > 0.0);
        CHECK(hemicube_coords_on_face<double, glm::dvec3>(q, f.x) == f);
        const glm::dvec4 clip = hemicube_face_clip<double, glm::dvec3, glm::dvec4>(q, f.x, 0.01, 10.0);
        CHECK(clip.w == q.z);
        CHECK(clip.x / clip.w * 0.5 + 0.5 == Approx(f.y).margin(1e-12));
        CHECK(clip.y / clip.w * 0.5 + 0.5 == Approx(f.z).margin(1e-12));
    }
    double row = 0;
    for (int face = 0; face < 5; ++face) {
        const auto axes = hemicube_face_axes<glm::dvec3>(face);
        CHECK(glm::cross(axes[0], axes[1]) == axes[2]);  // right x up = forward
        // The depth range maps onto [-1, 1] along the forward axis.
        const auto depth = [&](double z) {
            const glm::dvec4 c = hemicube_face_clip<double, glm::dvec3, glm::dvec4>({0, 0, z}, double(face), 0.01, 10.0);
            return c.z / c.w;
        };
        CHECK(depth(0.01) == Approx(-1.0));
        CHECK(depth(10.0) == Approx(1.0));
        // The faces tile a buffer of 3 res rows: the top face, then the four half faces.
        CHECK(hemicube_face_first_row(double(face), 64.0) == row);
        row += hemicube_face_rows(double(face), 64.0);
    }
    CHECK(row == 3 * 64.0);
}

TEST_CASE("an element's item-buffer texel is its coordinate's, floored and clamped to the buffer",
          "[radiosity][kernel]") {
    CHECK(item_texel(3.0, 8.0) == 3.0);
    CHECK(item_texel(2.999, 8.0) == 2.0);
    CHECK(item_texel(-0.5, 8.0) == 0.0);
    CHECK(item_texel(8.0, 8.0) == 7.0);
    CHECK(item_texel(1e30, 8.0) == 7.0);
    // The normal looks up the stereographic buffer's centre, the horizon its rim, a point
    // behind the shooter a texel of the buffer's border.
    CHECK(stereographic_item_texel<double, glm::dvec3, glm::dvec2>({0, 0, 2}, 64.0) == glm::dvec2(32, 32));
    CHECK(stereographic_item_texel<double, glm::dvec3, glm::dvec2>({1, 0, 0}, 64.0) == glm::dvec2(63, 32));
    CHECK(stereographic_item_texel<double, glm::dvec3, glm::dvec2>({0, -1, 0}, 64.0) == glm::dvec2(32, 0));
    CHECK(stereographic_item_texel<double, glm::dvec3, glm::dvec2>({0.1, 0.2, -1}, 64.0) == glm::dvec2(63, 63));
    // On the hemicube: the normal in the top face's middle; a side face's axis on the horizon
    // in its bottom row; a point behind the shooter in that bottom row too.
    CHECK(hemicube_item_texel<double, glm::dvec3>({0, 0, 1}, 64.0) == glm::dvec3(0, 32, 32));
    CHECK(hemicube_item_texel<double, glm::dvec3>({1, 0, 0}, 64.0) == glm::dvec3(1, 32, 0));
    CHECK(hemicube_item_texel<double, glm::dvec3>({0, 1, 0.999}, 64.0) == glm::dvec3(3, 32, 31));
    CHECK(hemicube_item_texel<double, glm::dvec3>({-1, 0.2, -0.5}, 64.0) == glm::dvec3(2, 25, 0));
    // A directional light's buffer: the corner lo is texel (0, 0); beyond it, the border.
    const glm::dvec3 t(1, 0, 0), b(0, 1, 0);
    CHECK(parallel_item_texel<double, glm::dvec3, glm::dvec2>({-1, -1, 5}, t, b, {-1, -1}, 32.0, 64.0) == glm::dvec2(0));
    CHECK(parallel_item_texel<double, glm::dvec3, glm::dvec2>({0.5, -2, 0}, t, b, {-1, -1}, 32.0, 64.0) ==
          glm::dvec2(48, 0));
    CHECK(parallel_item_coords<double, glm::dvec3, glm::dvec2>({0.5, 0.25, 7}, t, b, {-1, -1}, 32.0) ==
          glm::dvec2(48, 40));
}

TEST_CASE("a triangle's plane in the shooter's frame holds its corners and faces away from the shooter",
          "[radiosity][kernel]") {
    pcg32 rng(44);
    const auto point = [&] { return glm::dvec3(rng.next_float(), rng.next_float(), rng.next_float()) * 4.0 - 2.0; };
    for (int k = 0; k < 1000; ++k) {
        const glm::dvec3 a = point(), b = point(), c = point(), shooter = point();
        const glm::dvec3 n = glm::normalize(glm::cross(b - a, c - a));
        const glm::dvec3 axis = glm::normalize(point());
        const auto tb = orthonormal_basis<double, glm::dvec3>(axis);
        const auto local = [&](glm::dvec3 p) { return to_shooter_frame<double, glm::dvec3>(p, shooter, tb[0], tb[1], axis); };
        const glm::dvec4 plane = shooter_plane<double, glm::dvec3, glm::dvec4>(n, local(a), tb[0], tb[1], axis);
        CHECK(plane.w >= 0.0);
        CHECK(glm::length(glm::dvec3(plane)) == Approx(1.0));
        for (const glm::dvec3& p : {a, b, c}) CHECK(glm::dot(glm::dvec3(plane), local(p)) == Approx(plane.w).margin(1e-9));
    }
}

TEST_CASE("a light's two hemispheres take a receiver on the plane between them once", "[radiosity][kernel]") {
    const glm::dvec3 light(1, 2, 3), axis(0, 0, 1);
    for (const glm::dvec3& p : {glm::dvec3(4, -2, 3), glm::dvec3(1, 2, 3.5), glm::dvec3(0, 0, 2)}) {
        const double first = light_hemisphere_side<double, glm::dvec3>(p, light, axis, 0.0);
        const double second = light_hemisphere_side<double, glm::dvec3>(p, light, -axis, 1.0);
        CHECK(first + second == 1.0);
    }
    CHECK(light_hemisphere_side<double, glm::dvec3>({4, -2, 3}, light, axis, 0.0) == 1.0);
    CHECK(light_hemisphere_side<double, glm::dvec3>({4, -2, 3}, light, axis, 1.0) == 0.0);
}

TEST_CASE("hemisphere depth is the radial distance mapped from [near, far] to [0, 1]", "[radiosity][kernel]") {
    CHECK(hemisphere_depth<double, glm::dvec3>({0, 3, 4}, 1.0, 11.0) == Approx(0.4));
    CHECK(hemisphere_depth<double, glm::dvec3>({0, 0, 1}, 1.0, 11.0) == 0.0);
}
