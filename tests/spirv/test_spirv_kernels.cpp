// Every kernel the GL adapter emits (gl::emitted_kernels: each in every variant its passes
// compile), wrapped in a Vulkan compute shader, compiles to SPIR-V with glslang (as
// `glslangValidator -V --target-env vulkan1.2`) and passes SPIRV-Tools' validator (as
// `spirv-val --target-env vulkan1.2`); the same kernels in their OpenGL compute shaders, and
// the full shaders the GL adapter shows (the splat pass's, the volume lookup's), compile as
// OpenGL GLSL 4.50 with glslang.
// The catalog is checked against the sources: every kernel a GL pass adds to its function set
// (`.add("name", kernel<...>, ...)` in adapters/gl/src) must be in it under the same name and
// kernel function, so a new or replaced kernel cannot be missed.
// The compile cases skip when glslang or SPIRV-Tools was not found at configure time.
#include "../skip.hpp"

#include <bounce/gl/irradiance_volume.hpp>
#include <bounce/gl/kernel_catalog.hpp>
#include <bounce/gl/splat_pass.hpp>

#if BOUNCE_HAS_GLSLANG
#include "glsl_compiler.hpp"
#endif

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <regex>
#include <set>
#include <utility>
#include <sstream>
#include <string>

using namespace bounce;
namespace fs = std::filesystem;

namespace {

std::string read_all(const fs::path& p) {
    std::ifstream in(p);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

}  // namespace

// The kernel function an `.add(` call names, from the text of its expression:
// "&W::template influence_radius<glsl::f32>" and "influence_radius<f32>" are both
// "influence_radius".
std::string kernel_function(std::string expr) {
    expr = expr.substr(0, expr.find_first_of("<("));
    const auto space = expr.find_last_of(" \t\n&");
    if (space != std::string::npos) expr = expr.substr(space + 1);
    const auto scope = expr.rfind("::");
    return scope == std::string::npos ? expr : expr.substr(scope + 2);
}

TEST_CASE("every kernel the GL passes emit is in the kernel catalog, under its name", "[spirv]") {
    std::set<std::pair<std::string, std::string>> catalogued;  // (name, kernel function)
    for (const auto& k : gl::emitted_kernels()) catalogued.insert({k.name, kernel_function(k.kernel)});
    const std::regex added(R"(\.add\(\s*"([A-Za-z_][A-Za-z_0-9]*)\"\s*,\s*([^,<(]+))");
    std::size_t found = 0;
    for (const auto& entry : fs::directory_iterator(fs::path(BOUNCE_SOURCE_DIR) / "adapters" / "gl" / "src")) {
        if (entry.path().extension() != ".cpp" || entry.path().filename() == "kernel_catalog.cpp") continue;
        const std::string text = read_all(entry.path());
        for (std::sregex_iterator it(text.begin(), text.end(), added), end; it != end; ++it) {
            ++found;
            const std::pair<std::string, std::string> kernel{(*it)[1].str(), kernel_function((*it)[2].str())};
            INFO(entry.path().filename().string() << " emits " << kernel.second << " as " << kernel.first);
            CHECK(catalogued.count(kernel) == 1);
        }
    }
    CHECK(found >= 60);  // the pattern still matches the passes' calls
    CHECK(kernel_function("&W::template influence_radius<glsl::f32>") == "influence_radius");
    CHECK(kernel_function("glsl::f32") == "f32");
}

#if BOUNCE_HAS_GLSLANG

TEST_CASE("the in-process compiler and validator refuse what glslangValidator and spirv-val refuse", "[spirv]") {
    CHECK_FALSE(spirv_test::compile_for_vulkan("#version 450\nvoid main() { undeclared = 1.0; }\n", spirv_test::stage::compute).ok);
    // A loose uniform is OpenGL GLSL, not Vulkan GLSL.
    const std::string loose = "#version 450\nlayout(local_size_x = 1) in;\nuniform float f;\nvoid main() {}\n";
    CHECK(spirv_test::compile_for_opengl(loose, spirv_test::stage::compute).ok);
    CHECK_FALSE(spirv_test::compile_for_vulkan(loose, spirv_test::stage::compute).ok);
    auto good = spirv_test::compile_for_vulkan("#version 450\nlayout(local_size_x = 1) in;\nvoid main() {}\n", spirv_test::stage::compute);
    REQUIRE(good.ok);
    CHECK(spirv_test::validate_for_vulkan(good.spirv) == "");
    good.spirv.resize(good.spirv.size() - 2);  // truncated: an instruction runs past the end
    CHECK(spirv_test::validate_for_vulkan(good.spirv) != "");
}

TEST_CASE("every emitted kernel compiles to SPIR-V for Vulkan 1.2 and passes spirv-val", "[spirv]") {
    const auto kernels = gl::emitted_kernels(gl::compute_target::vulkan);
    REQUIRE(kernels.size() >= 80);
    for (const auto& k : kernels) {
        INFO(k.pass << ": " << k.name << " " << k.variant);
        const auto c = spirv_test::compile_for_vulkan(k.compute_source, spirv_test::stage::compute);
        INFO(c.log << "\n" << k.compute_source);
        REQUIRE(c.ok);
        REQUIRE(!c.spirv.empty());
        CHECK(spirv_test::validate_for_vulkan(c.spirv) == "");
    }
}

TEST_CASE("the emitted kernels and the splat and volume passes' shaders compile as OpenGL GLSL 4.50", "[spirv]") {
    const auto compile = [](const std::string& what, const std::string& source, spirv_test::stage s) {
        const auto c = spirv_test::compile_for_opengl(source, s);
        INFO(what << "\n" << c.log << "\n" << source);
        CHECK(c.ok);
    };
    for (const auto& k : gl::emitted_kernels(gl::compute_target::opengl)) compile(k.name, k.compute_source, spirv_test::stage::compute);
    compile("irradiance_volume_lookup", gl::irradiance_volume_lookup::shader_source(), spirv_test::stage::compute);
    for (const weighting_kind w : weighting_kinds) {
        compile("splat_pass vertex", gl::splat_pass::vertex_source(w), spirv_test::stage::vertex);
        for (const bool gradients : {false, true})
            for (const bool front : {false, true})
                compile("splat_pass fragment", gl::splat_pass::fragment_source(w, gradients, front), spirv_test::stage::fragment);
    }
}

#else

TEST_CASE("every emitted kernel compiles to SPIR-V for Vulkan 1.2 and passes spirv-val", "[spirv]") {
    test::skip("glslang or SPIRV-Tools not found at configure time (Debian: glslang-dev, spirv-tools)");
}

#endif
