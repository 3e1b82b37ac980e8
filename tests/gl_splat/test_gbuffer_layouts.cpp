// A renderer's own G-buffer textures: normals in RGB32F and albedo in 8-bit RGBA, named by
// their GL ids, splat and read back as bounce's all-RGBA32F layout does.
#include "../gl/shared_context.hpp"

#include <bounce/gl/splat_pass.hpp>
#include <bounce/sampling.hpp>

#include <epoxy/gl.h>  // the test makes its textures as a renderer would
#include <catch2/catch.hpp>

#include <cmath>
#include <vector>

using namespace bounce;

namespace {

constexpr std::size_t W = 40, H = 30;

// A floor seen from above: every pixel covered, albedo in exact multiples of 1/255 so that
// an 8-bit texture holds it without rounding.
gbuffer<float> floor_gbuffer(const camera& cam) {
    gbuffer<float> g(W, H);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            const glm::vec3 d = cam.direction(float(x) + 0.5f, float(y) + 0.5f, W, H);
            const float t = -cam.position.z / d.z;
            g.position(x, y) = cam.position + t * d;
            g.normal(x, y) = {0.f, 0.f, 1.f};
            g.depth(x, y) = t * glm::dot(d, cam.forward());
            g.albedo(x, y) = glm::vec3(float((x * 7) % 256), float((y * 11) % 256), float((x + y) % 256)) / 255.f;
        }
    return g;
}

// A texture of the renderer's, filled from CPU rows (row 0 at the top, flipped for GL).
GLuint renderer_texture(GLenum internal, GLenum format, GLenum type, const void* rows, std::size_t texel_bytes) {
    GLuint t = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &t);
    glTextureStorage2D(t, 1, internal, GLsizei(W), GLsizei(H));
    const auto* bytes = static_cast<const unsigned char*>(rows);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    for (std::size_t y = 0; y < H; ++y)
        glTextureSubImage2D(t, 0, 0, GLint(H - 1 - y), GLsizei(W), 1, format, type, bytes + y * W * texel_bytes);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 4);
    return t;
}

}  // namespace

TEST_CASE("a renderer's RGB32F normals and RGBA8 albedo splat and read back as the RGBA32F layout does",
          "[gl][splat][gbuffer]") {
    gl_test::shared_context();
    camera cam;
    cam.position = {0.f, -0.5f, 2.f};
    cam.look_at = {0.f, 0.f, 0.f};
    gbuffer<float> g = floor_gbuffer(cam);

    gl::gbuffer_upload reference;  // bounce's layout: three RGBA32F textures
    reference.upload(g.view());

    std::vector<glm::vec3> normals(W * H);
    std::vector<glm::u8vec4> albedo(W * H);
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            normals[y * W + x] = g.normal(x, y);
            albedo[y * W + x] = glm::u8vec4(glm::round(g.albedo(x, y) * 255.f), 255);
        }
    const GLuint normal_name = renderer_texture(GL_RGB32F, GL_RGB, GL_FLOAT, normals.data(), sizeof(glm::vec3));
    const GLuint albedo_name = renderer_texture(GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, albedo.data(), 4);
    const gl::gbuffer_textures own{reference.textures().position_depth, gl::texture_ref::of(normal_name, "normal"),
                                   gl::texture_ref::of(albedo_name, "albedo")};
    CHECK(own.normal.format == gl::texel_format::rgb32f);
    CHECK(own.albedo.format == gl::texel_format::rgba8);

    // Reading back: normals exactly; albedo as the 8-bit codes' unorm values, c / 255, which
    // are the floats we stored up to float rounding of the division (half an ulp each way).
    gbuffer<float> back(W, H);
    gl::read_gbuffer(own, back.view());
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            CHECK(back.normal(x, y) == g.normal(x, y));
            CHECK(back.position(x, y) == g.position(x, y));
            for (int c = 0; c < 3; ++c) CHECK(std::abs(back.albedo(x, y)[c] - g.albedo(x, y)[c]) <= 1.2e-7f);
        }

    // Splatting: the same records over both layouts give the same buffer (the albedo enters
    // each term as one factor, so its half-ulp differences stay below 1e-6 relative).
    std::vector<irradiance_record> records;
    pcg32 rng(5);
    for (int k = 0; k < 40; ++k) {
        irradiance_record r;
        const std::size_t x = rng.next_u32() % W, y = rng.next_u32() % H;
        r.position = g.position(x, y);
        r.normal = g.normal(x, y);
        r.irradiance = glm::vec3(1.f + rng.next_float(), 2.f, 0.5f);
        r.radius = 0.5f + rng.next_float();
        records.push_back(r);
    }
    splat_params sp;
    sp.a = 0.3f;
    gl::splat_pass a, b;
    a.upload(records);
    b.upload(records);
    a.clear(W, H);
    b.clear(W, H);
    a.splat(reference.textures(), cam, sp, weighting_kind::ward_smooth);
    b.splat(own, cam, sp, weighting_kind::ward_smooth);
    const image<glm::vec4> sa = a.read_splat(), sb = b.read_splat();
    double worst = 0;
    std::size_t reached = 0;
    for (std::size_t y = 0; y < H; ++y)
        for (std::size_t x = 0; x < W; ++x) {
            reached += sa(x, y).w > 0.f ? 1 : 0;
            CHECK(sb(x, y).w == sa(x, y).w);  // weights do not depend on the albedo
            for (int c = 0; c < 3; ++c)
                worst = std::max(worst, double(std::abs(sb(x, y)[c] - sa(x, y)[c])) / std::max(1e-6, double(sa(x, y)[c])));
        }
    CHECK(reached > W * H / 4);
    CHECK(worst <= 1e-6);

    // What a pass cannot read is refused, naming what is wrong.
    GLuint rg = 0;
    glCreateTextures(GL_TEXTURE_2D, 1, &rg);
    glTextureStorage2D(rg, 1, GL_RG16F, GLsizei(W), GLsizei(H));
    CHECK_THROWS_WITH(gl::texture_ref::of(rg, "normal"), Catch::Contains("normal") && Catch::Contains("internal format"));
    CHECK_THROWS_WITH(gl::texture_ref::of(987654u, "albedo"), Catch::Contains("albedo") && Catch::Contains("not a texture"));
    gl::gbuffer_textures wrong = own;
    wrong.position_depth = own.normal;  // depth needs a w channel
    CHECK_THROWS_AS(wrong.validate(), parameter_error);
    const GLuint names[3] = {normal_name, albedo_name, rg};
    glDeleteTextures(3, names);
}
