// The headless context and the object wrappers: a 4.5 core context through EGL, clear
// failures naming what is missing, shader errors that carry the numbered source.
#include "shared_context.hpp"

#include <bounce/gl/objects.hpp>


#include <epoxy/gl.h>  // GL entry points from whatever context is current (EGL, GLX, WGL)
#include <catch2/catch.hpp>

#include <string>

using namespace bounce;

TEST_CASE("a headless OpenGL 4.5 core context is created through EGL and made current", "[gl][context]") {
    auto& c = gl_test::shared_context();
    CHECK(c.is_current());
    CHECK_FALSE(c.platform().empty());
    GLint major = 0, minor = 0, profile = 0;
    glGetIntegerv(GL_MAJOR_VERSION, &major);
    glGetIntegerv(GL_MINOR_VERSION, &minor);
    glGetIntegerv(GL_CONTEXT_PROFILE_MASK, &profile);
    INFO(c.platform() << ": " << c.renderer() << ", " << c.version());
    CHECK(major * 100 + minor >= 405);
    CHECK((profile & GL_CONTEXT_CORE_PROFILE_BIT) != 0);
}

TEST_CASE("each EGL platform either gives a context or says why, naming itself", "[gl][context]") {
    for (const auto platform : {gl::egl_platform::device, gl::egl_platform::surfaceless}) {
        const std::string name =
            platform == gl::egl_platform::device ? "EGL_EXT_platform_device" : "EGL_MESA_platform_surfaceless";
        try {
            gl::context c({platform});
            CHECK(c.is_current());
            CHECK(c.platform().rfind(name, 0) == 0);
        } catch (const gl::gl_error& e) {
            INFO(e.what());
            CHECK(std::string(e.what()).find(name) != std::string::npos);
        }
    }
    gl_test::shared_context();
}

TEST_CASE("asking for an OpenGL version no driver has fails with a gl_error naming it", "[gl][context][bad-input]") {
    try {
        gl::context c({gl::egl_platform::any, 4, 9});
        FAIL("OpenGL 4.9 does not exist, yet a context was created");
    } catch (const gl::gl_error& e) {
        INFO(e.what());
        CHECK(std::string(e.what()).find("4.9 core") != std::string::npos);
    }
    CHECK_THROWS_AS(gl::context({gl::egl_platform::any, 3, 3}), parameter_error);
    gl_test::shared_context();
}

TEST_CASE("objects refuse to be created without a current context", "[gl][context][bad-input]") {
    { const gl::context temporary; }  // made current, then released by its destructor
    CHECK_THROWS_AS(gl::buffer(16), gl::gl_error);
    gl_test::shared_context();
    CHECK_NOTHROW(gl::buffer(16));
}

TEST_CASE("a shader that does not compile reports the log and the numbered source", "[gl][objects][bad-input]") {
    gl_test::shared_context();
    const std::string source = "#version 450 core\n"
                               "layout(local_size_x = 1) in;\n"
                               "void main() {\n"
                               "    float x = undefined_variable_here;\n"
                               "}\n";
    try {
        gl::program::compute(source);
        FAIL("the shader compiled");
    } catch (const gl::shader_error& e) {
        const std::string what = e.what();
        INFO(what);
        CHECK_FALSE(e.log().empty());
        CHECK(what.find(e.log()) != std::string::npos);
        CHECK(e.source() == source);
        CHECK(what.find("compute shader failed to compile") != std::string::npos);
        CHECK(what.find("   1| #version 450 core") != std::string::npos);
        CHECK(what.find("   4|     float x = undefined_variable_here;") != std::string::npos);
    }
}

TEST_CASE("a program that does not link reports the log and every stage's numbered source", "[gl][objects][bad-input]") {
    gl_test::shared_context();
    const std::string vs = "#version 450 core\nvoid main() { gl_Position = vec4(0.0); }\n";
    const std::string fs = "#version 450 core\n"
                           "float declared_never_defined(float x);\n"
                           "out vec4 colour;\n"
                           "void main() { colour = vec4(declared_never_defined(1.0)); }\n";
    try {
        gl::program p(vs, fs);
        FAIL("the program linked");
    } catch (const gl::shader_error& e) {
        const std::string what = e.what();
        INFO(what);
        CHECK(what.find("failed to link") != std::string::npos);
        CHECK(what.find(e.log()) != std::string::npos);
        CHECK(what.find("--- vertex shader source ---") != std::string::npos);
        CHECK(what.find("   2| float declared_never_defined(float x);") != std::string::npos);
    }
}

TEST_CASE("buffers and textures hold what is written and refuse bad sizes", "[gl][objects]") {
    gl_test::shared_context();
    const std::vector<float> data = {1.f, -2.f, 3.5f, 1e-30f};
    gl::buffer b{std::span<const float>(data)};
    CHECK(b.size() == 16);
    CHECK(b.read_all<float>() == data);
    const float x = 7.f;
    b.write(4, &x, sizeof x);
    CHECK(b.read_all<float>()[1] == 7.f);
    CHECK_THROWS_AS(b.write(12, data.data(), 8), parameter_error);
    CHECK_THROWS_AS(gl::buffer(0), parameter_error);

    gl::texture t(gl::texel_format::rgba32f, 3, 2);
    const float texel[4] = {0.25f, 0.5f, 0.75f, 1.f};
    glClearTexImage(t.id(), 0, GL_RGBA, GL_FLOAT, texel);
    const auto texels = t.read_floats();
    REQUIRE(texels.size() == 24);
    for (std::size_t i = 0; i < texels.size(); ++i) CHECK(texels[i] == texel[i % 4]);
    CHECK_THROWS_AS(gl::texture(gl::texel_format::r32f, 0, 4), parameter_error);
    CHECK_THROWS_AS(gl::texture(gl::texel_format::r32f, 1u << 20, 4), gl::gl_error);
    gl::check_error("test");
}
