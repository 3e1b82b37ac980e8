// Properties of the weighting policies and of record extrapolation, on random and
// adversarial inputs: the singular point, n.nk above 1, grazing normals, the zone border.
#include <bounce/cache/record.hpp>
#include <bounce/sampling.hpp>
#include <bounce/cache/weighting.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <cmath>
#include <span>

using namespace bounce;

namespace {
glm::vec3 random_unit(pcg32& rng) {
    const glm::dvec2 u(rng.next_double(), rng.next_double());
    const double z = 2 * u.x - 1, r = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * std::numbers::pi * u.y;
    return glm::normalize(glm::vec3(float(r * std::cos(phi)), float(r * std::sin(phi)), float(z)));
}

struct query {
    glm::vec3 p, n, pk, nk;
    float r, a;
};

// Random queries near a record, then the cases that break naive code.
std::vector<query> queries() {
    pcg32 rng(1234);
    std::vector<query> q;
    for (int i = 0; i < 400; ++i) {
        const glm::vec3 nk = random_unit(rng);
        glm::vec3 n = glm::normalize(nk + 0.6f * random_unit(rng));
        const float r = 0.05f + 3 * rng.next_float(), a = 0.05f + 0.9f * rng.next_float();
        const glm::vec3 pk = 10.f * random_unit(rng);
        const glm::vec3 p = pk + random_unit(rng) * (2.f * a * r * rng.next_float());
        q.push_back({p, n, pk, nk, r, a});
    }
    const glm::vec3 nk = glm::normalize(glm::vec3(0.3f, -0.2f, 0.9f));
    q.push_back({{1, 2, 3}, nk, {1, 2, 3}, nk, 1.f, 0.2f});                      // the singular point
    q.push_back({{1, 2, 3}, nk * 1.0000003f, {1, 2, 3}, nk, 1.f, 0.2f});         // n.nk > 1
    q.push_back({{1, 2, 3}, nk * 1.0000003f, {1, 2, 3}, nk * 1.0000003f, 1e-6f, 0.2f});
    q.push_back({{1, 2, 3.0001f}, nk, {1, 2, 3}, nk, 1e-3f, 0.1f});             // tiny radius
    q.push_back({{1, 2, 3}, -nk, {1, 2, 3}, nk, 1.f, 0.9f});                     // opposite normals
    q.push_back({{0, 0, 0}, {1, 0, 0}, {0, 0, 0}, {0, 1, 0}, 1.f, 0.5f});        // grazing: 90 degrees
    q.push_back({{0.2f, 0, 0}, nk, {0, 0, 0}, nk, 1.f, 0.2f});                   // exactly on the border
    return q;
}

template <class W>
float w_of(const query& q) {
    return W::template weight<float, glm::vec3>(q.p, q.n, q.pk, q.nk, 1.f / q.r, q.a);
}
}  // namespace

TEMPLATE_TEST_CASE("every weight is finite, non-negative and zero outside the zone of influence",
                   "[weighting]", ward_weight, ward_smooth_weight, ward_early_reject_weight<>, ward_scaled_normal_weight,
                   tabellion_weight) {
    static const auto qs = queries();
    const auto i = GENERATE(range<std::size_t>(0, 407));
    const auto& q = qs[i];
    const float w = w_of<TestType>(q);
    CHECK(std::isfinite(w));
    CHECK(w >= 0.f);
    // Capped by the inverse-weight floor (Ward forms) or by 1 (Tabellion).
    CHECK(w <= float(1 / inverse_weight_floor) * (1 + 1e-6f));
    const float zone = TestType::template influence_radius<float>(q.r, q.a);
    // A point outside the zone gets no weight, for every normal. Rounding of |p - pk| / R
    // is a few ulp: allow that margin at the border.
    if (glm::length(q.p - q.pk) > zone * (1 + 1e-5f)) CHECK(w == 0.f);
}

