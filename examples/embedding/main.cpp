// embedding: bounce inside a renderer that owns everything: its EGL context, its mesh arrays,
// its G-buffer textures and shader, its image writer. bounce gets views and texture names and
// adds one-bounce indirect light by irradiance splatting (docs/embedding.md walks through it).
//   build/bin/embedding --out embedding.png
#include <bounce/cpu/irradiance_cache.hpp>
#include <bounce/embree/irradiance_probe.hpp>
#include <bounce/embree/record_sampler.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/irradiance_splatter.hpp>

#include <epoxy/egl.h>
#include <epoxy/gl.h>
#include <OpenImageIO/imageio.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <cstdio>
#include <stdexcept>
#include <string>
#include <vector>

using namespace bounce;

// The renderer's G-buffer shader: world position and view depth, normal facing the eye, albedo.
const char* vertex_source = R"(#version 450 core
layout(location = 0) in vec3 position; layout(location = 1) in vec3 normal; layout(location = 2) in vec3 albedo;
layout(location = 0) uniform mat4 view_projection;
out vec3 p; out vec3 n; out vec3 rho;
void main() { p = position; n = normal; rho = albedo; gl_Position = view_projection * vec4(position, 1.0); })";
const char* fragment_source = R"(#version 450 core
layout(location = 1) uniform vec3 eye; layout(location = 2) uniform vec3 forward;
in vec3 p; in vec3 n; in vec3 rho;
layout(location = 0) out vec4 position_depth; layout(location = 1) out vec4 normal_out; layout(location = 2) out vec4 albedo;
void main() {
    position_depth = vec4(p, dot(p - eye, forward));
    normal_out = vec4(faceforward(normalize(n), p - eye, normalize(n)), 0.0);
    albedo = vec4(rho, 1.0);
})";

void make_context() {  // headless desktop GL 4.5 through Mesa's surfaceless EGL platform
    EGLDisplay d = eglGetPlatformDisplayEXT(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_SURFACE_TYPE, 0, EGL_NONE};
    const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION, 4, EGL_CONTEXT_MINOR_VERSION, 5,
                                      EGL_CONTEXT_OPENGL_PROFILE_MASK, EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT, EGL_NONE};
    EGLConfig config;
    EGLint count = 0;
    if (!d || !eglInitialize(d, nullptr, nullptr) || !eglBindAPI(EGL_OPENGL_API) ||
        !eglChooseConfig(d, config_attribs, &config, 1, &count) || count == 0)
        throw std::runtime_error("embedding: no EGL display with desktop OpenGL");
    EGLContext c = eglCreateContext(d, config, EGL_NO_CONTEXT, context_attribs);
    if (!c || !eglMakeCurrent(d, EGL_NO_SURFACE, EGL_NO_SURFACE, c)) throw std::runtime_error("embedding: no GL 4.5 context");
}

