// Reflective shadow maps between the CPU and GL: the textures' checks, their read-back into
// images, and the upload of CPU-made maps into textures of rsm_renderer's layout.
#include <bounce/gl/rsm_textures.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/errors.hpp>

#include <cmath>
#include <cstddef>
#include <string>

#include <glm/vec4.hpp>

namespace bounce::gl {

void rsm_textures::validate(const char* name) const {
    require(position.id != 0 && normal.id != 0 && flux.id != 0, name, "a map texture is missing");
    require(position.format == texel_format::rgba32f && normal.format == texel_format::rgba32f &&
                flux.format == texel_format::rgba32f,
            name, "position, normal and flux must be RGBA32F textures");
    require(flux.width > 0 && flux.height > 0, name, "the map has no size");
    require(position.width == flux.width && position.height == flux.height && normal.width == flux.width &&
                normal.height == flux.height,
            name, "position, normal and flux maps differ in size");
}

rsm_images::rsm_images(const rsm_textures& t)
    : position(t.width(), t.height()),
      normal(t.width(), t.height()),
      flux(t.width(), t.height()),
      light_view_projection(t.light_view_projection) {
    t.validate();
    read_texture(t.position, position.view());
    read_texture(t.normal, normal.view());
    read_texture(t.flux, flux.view());
}

namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// Throws parameter_error naming `name` at the first texel of `img` that `ok` refuses.
template <class Ok>
void require_texels(image_view<const glm::vec3> img, const std::string& name, const char* what, Ok ok) {
    for (std::size_t y = 0; y < img.height(); ++y)
        for (std::size_t x = 0; x < img.width(); ++x)
            if (!ok(img(x, y)))
                throw parameter_error(name, std::string(what) + " at texel (" + std::to_string(x) + ", " +
                                                std::to_string(y) + ")");
}

void check_map(const rsm_view& m, const std::string& name) {
    m.validate(name.c_str());
    for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
            require(std::isfinite(m.light_view_projection[c][r]), name.c_str(), "light_view_projection is not finite");
    require_texels(m.position, name, "position is not finite", finite);
    require_texels(m.normal, name, "normal is not finite", finite);
    require_texels(m.flux, name, "flux is not finite and non-negative",
                   [](const glm::vec3& f) { return finite(f) && f.x >= 0.f && f.y >= 0.f && f.z >= 0.f; });
}

// `img` into `t` as rgb with a = 0 (write_texture flips the rows), through `padded`.
void write_rgb(const texture& t, image_view<const glm::vec3> img, image<glm::vec4>& padded) {
    if (padded.width() != img.width() || padded.height() != img.height()) padded = image<glm::vec4>(img.width(), img.height());
    for (std::size_t y = 0; y < img.height(); ++y)
        for (std::size_t x = 0; x < img.width(); ++x) padded(x, y) = glm::vec4(img(x, y), 0.f);
    write_texture(t, padded.view());
}

}  // namespace

void rsm_upload::upload(std::span<const rsm_view> maps) {
    for (std::size_t i = 0; i < maps.size(); ++i) check_map(maps[i], "maps[" + std::to_string(i) + "]");
    if (owned_.size() > maps.size()) owned_.erase(owned_.begin() + std::ptrdiff_t(maps.size()), owned_.end());
    refs_.clear();
    image<glm::vec4> padded;
    for (std::size_t i = 0; i < maps.size(); ++i) {
        const rsm_view& m = maps[i];
        const std::size_t w = m.width(), h = m.height();
        if (i == owned_.size())
            owned_.push_back({texture(texel_format::rgba32f, w, h), texture(texel_format::rgba32f, w, h),
                              texture(texel_format::rgba32f, w, h)});
        else if (owned_[i].flux.width() != w || owned_[i].flux.height() != h)
            owned_[i] = {texture(texel_format::rgba32f, w, h), texture(texel_format::rgba32f, w, h),
                         texture(texel_format::rgba32f, w, h)};
        write_rgb(owned_[i].position, m.position, padded);
        write_rgb(owned_[i].normal, m.normal, padded);
        write_rgb(owned_[i].flux, m.flux, padded);
        refs_.push_back({owned_[i].position, owned_[i].normal, owned_[i].flux, m.light_view_projection});
    }
}

}  // namespace bounce::gl