TEST_CASE("Ward's weight is 1/inverse weight, contributes exactly where w >= 1/a, and survives the singularity",
          "[weighting]") {
    static const auto qs = queries();
    const auto i = GENERATE(range<std::size_t>(0, 407));
    const auto& q = qs[i];
    const double inv = glm::length(glm::dvec3(q.p - q.pk)) / q.r +
                       std::sqrt(std::max(0.0, 1.0 - glm::dot(glm::dvec3(q.n), glm::dvec3(q.nk)) - normal_rounding));
    const double expected = inv <= q.a ? 1.0 / std::max(inv, inverse_weight_floor) : 0.0;
    const float w = w_of<ward_weight>(q);
    // Away from the border the float result matches the double closed form to float rounding
    // of a few operations; at the border itself both answers are acceptable.
    if (std::abs(inv - q.a) > 1e-5 * q.a) CHECK(w == Approx(expected).epsilon(1e-5));
    // The smoothed weight is Ward's minus 1/a, so it vanishes continuously at the border.
    const float ws = w_of<ward_smooth_weight>(q);
    if (w > 0.f) CHECK(ws == Approx(w - 1.f / q.a).margin(1e-5 * w));
    else CHECK(ws == 0.f);
    // The GPU form with the normal scale of Eq. 8.2 is the same function: its early
    // rejection e1 + e2 > a^2 never removes a contributing record.
    const float wg = w_of<ward_early_reject_weight<>>(q);
    if (std::abs(inv - q.a) > 1e-5 * q.a) CHECK(wg == Approx(w).epsilon(1e-5));
}

TEST_CASE("equal normals give the capped weight at a record's own position, whatever the rounding", "[weighting][stability]") {
    // Normals as a G-buffer and a sampler would hold them: the same direction normalized
    // from different float inputs, so n.nk is 1 only to within a few ulps.
    pcg32 rng(31);
    for (int i = 0; i < 2000; ++i) {
        const glm::vec3 n = random_unit(rng);
        const glm::vec3 nk = glm::normalize(n * (0.5f + 3.f * rng.next_float()));
        const glm::vec3 p = 20.f * random_unit(rng);
        const float r = 1e-3f + rng.next_float(), a = 0.05f + 0.5f * rng.next_float();
        const float cap = float(1 / inverse_weight_floor);
        REQUIRE(ward_weight::weight<float, glm::vec3>(p, n, p, nk, 1.f / r, a) == cap);
        REQUIRE(ward_smooth_weight::weight<float, glm::vec3>(p, n, p, nk, 1.f / r, a) == cap - 1.f / a);
        REQUIRE(ward_early_reject_weight<>::weight<float, glm::vec3>(p, n, p, nk, 1.f / r, a) == cap);
        REQUIRE(normal_divergence<float, glm::vec3>(n, nk) == 0.f);
        // In double the same holds, and a real divergence of 0.1 degrees still counts.
        REQUIRE(normal_divergence<double, glm::dvec3>(glm::dvec3(n), glm::normalize(glm::dvec3(nk))) == 0.0);
    }
    const double t = 0.1 * std::numbers::pi / 180;
    const glm::dvec3 n(0, 0, 1), m(std::sin(t), 0, std::cos(t));
    REQUIRE(normal_divergence<double, glm::dvec3>(n, m) == Approx(std::sqrt(1 - std::cos(t) - normal_rounding)).epsilon(1e-12));
    REQUIRE(normal_divergence<double, glm::dvec3>(n, m) > 0.5 * std::sqrt(1 - std::cos(t)));
}

