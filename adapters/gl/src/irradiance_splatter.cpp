// The GPU stages of an irradiance-splatting frame around the caller's CPU scan.
#include <bounce/gl/irradiance_splatter.hpp>
#include <bounce/gl/objects.hpp>

#include <epoxy/gl.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <span>

namespace bounce::gl {

void irradiance_splatter_options::validate() const {
    splat.validate();
    require(std::isfinite(fill_holes) && fill_holes >= 0.f, "fill_holes", "must be a non-negative number (0: off)");
}

irradiance_splatter::irradiance_splatter(const irradiance_splatter_options& options) : options_(options) {
    options_.validate();
}

void irradiance_splatter::set_options(const irradiance_splatter_options& options) {
    options.validate();
    options_ = options;
}

void irradiance_splatter::splat_existing(const gbuffer_textures& g, const camera& cam,
                                         const std::vector<irradiance_record>& records, splatter_frame_stats& stats) {
    g.validate();
    const std::size_t w = g.width(), h = g.height();
    require(on_gpu_ <= records.size(), "records", "fewer records than the GPU holds: call reset() after replacing them");
    auto t0 = clock::now();
    if (on_gpu_ == 0) splats_.upload(records);  // first frame, or after reset()
    else if (on_gpu_ < records.size()) splats_.append(std::span(records).subspan(on_gpu_));
    on_gpu_ = records.size();
    splats_.clear(w, h);
    splats_.splat(splatted(g), cam, options_.splat, options_.weighting);
    if (options_.time_stages) finish();
    stats.splat_existing_ms = ms_since(t0);

    t0 = clock::now();
    if (gbuffer_.width() != w || gbuffer_.height() != h) {
        gbuffer_ = gbuffer<float>(w, h);
        splat_ = image<glm::vec4>(w, h);
    }
    read_gbuffer(g, gbuffer_.view());
    // The scan's copy weighs as the GPU does: an albedo of pi for irradiance (splatted(g)),
    // so that the verification's residuals divide the splat by the albedo it holds.
    if (output_ == output_quantity::irradiance)
        std::fill(gbuffer_.albedo.data(), gbuffer_.albedo.data() + w * h, glm::vec3(std::numbers::pi_v<float>));
    splats_.read_splat(splat_.view());
    stats.readback_ms = ms_since(t0);
}

void irradiance_splatter::resplat(const gbuffer_textures& g, const camera& cam,
                                  const std::vector<irradiance_record>& records, image_view<glm::vec4> splat) {
    g.validate();
    require(splat.width() == g.width() && splat.height() == g.height(), "splat", "size differs from the G-buffer");
    splats_.upload(records);
    on_gpu_ = records.size();
    wide_on_gpu_ = 0;  // radii changed: the wide splat's copy uploads again
    splats_.clear(g.width(), g.height());
    splats_.splat(splatted(g), cam, options_.splat, options_.weighting);
    splats_.read_splat(splat);
}

void irradiance_splatter::splat_new(const gbuffer_textures& g, const camera& cam,
                                    const std::vector<irradiance_record>& records, splatter_frame_stats& stats) {
    auto t0 = clock::now();
    const std::size_t before = on_gpu_;
    splats_.append(std::span(records).subspan(before));
    on_gpu_ = records.size();
    const gbuffer_textures sg = splatted(g);
    splats_.splat(sg, cam, options_.splat, options_.weighting, before);
    const bool fill = options_.fill_holes > 0.f;
    if (fill) {
        // Every record again with zones fill_holes x wider, for the pixels none reaches.
        if (wide_on_gpu_ > records.size()) wide_on_gpu_ = 0;
        if (wide_on_gpu_ == 0) wide_splats_.upload(records);
        else if (wide_on_gpu_ < records.size()) wide_splats_.append(std::span(records).subspan(wide_on_gpu_));
        wide_on_gpu_ = records.size();
        wide_splats_.clear(g.width(), g.height());
        splat_params wide = options_.splat;
        wide.a *= options_.fill_holes;
        wide_splats_.splat(sg, cam, wide, options_.weighting);
    }
    if (options_.time_stages) finish();
    stats.interpolate_ms = ms_since(t0);

    t0 = clock::now();
    compose_.compose(splats_.splat_texture(), nullptr, fill ? &wide_splats_.splat_texture() : nullptr, 1e-3f);
    if (options_.time_stages) finish();
    stats.normalize_ms = ms_since(t0);
}

gbuffer_textures irradiance_splatter::splatted(const gbuffer_textures& g) {
    if (output_ == output_quantity::radiance) return g;
    if (!pi_albedo_ || pi_albedo_->width() != g.width() || pi_albedo_->height() != g.height()) {
        pi_albedo_.emplace(texel_format::rgba32f, g.width(), g.height());
        const float pi[4] = {std::numbers::pi_v<float>, std::numbers::pi_v<float>, std::numbers::pi_v<float>, 1.f};
        glClearTexImage(pi_albedo_->id(), 0, GL_RGBA, GL_FLOAT, pi);
        check_error("irradiance_splatter: the albedo of pi");
    }
    gbuffer_textures out = g;
    out.albedo = *pi_albedo_;
    return out;
}

const texture& irradiance_splatter::compose(const texture& direct) {
    require(output_ == output_quantity::radiance, "output",
            "compose adds direct radiance to the indirect light: render with output_quantity::radiance");
    const bool fill = options_.fill_holes > 0.f;
    compose_.compose(splats_.splat_texture(), &direct, fill ? &wide_splats_.splat_texture() : nullptr, 1e-3f);
    return compose_.result();
}

}  // namespace bounce::gl
