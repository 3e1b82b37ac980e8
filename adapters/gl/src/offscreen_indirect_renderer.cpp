// gl::offscreen_indirect_renderer: the GL indirect passes for a caller without a GL context
// of its own (a study, a CPU renderer comparing backends): its own EGL context, host
// G-buffers and maps uploaded, the renderer kept while the options compare equal.
#include <bounce/gl/indirect_renderer.hpp>

#include <optional>
#include <utility>
#include <vector>

namespace bounce::gl {

struct offscreen_indirect_renderer::uploads {
    gbuffer_upload gbuffer;
    std::vector<texture> textures;  // position, normal, flux per map
    std::optional<texture> out;
    image<glm::vec4> padded;

    /// `img` into `t` (reallocated when its size differs), rgb + a = 0.
    void upload(std::size_t at, image_view<const glm::vec3> img) {
        if (at == textures.size() || textures[at].width() != img.width() || textures[at].height() != img.height()) {
            texture t(texel_format::rgba32f, img.width(), img.height());
            if (at == textures.size())
                textures.push_back(std::move(t));
            else
                textures[at] = std::move(t);
        }
        if (padded.width() != img.width() || padded.height() != img.height())
            padded = image<glm::vec4>(img.width(), img.height());
        for (std::size_t y = 0; y < img.height(); ++y)
            for (std::size_t x = 0; x < img.width(); ++x) padded(x, y) = glm::vec4(img(x, y), 0.f);
        write_texture(textures[at], padded.view());
    }
};

offscreen_indirect_renderer::offscreen_indirect_renderer(const context_options& options)
    : context_(options), uploads_(std::make_unique<uploads>()) {}

offscreen_indirect_renderer::~offscreen_indirect_renderer() {
    context_.make_current();
    renderer_.reset();
    uploads_.reset();
}

indirect_timings offscreen_indirect_renderer::render(const indirect_options& options, const gbuffer_view<float>& gb,
                                                     const camera& cam, std::span<const rsm_view> maps,
                                                     image_view<glm::vec3> irradiance) {
    indirect_renderer::validate_options(options);
    cam.validate();
    require(!gb.depth.empty(), "gb", "is empty");
    require(irradiance.width() == gb.width() && irradiance.height() == gb.height(), "irradiance",
            "size differs from the G-buffer");
    for (const auto& m : maps) m.validate();
    context_.make_current();
    uploads& u = *uploads_;
    u.gbuffer.upload(gb);
    std::vector<rsm_textures> refs;
    refs.reserve(maps.size());
    for (std::size_t i = 0; i < maps.size(); ++i) {
        u.upload(3 * i, maps[i].position);
        u.upload(3 * i + 1, maps[i].normal);
        u.upload(3 * i + 2, maps[i].flux);
    }
    for (std::size_t i = 0; i < maps.size(); ++i)
        refs.push_back({u.textures[3 * i], u.textures[3 * i + 1], u.textures[3 * i + 2], maps[i].light_view_projection});
    if (!u.out || u.out->width() != gb.width() || u.out->height() != gb.height())
        u.out.emplace(texel_format::rgba32f, gb.width(), gb.height());
    if (!renderer_ || !(renderer_->options() == options)) {
        renderer_.reset();
        renderer_.emplace(options, /*time_stages=*/true);
    }
    renderer_->set_point_sampler(points_);
    const indirect_timings t = renderer_->render(u.gbuffer.textures(), cam, refs, *u.out);
    read_texture(*u.out, irradiance);
    return t;
}

}  // namespace bounce::gl
