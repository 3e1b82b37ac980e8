#include <bounce/image.hpp>
#include <bounce/gbuffer.hpp>

#include <catch2/catch.hpp>
#include <glm/vec3.hpp>

using namespace bounce;

TEST_CASE("an image view with a row stride addresses the same memory as its owner", "[image]") {
    image<float> img(7, 5);
    for (std::size_t y = 0; y < 5; ++y)
        for (std::size_t x = 0; x < 7; ++x) img(x, y) = float(10 * y + x);
    const auto sub = img.view().subview(2, 1, 3, 3);
    CHECK(sub.stride() == 7);
    CHECK(sub(0, 0) == 12.f);
    CHECK(sub(2, 2) == 34.f);
    CHECK(sub.row(1)[1] == 23.f);
    image_view<const float> c = sub;
    CHECK(c(1, 1) == 23.f);
}

TEST_CASE("bad image parameters raise parameter_error naming the parameter", "[image][bad-input]") {
    CHECK_THROWS_AS(image<float>(0, 4), parameter_error);
    CHECK_THROWS_AS(image<float>(4, 0), parameter_error);
    float buf[8]{};
    CHECK_THROWS_AS(image_view<float>(buf, 4, 2, 3), parameter_error);
    CHECK_THROWS_AS(image_view<float>(nullptr, 4, 2), parameter_error);
    image<float> img(4, 4);
    CHECK_THROWS_AS(img.view().subview(3, 3, 2, 2), parameter_error);
    try {
        image_view<float>(buf, 4, 2, 3);
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "stride");
    }
}

TEST_CASE("require_finite finds the first NaN or infinity and names the buffer and pixel", "[image][bad-input]") {
    image<glm::vec3> img(3, 2, glm::vec3(1.f));
    CHECK_NOTHROW(require_finite<glm::vec3>(img.view(), "albedo"));
    img(2, 1).y = std::numeric_limits<float>::quiet_NaN();
    try {
        require_finite<glm::vec3>(img.view(), "albedo");
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "albedo");
        CHECK(std::string(e.what()).find("(2, 1)") != std::string::npos);
    }
    image<float> d(2, 2, 0.f);
    d(0, 1) = std::numeric_limits<float>::infinity();
    CHECK_THROWS_AS(require_finite<float>(d.view(), "depth"), parameter_error);
}