TEST_CASE("the smoothed weight falls continuously to zero at the border of the zone", "[weighting]") {
    const glm::vec3 n(0, 0, 1), pk(0.f);
    const float r = 2.f, a = 0.25f;
    float prev = 1e30f;
    for (int s = 0; s <= 1000; ++s) {
        const float dist = a * r * float(s) / 1000.f;
        const float w = ward_smooth_weight::weight<float, glm::vec3>({dist, 0, 0}, n, pk, n, 1.f / r, a);
        CHECK(w <= prev);  // monotone in distance
        prev = w;
    }
    // w' = R/d - 1/a; at d = aR(1 - eps) that is ~eps/a: small just inside the border.
    const float inside = ward_smooth_weight::weight<float, glm::vec3>({a * r * 0.999f, 0, 0}, n, pk, n, 1.f / r, a);
    CHECK(inside == Approx(0.001f / (0.999f * a)).epsilon(1e-2));
    CHECK(ward_smooth_weight::weight<float, glm::vec3>({a * r * 1.001f, 0, 0}, n, pk, n, 1.f / r, a) == 0.f);
}

TEST_CASE("float accumulation of thousands of records matches double within the rounding bound", "[weighting][stability]") {
    // 10,000 records spread around one point, some right on it (capped weights).
    pcg32 rng(77);
    const glm::vec3 p(0.f), n(0, 0, 1);
    float sum_f = 0.f;
    double sum_d = 0.0, sum_abs = 0.0;
    for (int k = 0; k < 10000; ++k) {
        const glm::vec3 pk = k % 1000 == 0 ? p : random_unit(rng) * (0.2f * rng.next_float());
        const glm::vec3 nk = glm::normalize(n + 0.1f * random_unit(rng));
        const float w = ward_weight::weight<float, glm::vec3>(p, n, pk, nk, 1.f, 0.5f);
        sum_f += w;
        sum_d += double(w);
        sum_abs += std::abs(double(w));
    }
    // Recursive summation: |error| <= (n - 1) u sum|w| with u = 2^-24 (Higham, Accuracy and
    // Stability, Eq. 4.4); the cap on weights keeps the sum finite.
    CHECK(std::isfinite(sum_f));
    CHECK(std::abs(double(sum_f) - sum_d) <= 9999 * 0x1p-24 * sum_abs);
}

TEST_CASE("extrapolation is exact at the record, first order nearby, and bounded", "[record]") {
    pcg32 rng(5);
    for (int i = 0; i < 300; ++i) {
        const glm::vec3 nk = random_unit(rng), pk = random_unit(rng);
        const glm::vec3 e(1.f + rng.next_float(), 2.f, 0.5f);
        glm::vec3 gr[3], gt[3];
        for (auto& g : gr) g = random_unit(rng) * rng.next_float();
        for (auto& g : gt) g = random_unit(rng) * rng.next_float();
        auto ext = [&](glm::vec3 p, glm::vec3 n, float m) {
            return extrapolated_irradiance<float, glm::vec3>(p, n, pk, nk, e, gr[0], gr[1], gr[2], gt[0], gt[1], gt[2], m);
        };
        CHECK(glm::length(ext(pk, nk, 1.f) - e) == 0.f);
        // A small move d and a small rotation by alpha about a tangent t.
        const auto tb = orthonormal_basis<float, glm::vec3>(nk);
        const float alpha = 1e-3f;
        const glm::vec3 n2 = glm::normalize(nk + alpha * glm::cross(tb[0], nk));
        const glm::vec3 d = 1e-3f * random_unit(rng);
        const glm::vec3 got = ext(pk + d, n2, 1.f);
        for (int c = 0; c < 3; ++c) {
            const float expected = e[c] + alpha * glm::dot(tb[0], gr[c]) + glm::dot(d, gt[c]);
            CHECK(got[c] == Approx(expected).margin(1e-5));
        }
        // Far away the gradient term is clamped to +-m E.
        const glm::vec3 far = ext(pk + 1e4f * random_unit(rng), -nk, 0.5f);
        for (int c = 0; c < 3; ++c) {
            CHECK(far[c] >= 0.5f * e[c] * (1 - 1e-6f));
            CHECK(far[c] <= 1.5f * e[c] * (1 + 1e-6f));
        }
    }
}

