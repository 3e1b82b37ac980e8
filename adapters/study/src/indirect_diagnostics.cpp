#include <bounce/study/indirect_diagnostics.hpp>

#include <bounce/cpu/interleave.hpp>
#include <bounce/errors.hpp>
#include <bounce/output.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include <fmt/core.h>
#include <glm/geometric.hpp>

namespace bounce::study {

diagnostic_occlusion::diagnostic_occlusion(const embree::accel& bvh, const io::scene& scene, std::string mode)
    : bvh_(bvh), scene_(scene), mode_(std::move(mode)), eps_(bvh.ray_epsilon()) {
    if (mode_ != "rays" && mode_ != "geometric" && mode_ != "shortened")
        throw parameter_error("--occlusion", "must be rays, geometric or shortened");
}

void diagnostic_occlusion::occluded(std::span<const visibility_segment> segments, std::span<std::uint8_t> blocked) const {
    thread_local std::vector<embree::ray> rays;
    thread_local std::vector<embree::hit> hits;
    rays.resize(segments.size());
    hits.resize(segments.size());
    const bool geo = mode_ == "geometric", shortened = mode_ == "shortened";
    for (std::size_t i = 0; i < segments.size(); ++i) {
        const visibility_segment& s = segments[i];
        const glm::vec3 rn = geo ? geometric_normal(s.receiver, s.receiver_normal) : s.receiver_normal;
        const glm::vec3 sn = geo ? geometric_normal(s.sender, s.sender_normal) : s.sender_normal;
        const glm::vec3 from = segment_end(s.receiver, rn, s.sender, eps_);
        const glm::vec3 to = shortened ? s.sender : segment_end(s.sender, sn, s.receiver, eps_);
        const float len = glm::length(to - from);
        rays[i] = {from, to - from, 0.f, shortened ? std::max(0.f, 1.f - 2.f * eps_ / len) : 1.f};
    }
    bvh_.intersect(rays, hits);
    for (std::size_t i = 0; i < segments.size(); ++i) {
        blocked[i] = hits[i].found() ? 1 : 0;
        if (!hits[i].found()) continue;
        const float len = glm::length(rays[i].direction);
        const float near = hits[i].t * len / eps_, far = (1.f - hits[i].t) * len / eps_;
        const float d = std::min(near, far);
        counts_[near <= far ? 0 : 1][d < 3.f ? 0 : d < 30.f ? 1 : d < 300.f ? 2 : 3] += 1;
    }
    total_ += segments.size();
}

std::string diagnostic_occlusion::summary() const {
    return fmt::format("occlusion {}: {} segments; blocked within 3/30/300/more eps of the receiver {} {} {} {}, "
                       "of the sender {} {} {} {}",
                       mode_, total_.load(), counts_[0][0].load(), counts_[0][1].load(), counts_[0][2].load(),
                       counts_[0][3].load(), counts_[1][0].load(), counts_[1][1].load(), counts_[1][2].load(),
                       counts_[1][3].load());
}

glm::vec3 diagnostic_occlusion::geometric_normal(const glm::vec3& p, const glm::vec3& n) const {
    const float probe = 4.f * eps_;
    const embree::ray r{p + n * probe, -n, 0.f, 2.f * probe};
    const embree::hit h = bvh_.intersect(r);
    return h.found() ? embree::surface_at(scene_.view(), r, h).geometric_normal : n;
}

io::scene flat_shaded(const io::scene& s) {
    io::scene f = s;
    f.name = s.name + "-flat";
    f.positions.clear();
    f.normals.clear();
    f.triangles.clear();
    for (const glm::uvec3& t : s.triangles) {
        const glm::vec3 a = s.positions[t.x], b = s.positions[t.y], c = s.positions[t.z];
        glm::vec3 n = glm::cross(b - a, c - a);
        const float len = glm::length(n);
        n = len > 0.f ? n / len : s.normals[t.x];
        if (glm::dot(n, s.normals[t.x] + s.normals[t.y] + s.normals[t.z]) < 0.f) n = -n;
        const std::uint32_t k = std::uint32_t(f.positions.size());
        for (const glm::vec3& p : {a, b, c}) {
            f.positions.push_back(p);
            f.normals.push_back(n);
        }
        f.triangles.push_back({k, k + 1, k + 2});
    }
    return f;
}

image<glm::vec3> blurred_reference(const gbuffer_view<float>& g, image_view<const glm::vec3> radiance,
                                   const indirect_options& options) {
    const std::size_t w = g.width(), h = g.height();
    image<glm::vec3> e(w, h), scratch(w, h), out(w, h);
    image<glm::vec2> edges(w, h);
    for (std::size_t y = 0; y < h; ++y)
        for (std::size_t x = 0; x < w; ++x) {
            const glm::vec3 rho = g.albedo(x, y);
            for (int c = 0; c < 3; ++c)
                e(x, y)[c] = rho[c] > 0.f ? radiance(x, y)[c] * float(std::numbers::pi) / rho[c] : 0.f;
        }
    cpu::discontinuity_buffer(g, options.discontinuity, edges.view());
    cpu::geometry_aware_blur(e.view(), edges.view(), g.depth, options.pattern, scratch.view(), out.view());
    apply_output(output_quantity::radiance, image_view<const glm::vec3>(g.albedo), out.view());
    return out;
}

image<glm::vec3> reached_sub_buffers_image(const gbuffer_view<float>& g, const indirect_options& options) {
    image<glm::vec2> edges(g.width(), g.height());
    image<float> reached(g.width(), g.height());
    cpu::discontinuity_buffer(g, options.discontinuity, edges.view());
    cpu::reached_sub_buffers(edges.view(), g.depth, options.pattern, reached.view());
    image<glm::vec3> out(g.width(), g.height());
    for (std::size_t y = 0; y < g.height(); ++y)
        for (std::size_t x = 0; x < g.width(); ++x) out(x, y) = glm::vec3(reached(x, y));
    return out;
}

void write_raw_f32(const std::filesystem::path& file, image_view<const glm::vec3> img, const std::string& parameter) {
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    std::FILE* f = std::fopen(file.string().c_str(), "wb");
    if (f == nullptr) throw parameter_error(parameter, "cannot write " + file.string());
    bool ok = true;
    for (std::size_t y = 0; y < img.height(); ++y)
        ok = ok && std::fwrite(img.row(y).data(), sizeof(glm::vec3), img.width(), f) == img.width();
    ok = std::fclose(f) == 0 && ok;
    if (!ok) throw parameter_error(parameter, "could not write all of " + file.string());
}

}  // namespace bounce::study
