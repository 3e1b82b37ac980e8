// Properties of the GLSL text the emitter prints: shared values computed once, constants
// that read back exactly, select as a ternary, parentheses where precedence needs them,
// signatures read off the kernel's types, and names checked.
#include <bounce/glsl/emit.hpp>
#include <bounce/sampling.hpp>
#include <bounce/sh/basis.hpp>
#include <bounce/surface.hpp>

#include <catch2/catch.hpp>

#include <bit>
#include <cmath>
#include <cstdlib>
#include <limits>
#include <numbers>
#include <regex>
#include <string>

namespace bounce::emit_test {

// Small kernels written as every kernel is: templates over T, unqualified vocabulary.
template <real T>
T shared_product(T a, T b) {
    const T s = a * b + T(1);
    return s * s + s;
}
template <real T>
T twice_built(T a, T b) {
    return a * b + a * b;  // two separate nodes, structurally equal
}
template <real T>
T magnitude(T x) {
    return select(x > T(0), x, -x);
}
template <real T>
T associativity(T a, T b, T c) {
    return (a - (b - c)) * ((a - b) - c) / (a / (b * c));
}
template <real T>
T constants(T x) {
    return x * T(0.1) + T(0.7) * T(std::numbers::pi) + T(-2.5) * x;
}
template <real T, vec3_of<T> V>
T middle(T a, T b, T c) {
    return V(a, b, c).y;
}
template <real T, vec3_of<T> V>
V with_y(const V& v, T y) {
    V r = v;
    r.y = y;  // GLM allows assigning a component; so do the expression types
    return r * T(2);
}
template <real T>
T minus_negative(T x) {
    return x - T(-0.5) * T(3);
}
template <real T, vec3_of<T> V>
std::tuple<T, V> polar(const V& v) {
    return {length(v), normalize(v)};
}

int count(const std::string& s, const std::string& what) {
    int n = 0;
    for (auto p = s.find(what); p != std::string::npos; p = s.find(what, p + 1)) ++n;
    return n;
}

}  // namespace bounce::emit_test

using namespace bounce;
using namespace bounce::emit_test;
using glsl::f32;
using glsl::vec2;
using glsl::vec3;

// The expression types satisfy the concepts every kernel is constrained by.
static_assert(real<f32>);
static_assert(vec3_of<vec3, f32>);
static_assert(vec2_of<vec2, f32>);
static_assert(!real<glsl::boolean>);

TEST_CASE("a value used more than once is computed once, as a local", "[glsl][emit]") {
    const auto src = glsl::emit("shared_product", shared_product<f32>, "a", "b");
    INFO(src);
    CHECK(src ==
          "float shared_product(float a, float b) {\n"
          "    float t0 = a * b + 1.0;\n"
          "    return t0 * t0 + t0;\n"
          "}\n");
    // Structurally equal subexpressions built twice are one value too.
    const auto twice = glsl::emit("twice_built", twice_built<f32>, "a", "b");
    INFO(twice);
    CHECK(count(twice, "a * b") == 1);
    CHECK(count(twice, "float t0 = a * b;") == 1);
    CHECK(count(twice, "return t0 + t0;") == 1);
}

TEST_CASE("select prints as a ternary and components of built vectors as the scalars", "[glsl][emit]") {
    const auto src = glsl::emit("magnitude", magnitude<f32>, "x");
    INFO(src);
    CHECK(src.find("return x > 0.0 ? x : -x;") != std::string::npos);
    const auto mid = glsl::emit("middle", middle<f32, vec3>, "a", "b", "c");
    INFO(mid);
    CHECK(mid.find("return b;") != std::string::npos);
}

TEST_CASE("parentheses follow GLSL precedence and left associativity", "[glsl][emit]") {
    const auto src = glsl::emit("associativity", associativity<f32>, "a", "b", "c");
    INFO(src);
    CHECK(src.find("return (a - (b - c)) * (a - b - c) / (a / (b * c));") != std::string::npos);
    const auto neg = glsl::emit("minus_negative", minus_negative<f32>, "x");
    INFO(neg);
    CHECK(neg.find("return x - (-1.5);") != std::string::npos);
}

TEST_CASE("assigning a vector component rebuilds the vector from its components", "[glsl][emit]") {
    const auto src = glsl::emit("with_y", with_y<f32, vec3>, "v", "y");
    INFO(src);
    CHECK(src.find("return vec3(v.x, y, v.z) * 2.0;") != std::string::npos);
}

TEST_CASE("float literals read back as exactly the same float", "[glsl][emit]") {
    // Random bit patterns cover every exponent; strtof is correctly rounded, as GLSL
    // compilers' literal parsing is.
    pcg32 rng(99);
    for (int i = 0; i < 200000; ++i) {
        const float v = std::bit_cast<float>(rng.next_u32());
        if (!std::isfinite(v)) continue;
        const auto s = glsl::float_literal(v);
        REQUIRE(s.find_first_of(".e") != std::string::npos);  // a float literal, not an int
        REQUIRE(std::bit_cast<std::uint32_t>(std::strtof(s.c_str(), nullptr)) == std::bit_cast<std::uint32_t>(v));
    }
    CHECK(glsl::float_literal(1.f) == "1.0");
    CHECK(glsl::float_literal(0.1f) == "0.1");
    CHECK(glsl::float_literal(-0.f) == "-0.0");
    CHECK(glsl::float_literal(float(std::numbers::pi)) == "3.1415927");
    CHECK(glsl::float_literal(std::numeric_limits<float>::infinity()) == "uintBitsToFloat(0x7f800000u)");
    CHECK(glsl::float_literal(-std::numeric_limits<float>::infinity()) == "uintBitsToFloat(0xff800000u)");
}

