// The splat box contains the projection of every visible point of the sphere and is tight.
#include <bounce/sampling.hpp>
#include <bounce/splat_bounds.hpp>

#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <numbers>

using namespace bounce;

namespace {
struct sphere_case {
    glm::dvec3 c;
    double r;
};

std::vector<sphere_case> cases() {
    std::vector<sphere_case> v = {
        {{0, 0, -5}, 1},          // centred, in front
        {{0, 0, 0}, 1},           // contains the eye
        {{0.3, -0.2, -0.05}, 0.5},  // crosses the near plane
        {{0, 0, 3}, 1},           // behind the camera
        {{0, 0, 1}, 1.2},         // behind, but reaches past the near plane
        {{4, 0, -1}, 3.5},        // beside the eye, crossing the near plane
        {{0, 0, -1.1}, 1},        // tangent region to the near plane
        {{50, 3, -2}, 0.1},       // far outside the frustum
    };
    pcg32 rng(99);
    for (int i = 0; i < 300; ++i)
        v.push_back({{8 * rng.next_double() - 4, 8 * rng.next_double() - 4, 2 - 12 * rng.next_double()},
                     0.01 + 3 * rng.next_double()});
    return v;
}
}  // namespace

TEST_CASE("the splat box holds every visible point of the sphere and touches its extremes", "[splat][bounds]") {
    static const auto all = cases();
    const auto i = GENERATE(range<std::size_t>(0, 308));
    const auto sc = all[i];
    const double near = 0.1, tan_y = std::tan(0.5), aspect = 1.5;
    const auto box = sphere_ndc_bounds<double, glm::dvec3>(sc.c, sc.r, near, tan_y, aspect);

    // Sample the sphere's solid interior and surface densely; project points with depth >= near.
    pcg32 rng(std::uint64_t(i) + 1);
    double xmin = 1e300, xmax = -1e300, ymin = 1e300, ymax = -1e300;
    int visible = 0;
    for (int s = 0; s < 20000; ++s) {
        const glm::dvec3 dir = uniform_hemisphere<double, glm::dvec3, glm::dvec2>({rng.next_double(), rng.next_double()}) *
                               (rng.next_u32() & 1 ? 1.0 : -1.0);
        const double rad = s % 2 ? sc.r : sc.r * std::cbrt(rng.next_double());
        const glm::dvec3 q = sc.c + dir * rad;
        // Also the near plane disc, where the clipped sphere's extremes can lie.
        glm::dvec3 qn = q;
        if (s % 3 == 0) {
            const double h2 = sc.r * sc.r - (near + sc.c.z) * (near + sc.c.z);
            if (h2 >= 0) qn = {sc.c.x + std::sqrt(h2) * dir.x / std::max(1e-12, std::hypot(dir.x, dir.y)),
                               sc.c.y + std::sqrt(h2) * dir.y / std::max(1e-12, std::hypot(dir.x, dir.y)), -near};
        }
        if (-qn.z < near) continue;
        ++visible;
        const double x = qn.x / -qn.z / (tan_y * aspect), y = qn.y / -qn.z / tan_y;
        // Conservative: rounding of the closed form is a few ulp of the slopes involved.
        const double tol = 1e-9 * (1 + std::abs(x) + std::abs(y));
        REQUIRE(x >= box[0] - tol);
        REQUIRE(x <= box[2] + tol);
        REQUIRE(y >= box[1] - tol);
        REQUIRE(y <= box[3] + tol);
        xmin = std::min(xmin, x);
        xmax = std::max(xmax, x);
        ymin = std::min(ymin, y);
        ymax = std::max(ymax, y);
    }
    if (visible == 0) {
        // Nothing in front of the near plane: the box is empty and off screen.
        CHECK(box[0] == 2.0);
        CHECK(box[2] == 2.0);
        return;
    }
    // Tight: 20000 samples of a sphere come within a small fraction of the box width of
    // each edge (the gap shrinks like the square root of the sample spacing near a tangent).
    const double w = box[2] - box[0], h = box[3] - box[1];
    CHECK(xmin - box[0] < 0.05 * w + 1e-9);
    CHECK(box[2] - xmax < 0.05 * w + 1e-9);
    CHECK(ymin - box[1] < 0.05 * h + 1e-9);
    CHECK(box[3] - ymax < 0.05 * h + 1e-9);
}

TEST_CASE("a sphere in front of the camera gets the closed-form box of its tangent cone", "[splat][bounds]") {
    // Centred sphere at distance D: half-angle asin(r/D), so the slope bound is tan(asin(r/D)).
    for (double D : {2.0, 5.0, 100.0})
        for (double r : {0.01, 0.5, 1.5}) {
            const auto box = sphere_ndc_bounds<double, glm::dvec3>({0, 0, -D}, r, 0.01, 1.0, 1.0);
            const double s = std::tan(std::asin(r / D));
            CHECK(box[2] == Approx(s).epsilon(1e-12));
            CHECK(box[0] == Approx(-s).epsilon(1e-12));
            CHECK(box[3] == Approx(s).epsilon(1e-12));
        }
}

TEST_CASE("float and double instantiations of the splat box agree", "[splat][bounds]") {
    pcg32 rng(3);
    for (int i = 0; i < 500; ++i) {
        const glm::dvec3 c(6 * rng.next_double() - 3, 6 * rng.next_double() - 3, -0.5 - 10 * rng.next_double());
        const double r = 0.05 + rng.next_double();
        const auto bd = sphere_ndc_bounds<double, glm::dvec3>(c, r, 0.1, 0.7, 1.3);
        const auto bf = sphere_ndc_bounds<float, glm::vec3>(glm::vec3(c), float(r), 0.1f, 0.7f, 1.3f);
        for (int k = 0; k < 4; ++k) CHECK(bf[k] == Approx(bd[k]).margin(1e-4).epsilon(1e-4));
    }
}
