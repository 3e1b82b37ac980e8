#include "glsl_compiler.hpp"

#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <spirv-tools/libspirv.hpp>

#include <memory>
#include <mutex>

namespace bounce::spirv_test {

namespace {

EShLanguage language(stage s) {
    switch (s) {
        case stage::vertex: return EShLangVertex;
        case stage::fragment: return EShLangFragment;
        case stage::compute: return EShLangCompute;
    }
    return EShLangCompute;
}

void initialize() {
    static std::once_flag once;
    std::call_once(once, [] { glslang::InitializeProcess(); });
}

compiled compile(const std::string& source, stage s, bool vulkan) {
    initialize();
    const EShLanguage lang = language(s);
    auto shader = std::make_unique<glslang::TShader>(lang);
    const char* text = source.c_str();
    shader->setStrings(&text, 1);
    auto messages = EShMsgDefault;
    if (vulkan) {
        shader->setEnvInput(glslang::EShSourceGlsl, lang, glslang::EShClientVulkan, 100);
        shader->setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_2);
        shader->setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_5);
        messages = EShMessages(EShMsgSpvRules | EShMsgVulkanRules);
    }
    compiled out;
    if (!shader->parse(GetDefaultResources(), 450, false, messages)) {
        out.log = shader->getInfoLog();
        return out;
    }
    glslang::TProgram program;
    program.addShader(shader.get());
    if (!program.link(messages)) {
        out.log = program.getInfoLog();
        return out;
    }
    if (vulkan) glslang::GlslangToSpv(*program.getIntermediate(lang), out.spirv);
    out.ok = true;
    out.log = shader->getInfoLog();
    return out;
}

}  // namespace

compiled compile_for_vulkan(const std::string& source, stage s) { return compile(source, s, true); }
compiled compile_for_opengl(const std::string& source, stage s) { return compile(source, s, false); }

std::string validate_for_vulkan(const std::vector<std::uint32_t>& spirv) {
    spvtools::SpirvTools tools(SPV_ENV_VULKAN_1_2);
    std::string messages;
    tools.SetMessageConsumer([&](spv_message_level_t, const char*, const spv_position_t& at, const char* message) {
        messages += "word " + std::to_string(at.index) + ": " + message + "\n";
    });
    if (tools.Validate(spirv)) return {};
    return messages.empty() ? std::string("invalid") : messages;
}

}  // namespace bounce::spirv_test