int main(int argc, char** argv) {
    const std::string out = argc == 3 && std::string(argv[1]) == "--out" ? argv[2] : "embedding.png";
    // The output checked before the work: a format OpenImageIO writes, in a place it can go.
    {
        const bool existed = std::filesystem::exists(out);
        std::ofstream probe(out, std::ios::app);
        if (!OIIO::ImageOutput::create(out) || !probe || std::filesystem::is_directory(out)) {
            std::fprintf(stderr, "embedding: --out %s: not a writable image file (.png, .exr ...)\n", out.c_str());
            return 2;
        }
        probe.close();
        if (!existed) std::filesystem::remove(out);
    }
    const std::size_t w = 256, h = 256;
    // The renderer's mesh: a floor, a red and a green wall, flat-shaded, one material each.
    std::vector<glm::vec3> positions, normals, albedos;
    std::vector<glm::uvec3> triangles;
    std::vector<std::uint32_t> material_of;
    const std::vector<material> materials{{glm::vec3(0.75f), glm::vec3(0.f)}, {{0.7f, 0.1f, 0.1f}, glm::vec3(0.f)},
                                          {{0.1f, 0.6f, 0.1f}, glm::vec3(0.f)}};
    auto quad = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, std::uint32_t m) {
        const auto base = std::uint32_t(positions.size());
        for (glm::vec3 v : {a, b, c, d}) {
            positions.push_back(v);
            normals.push_back(glm::normalize(glm::cross(b - a, d - a)));
            albedos.push_back(materials[m].albedo);
        }
        triangles.insert(triangles.end(), {{base, base + 1, base + 2}, {base, base + 2, base + 3}});
        material_of.insert(material_of.end(), {m, m});
    };
    quad({-1, 0, 1}, {1, 0, 1}, {1, 0, -1}, {-1, 0, -1}, 0);
    quad({-1, 0, 1}, {-1, 0, -1}, {-1, 2, -1}, {-1, 2, 1}, 1);
    quad({1, 0, -1}, {1, 0, 1}, {1, 2, 1}, {1, 2, -1}, 2);
    const std::vector<light> lights{spot_light{{0.f, 1.9f, 0.f}, {0, -1, 0}, glm::vec3(4.f), 60.f}};
    const scene_view scene{positions, normals, triangles, material_of, materials, lights, false};
    camera cam;
    cam.position = {0.f, 1.f, 3.2f};
    cam.look_at = {0.f, 0.8f, 0.f};

    make_context();
    // The renderer's G-buffer: three RGBA32F targets and a depth buffer, drawn by its shader.
    GLuint tex[3], depth, fbo, vao, vbo[3], ibo, program = glCreateProgram();
    glCreateTextures(GL_TEXTURE_2D, 3, tex);
    for (GLuint t : tex) glTextureStorage2D(t, 1, GL_RGBA32F, GLsizei(w), GLsizei(h));
    glCreateRenderbuffers(1, &depth);
    glNamedRenderbufferStorage(depth, GL_DEPTH_COMPONENT32F, GLsizei(w), GLsizei(h));
    glCreateFramebuffers(1, &fbo);
    for (GLenum i = 0; i < 3; ++i) glNamedFramebufferTexture(fbo, GL_COLOR_ATTACHMENT0 + i, tex[i], 0);
    glNamedFramebufferRenderbuffer(fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    const GLenum draw[3] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1, GL_COLOR_ATTACHMENT2};
    glNamedFramebufferDrawBuffers(fbo, 3, draw);
    for (auto [type, src] : {std::pair{GL_VERTEX_SHADER, vertex_source}, {GL_FRAGMENT_SHADER, fragment_source}}) {
        const GLuint s = glCreateShader(type);
        glShaderSource(s, 1, &src, nullptr);
        glCompileShader(s);
        glAttachShader(program, s);
    }
    glLinkProgram(program);
    glCreateVertexArrays(1, &vao);
    glCreateBuffers(3, vbo);
    glCreateBuffers(1, &ibo);
    for (GLuint a = 0; a < 3; ++a) {
        const auto& data = a == 0 ? positions : a == 1 ? normals : albedos;
        glNamedBufferStorage(vbo[a], GLsizeiptr(data.size() * sizeof(glm::vec3)), data.data(), 0);
        glVertexArrayVertexBuffer(vao, a, vbo[a], 0, sizeof(glm::vec3));
        glVertexArrayAttribFormat(vao, a, 3, GL_FLOAT, GL_FALSE, 0);
        glVertexArrayAttribBinding(vao, a, a);
        glEnableVertexArrayAttrib(vao, a);
    }
    glNamedBufferStorage(ibo, GLsizeiptr(triangles.size() * sizeof(glm::uvec3)), triangles.data(), 0);
    glVertexArrayElementBuffer(vao, ibo);
    const float background[4] = {0.f, 0.f, 0.f, INFINITY}, zero[4] = {0.f, 0.f, 0.f, 0.f};
    glClearNamedFramebufferfv(fbo, GL_COLOR, 0, background);  // depth +inf: nothing seen
    for (GLint i = 1; i < 3; ++i) glClearNamedFramebufferfv(fbo, GL_COLOR, i, zero);
    glClearNamedFramebufferfi(fbo, GL_DEPTH_STENCIL, 0, 1.f, 0);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, GLsizei(w), GLsizei(h));
    glEnable(GL_DEPTH_TEST);
    glUseProgram(program);
    const glm::mat4 vp = cam.projection_matrix(w, h) * cam.view_matrix();
    glUniformMatrix4fv(0, 1, GL_FALSE, &vp[0][0]);
    glUniform3fv(1, 1, &cam.position[0]);
    const glm::vec3 forward = cam.forward();
    glUniform3fv(2, 1, &forward[0]);
    glBindVertexArray(vao);
    glDrawElements(GL_TRIANGLES, GLsizei(3 * triangles.size()), GL_UNSIGNED_INT, nullptr);
    glBindFramebuffer(GL_FRAMEBUFFER, 0);

    // bounce: records by Embree rays, splatted on the GPU over the renderer's textures.
    const embree::accel bvh(scene);
    const embree::reference_integrator shading(bvh, scene);
    const embree::record_sampler sampler(shading, embree::hemisphere_grid_for(512), radius_limits{});
    const auto [lo, hi] = scene.bounds();
    // The verification pass (as ic_splatting's default): the image checked against 8-ray probes,
    // records added where it disagrees; its rounds splat every record again on the GPU (resplat).
    cpu::irradiance_cache_options options;
    options.verify.rounds = 2;
    cpu::irradiance_cache<ward_smooth_weight> cache(lo, hi, options);
    const embree::irradiance_probe probe(shading, 8);
    cache.set_probe(std::cref(probe));
    gl::irradiance_splatter splatter;
    const gl::gbuffer_textures g{gl::texture_ref::of(tex[0]), gl::texture_ref::of(tex[1]), gl::texture_ref::of(tex[2])};
    const auto resplat = [&](image_view<glm::vec4> splat) { splatter.resplat(g, cam, cache.records(), splat); };
    // Radiance rho/pi * E with the G-buffer's albedo, since compose adds it to the direct radiance.
    const auto stats = splatter.render(
        g, cam, cache.records(),
        [&](gbuffer_view<float> gv, image_view<glm::vec4> splat) {
            cache.scan_and_verify(gv, cam, sampler, splat, resplat);
        },
        output_quantity::radiance);
    const gl::scene_mesh mesh(scene);
    gl::direct_light direct(scene, mesh);
    direct.render(g);
    image<glm::vec3> pixels(w, h);
    gl::read_texture(splatter.compose(direct.radiance()), pixels.view());

    // The renderer's own image writer: 8-bit sRGB-like PNG through OpenImageIO.
    std::vector<unsigned char> bytes(3 * w * h);
    for (std::size_t i = 0; i < 3 * w * h; ++i)
        bytes[i] = (unsigned char)(255.f * std::pow(std::min(1.f, 2.f * pixels.data()[i / 3][int(i % 3)]), 1.f / 2.2f));
    auto file = OIIO::ImageOutput::create(out);
    if (!file || !file->open(out, OIIO::ImageSpec(int(w), int(h), 3, OIIO::TypeDesc::UINT8)) ||
        !file->write_image(OIIO::TypeDesc::UINT8, bytes.data()) || !file->close()) {
        std::fprintf(stderr, "embedding: cannot write %s\n", out.c_str());
        return 1;
    }
    std::printf("%zu records (%.1f ms splatting, %.1f ms scan); wrote %s\n", cache.records().size(),
                stats.splat_existing_ms + stats.interpolate_ms, stats.scan_ms, out.c_str());
}
