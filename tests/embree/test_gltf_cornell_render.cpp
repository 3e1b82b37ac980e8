// The Cornell box exported as glTF (tests/io/gltf_writer.hpp, with a scene.json for its
// cosine spot) renders the same reference image as the built-in box: the G-buffer and the
// reference integrator's direct and indirect images agree to float precision (here: bit
// for bit, as the scenes are), with the spot light and with the light quad as an emitter.
#include "../io/gltf_writer.hpp"
#include "../io/scratch_folder.hpp"

#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/io/scene.hpp>

#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace bounce;

namespace {

embree::reference_images render(const io::scene& s) {
    const embree::accel bvh(s);
    gbuffer<float> g = embree::ray_cast_gbuffer(bvh, s, s.camera, 24, 24);
    embree::reference_settings settings;
    settings.hemisphere_samples = 32;
    settings.area_samples = 4;
    return embree::render_reference(bvh, s, g.view(), settings);
}

// The largest difference of two images relative to the brightest pixel of the first.
float largest_difference(const image<glm::vec3>& a, const image<glm::vec3>& b) {
    float top = 0.f, diff = 0.f;
    for (std::size_t y = 0; y < a.height(); ++y)
        for (std::size_t x = 0; x < a.width(); ++x) {
            for (int c = 0; c < 3; ++c) {
                top = std::max(top, std::abs(a(x, y)[c]));
                diff = std::max(diff, std::abs(a(x, y)[c] - b(x, y)[c]));
            }
        }
    return top > 0.f ? diff / top : std::numeric_limits<float>::infinity();
}

}  // namespace

TEST_CASE("the Cornell box exported as glTF renders the built-in box's reference image", "[embree][gltf][cornell]") {
    test::scratch_folder dir;
    const io::scene box = io::cornell_box();
    const io::scene from_gltf = io::load_scene(test::write_as_gltf_scene(box, dir.path(), "cornell"));
    const embree::reference_images a = render(box), b = render(from_gltf);
    CHECK(largest_difference(a.direct, b.direct) <= std::numeric_limits<float>::epsilon());
    CHECK(largest_difference(a.indirect, b.indirect) <= std::numeric_limits<float>::epsilon());
    CHECK(largest_difference(a.combined, b.combined) <= std::numeric_limits<float>::epsilon());

    // The .glb alone lights the box with its emissive quad: the built-in box with
    // use_emission and no spot renders the same.
    io::scene emitting = io::cornell_box();
    emitting.lights.clear();
    emitting.use_emission = true;
    const io::scene alone = io::load_gltf(dir.path() / "cornell.glb");
    const embree::reference_images c = render(emitting), d = render(alone);
    CHECK(largest_difference(c.combined, d.combined) <= std::numeric_limits<float>::epsilon());
}
