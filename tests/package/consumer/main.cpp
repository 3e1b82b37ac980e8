// A renderer using the installed package: its own G-buffer memory wrapped in views, one
// record splatted with the CPU adapter. Exits non-zero if the result is wrong.
#include <bounce/cpu/splatting.hpp>

#ifdef BOUNCE_WITH_GL
#error "BOUNCE_WITH_GL comes with bounce::gl, which this consumer does not link"
#endif

#include <cstdio>
#include <vector>

int main() {
    const std::size_t w = 4, h = 4;
    std::vector<glm::vec3> pos(w * h), nrm(w * h, glm::vec3(0, 0, 1)), alb(w * h, glm::vec3(1.f));
    std::vector<float> depth(w * h, 1.f);
    for (std::size_t i = 0; i < w * h; ++i) pos[i] = glm::vec3(float(i % w) * 0.01f, float(i / w) * 0.01f, 0.f);
    bounce::gbuffer_view<float> gb{{pos.data(), w, h}, {nrm.data(), w, h}, {alb.data(), w, h}, {depth.data(), w, h}};
    bounce::camera cam;
    cam.position = {0.015f, 0.015f, 1.f};
    cam.look_at = {0.015f, 0.015f, 0.f};
    bounce::irradiance_record rec;
    rec.position = pos[5];
    rec.irradiance = glm::vec3(3.14159265f);
    rec.radius = 1.f;
    std::vector<glm::vec4> splat(w * h, glm::vec4(0.f));
    bounce::cpu::splat_params sp;
    sp.a = 0.5f;
    bounce::cpu::splat_record<bounce::ward_weight>(gb, cam, rec, sp, {splat.data(), w, h});
    const glm::vec4 s = splat[5];
    std::printf("splat at the record: (%g, %g)\n", double(s.x / s.w), double(s.w));
    return (s.w > 0.f && std::abs(s.x / s.w - 1.f) < 1e-5f) ? 0 : 1;
}
