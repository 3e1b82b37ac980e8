// Images: EXR keeps every float bit and PNG follows the sRGB formula.
#include "scratch_folder.hpp"

#include <bounce/io/image_io.hpp>
#include <bounce/sampling.hpp>

#include <OpenImageIO/imageio.h>
#include <catch2/catch.hpp>
#include <glm/glm.hpp>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

using namespace bounce;
using bounce::test::scratch_folder;

namespace {

// Floats over the whole range, signed, with the special values a renderer can produce.
float wild_float(pcg32& rng, int i) {
    constexpr float specials[] = {0.f, -0.f, 1e-40f, -1e-45f, std::numeric_limits<float>::max(),
                                  std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                                  std::numeric_limits<float>::quiet_NaN(), 1.f, 0.5f};
    if (i < 10) return specials[i];
    const float mag = std::ldexp(1.f + rng.next_float(), int(rng.next_u32() % 120) - 60);
    return rng.next_u32() & 1 ? mag : -mag;
}

bool same_bits(float a, float b) {
    return std::bit_cast<std::uint32_t>(a) == std::bit_cast<std::uint32_t>(b) || (std::isnan(a) && std::isnan(b));
}

// IEC 61966-2-1 encoding of a linear value in [0, 1].
double srgb_encode(double x) { return x <= 0.0031308 ? 12.92 * x : 1.055 * std::pow(x, 1 / 2.4) - 0.055; }
double srgb_decode(double v) { return v <= 0.04045 ? v / 12.92 : std::pow((v + 0.055) / 1.055, 2.4); }

// The 8-bit codes of an image file, read through OIIO without any conversion.
std::vector<std::uint8_t> read_codes(const std::filesystem::path& file, int& width, int& channels) {
    auto in = OIIO::ImageInput::open(file.string());
    REQUIRE(in);
    const auto& spec = in->spec();
    width = spec.width;
    channels = spec.nchannels;
    std::vector<std::uint8_t> codes(std::size_t(spec.width) * spec.height * spec.nchannels);
    REQUIRE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, codes.data()));
    return codes;
}

}  // namespace

TEST_CASE("EXR round trips every float bit, through a strided view", "[io][image][exr]") {
    pcg32 rng(23);
    // A 37 x 11 window of a 50-pixel-wide image: rows 50 apart.
    image<glm::vec3> big(50, 11, glm::vec3(-7.f));
    int i = 0;
    for (std::size_t y = 0; y < 11; ++y)
        for (std::size_t x = 0; x < 37; ++x)
            for (int c = 0; c < 3; ++c) big(x, y)[c] = wild_float(rng, i++);
    const image_view<const glm::vec3> window = big.view().subview(0, 0, 37, 11);
    scratch_folder dir;
    const auto file = dir.path() / "rgb.exr";
    io::write_exr(file, window);
    const image<glm::vec3> back = io::read_rgb(file);
    REQUIRE(back.width() == 37);
    REQUIRE(back.height() == 11);
    std::size_t differ = 0;
    for (std::size_t y = 0; y < 11; ++y)
        for (std::size_t x = 0; x < 37; ++x)
            for (int c = 0; c < 3; ++c) differ += same_bits(back(x, y)[c], window(x, y)[c]) ? 0 : 1;
    CHECK(differ == 0);
}

TEST_CASE("single-channel EXR round trips exactly and reads as grey", "[io][image][exr]") {
    pcg32 rng(29);
    image<float> v(13, 17);
    int i = 0;
    for (std::size_t y = 0; y < 17; ++y)
        for (std::size_t x = 0; x < 13; ++x) v(x, y) = wild_float(rng, i++);
    scratch_folder dir;
    io::write_exr(dir.path() / "depth.exr", image_view<const float>(v.view()));
    const image<glm::vec3> back = io::read_rgb(dir.path() / "depth.exr");
    std::size_t differ = 0;
    for (std::size_t y = 0; y < 17; ++y)
        for (std::size_t x = 0; x < 13; ++x)
            for (int c = 0; c < 3; ++c) differ += same_bits(back(x, y)[c], v(x, y)) ? 0 : 1;
    CHECK(differ == 0);
}

