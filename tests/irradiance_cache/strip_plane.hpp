#pragma once
// The verification tests' scene (cache/verification.hpp): a plane whose irradiance dips in a
// strip two pixels wide; only records measured inside the strip know it (their radius is
// small there, as the split sphere's is at the Cornell box's ceiling strip in front of the
// light), so the scan, whose records elsewhere reach far, covers the strip with the plane's
// irradiance. A probe per pixel (the truth with Monte Carlo-like noise of a known variance)
// finds it. Shared by the CPU frame's test and the GL frame's.
#include <bounce/cache/verification.hpp>
#include <bounce/camera.hpp>
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/gbuffer.hpp>
#include <bounce/image.hpp>

#include <cmath>
#include <cstdint>
#include <optional>
#include <random>
#include <span>

namespace bounce::strip_test {

constexpr std::size_t size = 64;
constexpr float strip_x = 0.1f, strip_half = 0.015f;  // pixels are about 0.013 wide at 64 x 64: two columns

inline bool in_strip(const glm::vec3& p) { return std::abs(p.x - strip_x) < strip_half; }
inline float truth(const glm::vec3& p) { return in_strip(p) ? 0.4f : 1.f; }

// The plane z = 0 seen from (0, 0, 1): every pixel's point, normal +z, grey albedo.
struct plane_view {
    camera cam;
    gbuffer<float> g;
    plane_view() : g(size, size) {
        for (std::size_t y = 0; y < size; ++y)
            for (std::size_t x = 0; x < size; ++x) {
                const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, size, size);
                g.position(x, y) = cam.position + d;  // d's component along the view axis is 1: z = 0
                g.normal(x, y) = glm::vec3(0, 0, 1);
                g.albedo(x, y) = glm::vec3(0.5f);
                g.depth(x, y) = 1.f;
            }
    }
};

// Records with the truth at their point; radius 0.5 (a zone of 15 pixels at a = 0.4) except
// inside the strip, where a record sees what makes the strip dark nearby.
struct strip_sampler {
    std::size_t calls = 0;
    void operator()(std::span<const glm::vec3> points, std::span<const glm::vec3> normals, std::span<const double>,
                    std::span<std::optional<irradiance_record>> out) {
        for (std::size_t k = 0; k < points.size(); ++k) {
            irradiance_record r;
            r.position = points[k];
            r.normal = normals[k];
            r.irradiance = glm::vec3(truth(points[k]));
            r.radius = in_strip(points[k]) ? 0.003f : 0.5f;
            out[k] = r;
            ++calls;
        }
    }
};

// A probe: the truth plus Gaussian noise of a relative spread 0.3 per ray over 8 rays, the
// variance it reports the true one; deterministic per pixel.
inline probe_estimate noisy_probe(glm::vec3 p, glm::vec3, std::size_t pixel) {
    std::mt19937 rng(std::uint32_t(pixel) * 2654435761u + 7u);
    std::normal_distribution<float> z(0.f, 1.f);
    const float e = truth(p), sd = 0.3f * e / std::sqrt(8.f);
    return {glm::vec3(e + sd * z(rng)), sd * sd, 8};
}

// The cache the strip tests render with: a = 0.4, no gradients, neighbour clamping.
inline cpu::irradiance_cache_options strip_options(std::uint32_t rounds) {
    cpu::irradiance_cache_options o;
    o.splat.a = 0.4f;
    o.splat.gradients = false;
    o.neighbour_clamp = true;
    o.verify.rounds = rounds;
    return o;
}

// Mean |image - truth| (E, red channel) over the strip's pixels and over the others.
struct strip_errors {
    double strip = 0, rest = 0;
    std::size_t strip_pixels = 0;
};

inline strip_errors errors_of(const gbuffer<float>& g, const image<glm::vec3>& irradiance) {
    strip_errors r;
    std::size_t rest = 0;
    for (std::size_t y = 0; y < size; ++y)
        for (std::size_t x = 0; x < size; ++x) {
            const glm::vec3 p = g.position(x, y);
            const double e = std::abs(double(irradiance(x, y).x) - truth(p));
            if (in_strip(p)) {
                r.strip += e;
                ++r.strip_pixels;
            } else {
                r.rest += e;
                ++rest;
            }
        }
    r.strip /= double(r.strip_pixels);
    r.rest /= double(rest);
    return r;
}

}  // namespace bounce::strip_test