TEST_CASE("Ward's in-front test keeps planes and spheres, cuts steps at the tolerance, and is off at 1",
          "[record][weighting]") {
    const auto seed = GENERATE(range(0, 200));
    pcg32 rng(std::uint64_t(seed) + 4000);
    const float a = 0.1f + 0.5f * rng.next_float(), r = 0.1f + 2 * rng.next_float(), inv_r = 1.f / r;
    const glm::vec3 nk = random_unit(rng), pk = random_unit(rng);
    const auto in_front = [&](glm::vec3 p, glm::vec3 n, glm::vec3 k, glm::vec3 nrm, float tolerance) {
        return record_in_front<float, glm::vec3>(p, n, k, nrm, inv_r, a, tolerance);
    };
    // Two points of one sphere (radius rho, centre c), normals radial, outwards (convex) or
    // inwards (concave): (p - pk) . (n + nk) = 0 exactly, so a small tolerance keeps them.
    const float rho = r * (0.2f + 5 * rng.next_float());
    const float side = seed % 2 ? 1.f : -1.f;
    const glm::vec3 c = pk - side * rho * nk;
    const glm::vec3 on_sphere = c + rho * glm::normalize(pk - c + random_unit(rng) * (a * r * rng.next_float()));
    if (glm::length(on_sphere - pk) <= a * r)
        CHECK_FALSE(in_front(on_sphere, side * glm::normalize(on_sphere - c), pk, nk, 0.01f));
    // A step of height h below the record's plane, n = nk: cut exactly where h > tolerance a R.
    const float tolerance = 0.02f + 0.3f * rng.next_float();
    const auto tb = orthonormal_basis<float, glm::vec3>(nk);
    const glm::vec3 along = (tb[0] * (rng.next_float() - 0.5f) + tb[1] * (rng.next_float() - 0.5f)) * (a * r);
    const float h = tolerance * a * r;
    CHECK(in_front(pk + along - 1.01f * h * nk, nk, pk, nk, tolerance));
    CHECK_FALSE(in_front(pk + along - 0.99f * h * nk, nk, pk, nk, tolerance));
    CHECK_FALSE(in_front(pk + along + h * nk, nk, pk, nk, tolerance));  // above the plane: never
    // Tolerance 1 is off: no point inside the zone lies a R below the mean plane.
    const glm::vec3 p = pk + random_unit(rng) * (0.999f * a * r * std::sqrt(rng.next_float()));
    const glm::vec3 n = random_unit(rng);
    CHECK_FALSE(in_front(p, n, pk, nk, 1.f));
    // And splat_contribution is zero where the test cuts, unchanged elsewhere.
    const glm::vec3 e(1.f, 2.f, 3.f), z(0.f), albedo(0.5f);
    const auto contribution = [&](glm::vec3 q, float tol) {
        return splat_contribution<ward_weight, true, true, float, glm::vec3>(q, nk, albedo, pk, nk, inv_r, a, e, z, z, z,
                                                                             z, z, z, 1.f, tol);
    };
    const auto without_test = [&](glm::vec3 q) {
        return splat_contribution<ward_weight, true, false, float, glm::vec3>(q, nk, albedo, pk, nk, inv_r, a, e, z, z, z,
                                                                              z, z, z, 1.f, 0.f);
    };
    const glm::vec3 below = pk + 0.5f * along - 1.5f * h * nk;
    CHECK(contribution(below, 1.f)[3] > 0.f);
    CHECK(contribution(below, 1.f) == without_test(below));
    CHECK(contribution(below, tolerance) == std::array<float, 4>{0.f, 0.f, 0.f, 0.f});
    const glm::vec3 level = pk + 0.5f * along - 0.5f * h * nk;
    CHECK(contribution(level, tolerance) == without_test(level));
}