TEST_CASE("image files that cannot be read or written raise image_error naming them", "[io][image][bad-input]") {
    scratch_folder dir;
    const image<glm::vec3> img(4, 4, glm::vec3(0.5f));
    const auto nowhere = dir.path() / "no" / "such" / "folder" / "x.exr";
    try {
        io::write_exr(nowhere, img.view());
        FAIL("wrote into a missing folder");
    } catch (const io::image_error& e) {
        CHECK(e.file() == nowhere);
    }
    for (const auto& file : {dir.path() / "missing.exr", dir.write("text.exr", "not an image at all\n"),
                             dir.write("empty.png", ""), dir.path()}) {
        INFO(file);
        try {
            (void)io::read_rgb(file);
            FAIL("read an image that is not there");
        } catch (const io::image_error& e) {
            CHECK(e.file() == file);
            CHECK_THAT(e.what(), Catch::Matchers::Contains(file.string()));
        }
    }
    CHECK_THROWS_AS(io::write_exr(dir.path() / "e.exr", image_view<const glm::vec3>{}), parameter_error);
}

TEST_CASE("PNG codes follow the sRGB formula after exposure and clamping", "[io][image][png]") {
    // Linear value -> code round(255 * srgb(clamp(x * exposure, 0, 1))), NaN -> 0. The
    // values are chosen at least 0.01 code from a rounding tie, so OIIO's transfer
    // function (within 1e-5 of the formula, i.e. 3e-3 code) cannot flip a code.
    const std::vector<double> xs = {0, 0.001, 0.002, 0.01, 0.05, 0.18, 0.3, 0.5, 0.75, 0.9, 1.0, 1.5, -0.2, 100};
    const float exposure = GENERATE(1.f, 2.f, 0.25f);
    // Red holds x / exposure and green x / (2 exposure) (exact in float: powers of two),
    // so the written codes are those of x and x / 2 whatever the exposure.
    image<glm::vec3> img(xs.size() + 1, 1);
    for (std::size_t i = 0; i < xs.size(); ++i)
        img(i, 0) = glm::vec3(float(xs[i]) / exposure, float(xs[i]) * 0.5f / exposure, 0.f);
    img(xs.size(), 0) =
        glm::vec3(std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity(), 0.18f / exposure);
    scratch_folder dir;
    const auto file = dir.path() / "codes.png";
    io::write_png(file, img.view(), exposure);
    int width = 0, channels = 0;
    const auto codes = read_codes(file, width, channels);
    REQUIRE(width == int(xs.size() + 1));
    REQUIRE(channels == 3);
    const auto expected_code = [](double x) {
        const double v = 255 * srgb_encode(std::clamp(x, 0.0, 1.0));
        if (x > 0 && x < 1) REQUIRE(std::abs(v - std::floor(v) - 0.5) > 0.01);
        return int(std::lround(v));
    };
    for (std::size_t i = 0; i < xs.size(); ++i) {
        INFO("x = " << xs[i] << ", exposure " << exposure);
        CHECK(int(codes[3 * i]) == expected_code(xs[i]));
        CHECK(int(codes[3 * i + 1]) == expected_code(xs[i] * 0.5));
        CHECK(int(codes[3 * i + 2]) == 0);
    }
    // Non-finite pixels are written black; the finite channel beside them is not touched.
    const std::size_t last = 3 * xs.size();
    CHECK(int(codes[last]) == 0);
    CHECK(int(codes[last + 1]) == 0);
    CHECK(int(codes[last + 2]) == expected_code(0.18));

    // read_rgb decodes the codes back to linear: k -> decode(k / 255), to OIIO's 1e-5.
    const image<glm::vec3> back = io::read_rgb(file);
    for (std::size_t i = 0; i < xs.size(); ++i)
        CHECK(back(i, 0).g == Approx(srgb_decode(codes[3 * i + 1] / 255.0)).margin(1e-5));
}

TEST_CASE("write_png refuses a bad exposure or an empty image", "[io][image][png][bad-input]") {
    scratch_folder dir;
    const image<glm::vec3> img(2, 2, glm::vec3(0.5f));
    for (float e : {0.f, -1.f, std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity()})
        CHECK_THROWS_AS(io::write_png(dir.path() / "x.png", img.view(), e), parameter_error);
    CHECK_THROWS_AS(io::write_png(dir.path() / "x.png", image_view<const glm::vec3>{}), parameter_error);
}