TEST_CASE("constants of an emitted kernel are folded in float and print exactly", "[glsl][emit]") {
    const auto src = glsl::emit("constants", constants<f32>, "x");
    INFO(src);
    // Constant arithmetic is folded in float, as the CPU float instantiation computes it.
    const float folded = 0.7f * float(std::numbers::pi);
    CHECK(src.find(glsl::float_literal(folded)) != std::string::npos);
    CHECK(src.find("x * 0.1") != std::string::npos);
    CHECK(src.find("-2.5 * x") != std::string::npos);
    // Every literal in the text reads back as a float the kernel used.
    const std::regex literal(R"((\d+\.\d*(e[+-]?\d+)?|\d+e[+-]?\d+))");
    int n = 0;
    for (auto it = std::sregex_iterator(src.begin(), src.end(), literal); it != std::sregex_iterator(); ++it, ++n) {
        const float v = std::strtof(it->str().c_str(), nullptr);
        CHECK((v == 0.1f || v == folded || v == 2.5f));
    }
    CHECK(n == 3);
}

TEST_CASE("signatures are read off the kernel's parameter and result types", "[glsl][emit]") {
    const auto basis = glsl::emit("orthonormal_basis", orthonormal_basis<f32, vec3>, "n");
    CHECK(basis.rfind("void orthonormal_basis(vec3 n, out vec3 result[2]) {\n", 0) == 0);
    CHECK(basis.find("result[0] = ") != std::string::npos);
    CHECK(basis.find("result[1] = ") != std::string::npos);
    const auto world = glsl::emit("to_world", to_world<f32, vec3>, "d", "n");
    CHECK(world.rfind("vec3 to_world(vec3 d, vec3 n) {\n", 0) == 0);
    const auto disc = glsl::emit("concentric_disc", concentric_disc<f32, vec2>, "u");
    CHECK(disc.rfind("vec2 concentric_disc(vec2 u) {\n", 0) == 0);
    const auto sh = glsl::emit("sh_basis", sh_basis<4, f32, vec3>, "d", "y");
    CHECK(sh.rfind("void sh_basis(vec3 d, out float y[16]) {\n", 0) == 0);
    CHECK(sh.find("y[15] = ") != std::string::npos);
    const auto p = glsl::emit("polar", polar<f32, vec3>, "v");
    CHECK(p.rfind("void polar(vec3 v, out float result0, out vec3 result1) {\n", 0) == 0);
    const auto lambda = glsl::emit("sum", [](const std::array<f32, 3>& c) { return c[0] + c[1] + c[2]; }, "c");
    CHECK(lambda == "float sum(float c[3]) {\n    return c[0] + c[1] + c[2];\n}\n");
}

TEST_CASE("locals never take a parameter's name", "[glsl][emit]") {
    const auto src = glsl::emit("shared_product", shared_product<f32>, "t0", "t1");
    INFO(src);
    CHECK(src.find("float t_0 = t0 * t1 + 1.0;") != std::string::npos);
}

TEST_CASE("names that GLSL cannot take are refused with parameter_error", "[glsl][emit][bad-input]") {
    CHECK_THROWS_AS(glsl::emit("f", magnitude<f32>, "gl_x"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("f", magnitude<f32>, "2x"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("f", magnitude<f32>, "a__b"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("f", magnitude<f32>, "dot"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("float", magnitude<f32>, "x"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("f", shared_product<f32>, "a", "a"), parameter_error);
    CHECK_THROWS_AS(glsl::emit("f", orthonormal_basis<f32, vec3>, "n", "n"), parameter_error);
    try {
        glsl::emit("f", magnitude<f32>, "x y");
        FAIL("no exception");
    } catch (const parameter_error& e) {
        CHECK(e.parameter() == "names");
        CHECK(std::string(e.what()).find("x y") != std::string::npos);
    }
}

TEST_CASE("a function set holds each function once and refuses two under one name", "[glsl][emit]") {
    glsl::function_set set;
    set.add("facing_normal", facing_normal<f32, vec3>, "n", "p", "eye");
    set.add("view_depth", view_depth<f32, vec3>, "p", "eye", "forward");
    set.add("facing_normal", facing_normal<f32, vec3>, "n", "p", "eye");
    const auto src = set.source();
    CHECK(count(src, "vec3 facing_normal(") == 1);
    CHECK(count(src, "float view_depth(") == 1);
    CHECK(src.find("vec3 facing_normal(") < src.find("float view_depth("));
    CHECK(set.contains("view_depth"));
    CHECK_FALSE(set.contains("to_world"));
    CHECK_THROWS_AS(set.add("view_depth", magnitude<f32>, "x"), parameter_error);
}