TEST_CASE("radius limits apply the gradient limit, then world and pixel clamps", "[record]") {
    const std::array<glm::dvec3, 3> g{glm::dvec3(2, 0, 0), glm::dvec3(0, 0.5, 0), glm::dvec3(0)};
    const glm::dvec3 e(1, 1, 1);
    radius_limits lim;
    CHECK(limit_radius(3.0, e, g, lim, 0.0) == Approx(0.5f));  // E/|g| = 1/2 on the red channel
    lim.gradient_limit = false;
    CHECK(limit_radius(3.0, e, g, lim, 0.0) == Approx(3.f));
    lim.max_world = 2.f;
    CHECK(limit_radius(3.0, e, g, lim, 0.0) == Approx(2.f));
    lim.min_pixels = 3.f;
    lim.max_pixels = 10.f;
    CHECK(limit_radius(3.0, e, g, lim, 0.1) == Approx(1.f));    // 10 px * 0.1
    CHECK(limit_radius(0.01, e, g, lim, 0.1) == Approx(0.3f));  // 3 px * 0.1
    CHECK(limit_radius(std::numeric_limits<double>::infinity(), e, g, lim, 0.1) == Approx(1.f));
}

TEST_CASE("neighbour clamping makes radii 1-Lipschitz", "[record]") {
    pcg32 rng(8);
    std::vector<irradiance_record> recs(200);
    for (auto& r : recs) {
        r.position = 5.f * random_unit(rng) * rng.next_float();
        r.radius = 0.01f + 4 * rng.next_float() * rng.next_float();
    }
    // Clamp in creation order, as a cache does when records arrive.
    for (std::size_t i = 1; i < recs.size(); ++i)
        recs[i].radius = neighbour_clamped_radius(recs[i], std::span(recs.data(), i));
    for (std::size_t i = 1; i < recs.size(); ++i)
        for (std::size_t j = 0; j < i; ++j)
            CHECK(recs[i].radius <= recs[j].radius + glm::length(recs[i].position - recs[j].position) + 1e-6f);
}

namespace {
// A class template over a policy, standing in for cpu::irradiance_cache<Weight>.
template <class Weight>
struct policy_holder {
    float weight_at(const query& q) const { return w_of<Weight>(q); }
};
}  // namespace

TEST_CASE("policy types and weighting kinds map both ways, by name too", "[weighting][vocabulary]") {
    static_assert(weighting_kind_of<ward_smooth_weight> == weighting_kind::ward_smooth);
    static_assert(weighting_kind_of<const tabellion_weight&> == weighting_kind::tabellion);
    static_assert(named_weighting<ward_scaled_normal_weight> && !named_weighting<ward_early_reject_weight<1, 3>>,
                  "only the policies the GL pass compiles have a kind");
    static_assert(!named_weighting<weighting_kind>);
    for (const weighting_kind k : weighting_kinds) {
        CHECK(with_weighting(k, [](auto w) { return weighting_kind_of<decltype(w)>; }) == k);
        CHECK(parse_weighting(weighting_name(k)) == k);
    }
    CHECK(weighting_name(weighting_kind::ward_early_reject) == "ward-gpu");
    CHECK(weighting_name(weighting_kind::ward_scaled_normal) == "ward-gpu-shader");
    CHECK_FALSE(parse_weighting("Ward").has_value());
    CHECK_FALSE(parse_weighting("").has_value());

    // A policy-templated type chosen at run time: the variant holds the kind's instantiation
    // and weighs exactly as that policy does.
    const std::vector<query> qs = queries();
    for (const weighting_kind k : weighting_kinds) {
        const weighting_variant<policy_holder> held =
            with_weighting(k, [](auto w) { return weighting_variant<policy_holder>(policy_holder<decltype(w)>{}); });
        CHECK(held.index() == std::size_t(k));
        for (const query& q : qs) {
            const float by_variant = std::visit([&](const auto& h) { return h.weight_at(q); }, held);
            CHECK(by_variant == with_weighting(k, [&](auto w) { return w_of<decltype(w)>(q); }));
        }
    }
}
