// The raster G-buffer (OpenGL) and the ray-cast one (Embree) see the same surfaces through
// the same pixel centres: they agree pixel by pixel except along silhouettes, where a
// rasterizer's coverage rule and a ray's hit can pick different sides of an edge.
#include "../skip.hpp"

#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/gl/context.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <cmath>

using namespace bounce;

namespace {
struct agreement {
    std::size_t pixels = 0, agree = 0;
};

agreement compare(const io::scene& scene, std::size_t w, std::size_t h) {
    static gl::context ctx;
    ctx.make_current();
    gl::scene_mesh mesh(scene);
    gl::gbuffer_pass pass;
    pass.render(mesh, scene.camera, w, h);
    const auto raster = pass.read();
    const embree::accel bvh(scene);
    const auto traced = embree::ray_cast_gbuffer(bvh, scene, scene.camera, w, h);
    // Tolerances: positions are interpolated in float by the rasterizer and intersected in
    // float by Embree, both within ~1e-5 of the scene size; normals within 1e-3; albedo
    // exactly the material's.
    const auto [lo, hi] = scene.bounds();
    const float size = glm::length(hi - lo);
    agreement a;
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            ++a.pixels;
            const bool rc = std::isfinite(raster.depth(x, y)), tc = std::isfinite(traced.depth(x, y));
            if (rc != tc) continue;
            if (!rc) {
                ++a.agree;
                continue;
            }
            const bool same = glm::length(raster.position(x, y) - traced.position(x, y)) <= 1e-4f * size &&
                              glm::dot(raster.normal(x, y), traced.normal(x, y)) >= 0.999f &&
                              raster.albedo(x, y) == traced.albedo(x, y) &&
                              std::abs(raster.depth(x, y) - traced.depth(x, y)) <= 1e-4f * size;
            a.agree += same;
        }
    return a;
}
}  // namespace

TEST_CASE("raster and ray-cast G-buffers of the Cornell box agree on at least 99% of pixels", "[gbuffer][gl][embree]") {
    const auto a = compare(io::cornell_box(), 160, 120);
    CAPTURE(a.pixels, a.agree);
    CHECK(double(a.agree) >= 0.99 * double(a.pixels));
}

TEST_CASE("raster and ray-cast G-buffers of Sponza agree on at least 99% of pixels", "[gbuffer][gl][embree]") {
    const auto file = io::scenes_dir() / "sponza" / "scene.json";
    if (!std::filesystem::exists(file)) {
        bounce::test::skip(file.string() + " not found (set BOUNCE_SCENES)");
        return;
    }
    const auto a = compare(io::load_scene(file), 128, 96);
    CAPTURE(a.pixels, a.agree);
    CHECK(double(a.agree) >= 0.99 * double(a.pixels));
}
