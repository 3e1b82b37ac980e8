// bounce_vk_emit <folder>: writes the Vulkan passes' GLSL compute shaders (one <name>.comp
// each) and names.txt (one name a line) into <folder>, for cmake/compile_spirv.cmake to
// compile with glslangValidator, validate with spirv-val and embed as uint32 arrays.
#include "../src/shader_sources.hpp"

#include <exception>
#include <filesystem>
#include <fstream>
#include <iostream>

int main(int argc, char** argv) {
    if (argc != 2) {
        std::cerr << "usage: bounce_vk_emit <folder>\n";
        return 2;
    }
    try {
        const std::filesystem::path dir(argv[1]);
        std::filesystem::create_directories(dir);
        std::ofstream names(dir / "names.txt");
        for (const auto& s : bounce::vk::detail::shader_sources()) {
            std::ofstream(dir / (s.name + ".comp")) << s.glsl;
            names << s.name << "\n";
        }
        return names ? 0 : 1;
    } catch (const std::exception& e) {
        std::cerr << "bounce_vk_emit: " << e.what() << "\n";
        return 1;
    }
}
