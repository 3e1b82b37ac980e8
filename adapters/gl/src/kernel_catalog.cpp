// The catalog of every kernel the GL passes emit (kernel_catalog.hpp). Each line names the
// kernel as its pass does; tests/spirv checks that no name a pass adds is missing here.
#include <bounce/gl/kernel_catalog.hpp>

#include <bounce/cache/plane_pixel.hpp>
#include <bounce/cache/record.hpp>
#include <bounce/cache/weighting.hpp>
#include <bounce/direct_light.hpp>
#include <bounce/gl/irradiance_volume.hpp>
#include <bounce/indirect/imperfect_shadow_maps.hpp>
#include <bounce/indirect/interleaved_sampling.hpp>
#include <bounce/indirect/rsm.hpp>
#include <bounce/indirect/rsm_layout.hpp>
#include <bounce/indirect/rsm_sampling.hpp>
#include <bounce/radiosity/ambient.hpp>
#include <bounce/radiosity/kernels.hpp>
#include <bounce/radiosity/shooters.hpp>
#include <bounce/radiosity/sides.hpp>
#include <bounce/radiosity/stereographic_tessellation.hpp>
#include <bounce/sampling.hpp>
#include <bounce/shadow_mapping.hpp>
#include <bounce/splat_bounds.hpp>
#include <bounce/surface.hpp>
#include <bounce/volume/kernels.hpp>
#include <bounce/volume/visibility_kernels.hpp>

#include <string>
#include <utility>

namespace bounce::gl {

namespace {

// A kernel as text and as the expression: `add(pass, name, BOUNCE_KERNEL(f<T, V>))`.
#define BOUNCE_KERNEL(...) #__VA_ARGS__, __VA_ARGS__

using glsl::f32;
using glsl::vec2;
using glsl::vec3;
using glsl::vec4;

class catalog {
public:
    explicit catalog(compute_target target) : target_(target) {}

    /// `kernel` is the C++ expression of `fn` as written (BOUNCE_KERNEL gives both).
    template <class F>
    catalog& add(const char* pass, const char* name, const char* kernel, F&& fn, std::string variant = {}) {
        kernels_.push_back({pass, name, kernel, std::move(variant), map_kernel_source(std::forward<F>(fn), target_)});
        return *this;
    }
    std::vector<emitted_kernel> take() { return std::move(kernels_); }

private:
    compute_target target_;
    std::vector<emitted_kernel> kernels_;
};

void splatting(catalog& c) {
    for (const weighting_kind kind : weighting_kinds)
        with_weighting(kind, [&](auto policy) {
            using W = decltype(policy);
            const std::string w(weighting_name(kind));
            c.add("splat_pass vertex", "influence_radius", BOUNCE_KERNEL(&W::template influence_radius<f32>), w);
            for (const bool gradients : {false, true})
                for (const bool front : {false, true})
                    with_kernel_flags(gradients, front, [&](auto g, auto f) {
                        c.add("splat_pass fragment", "splat_contribution",
                              BOUNCE_KERNEL(splat_contribution<W, decltype(g)::value, decltype(f)::value, f32, vec3>),
                              w + (gradients ? ", gradients" : "") + (front ? ", front test" : ""));
                    });
        });
    c.add("splat_pass vertex", "sphere_ndc_bounds", BOUNCE_KERNEL(sphere_ndc_bounds<f32, vec3>))
        .add("compose_pass", "normalized_splat", BOUNCE_KERNEL(normalized_splat<f32, vec3>))
        .add("compose_pass", "hole_filled_splat", BOUNCE_KERNEL(hole_filled_splat<f32, vec3>));
}

void direct_and_gbuffer(catalog& c) {
    c.add("gbuffer_pass", "facing_normal", BOUNCE_KERNEL(facing_normal<f32, vec3>))
        .add("gbuffer_pass", "view_depth", BOUNCE_KERNEL(view_depth<f32, vec3>))
        .add("direct_light radial depth", "radial_shadow_depth", BOUNCE_KERNEL(radial_shadow_depth<f32, vec3>))
        .add("direct_light radial depth", "slope_biased_depth", BOUNCE_KERNEL(slope_biased_depth<f32>))
        .add("direct_light", "bounce_dl_point_light_irradiance", BOUNCE_KERNEL(point_light_irradiance<f32, vec3>))
        .add("direct_light", "bounce_dl_spot_light_irradiance", BOUNCE_KERNEL(spot_light_irradiance<f32, vec3>))
        .add("direct_light", "bounce_dl_directional_light_irradiance", BOUNCE_KERNEL(directional_light_irradiance<f32, vec3>))
        .add("direct_light", "bounce_dl_normal_offset_point", BOUNCE_KERNEL(normal_offset_point<f32, vec3>))
        .add("direct_light", "bounce_dl_perspective_shadow_texel", BOUNCE_KERNEL(perspective_shadow_texel<f32, vec3>))
        .add("direct_light", "bounce_dl_cube_shadow_texel", BOUNCE_KERNEL(cube_shadow_texel<f32, vec3>))
        .add("direct_light", "bounce_dl_shadow_map_taps", BOUNCE_KERNEL(shadow_map_taps<f32, vec3>))
        .add("direct_light", "bounce_dl_cube_shadow_taps", BOUNCE_KERNEL(cube_shadow_taps<f32, vec3>))
        .add("direct_light", "bounce_dl_pcf_visibility", BOUNCE_KERNEL(pcf_visibility<f32>))
        .add("direct_light radiance, output_pass, hemisphere_raster", "lambertian_radiance", BOUNCE_KERNEL(lambertian_radiance<f32, vec3>))
        .add("hemisphere_raster", "plane_hit_distance", BOUNCE_KERNEL(plane_hit_distance<f32, vec3>))
        .add("hemisphere_raster reduce", "plane_pixel_terms", BOUNCE_KERNEL(plane_pixel_terms<f32, vec3, vec2>))
        .add("rsm_renderer", "point_light_texel_flux", BOUNCE_KERNEL(point_light_texel_flux<f32, vec3>))
        .add("rsm_renderer", "spot_light_texel_flux", BOUNCE_KERNEL(spot_light_texel_flux<f32, vec3>))
        .add("rsm_renderer", "directional_light_texel_flux", BOUNCE_KERNEL(directional_light_texel_flux<f32, vec3>));
}

void indirect(catalog& c) {
    c.add("indirect split, gather", "interleave_gather_coordinate", BOUNCE_KERNEL(interleave_gather_coordinate<f32>))
        .add("indirect split", "interleave_split_coordinate", BOUNCE_KERNEL(interleave_split_coordinate<f32>))
        .add("indirect gather", "rsm_disc_centre", BOUNCE_KERNEL(rsm_disc_centre<f32, vec2>))
        .add("indirect gather", "pixel_light_irradiance", BOUNCE_KERNEL(pixel_light_irradiance<f32, vec3>))
        .add("indirect upsample", "geometry_aware_upsample_weights", BOUNCE_KERNEL(geometry_aware_upsample_weights<f32, vec3>))
        .add("indirect edges", "geometry_discontinuity", BOUNCE_KERNEL(geometry_discontinuity<f32, vec3>))
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<1, f32, vec3>), "R = 1")
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<3, f32, vec3>), "R = 3")
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<7, f32, vec3>), "R = 7")
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<15, f32, vec3>), "R = 15")
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<31, f32, vec3>), "R = 31")
        .add("indirect tent", "geometry_aware_tent", BOUNCE_KERNEL(geometry_aware_tent<63, f32, vec3>), "R = 63")
        .add("indirect splat", "ism_map_texel", BOUNCE_KERNEL(ism_map_texel<f32, vec3, vec2>))
        .add("indirect splat", "ism_visible", BOUNCE_KERNEL(ism_visible<f32, vec3>))
        .add("indirect ism splat", "ism_splat_texel", BOUNCE_KERNEL(ism_splat_texel<f32, vec3, vec2>))
        .add("indirect ism pull", "ism_pull", BOUNCE_KERNEL(ism_pull<f32>))
        .add("indirect ism push", "ism_push", BOUNCE_KERNEL(ism_push<f32>));
}

void volume(catalog& c) {
    constexpr int L = irradiance_volume_bands;
    c.add("irradiance_volume_lookup", "iv_clamp", BOUNCE_KERNEL(volume_clamp<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_octant", BOUNCE_KERNEL(octree_octant<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_reaches", BOUNCE_KERNEL(octree_node_reaches<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_trilinear_weights", BOUNCE_KERNEL(trilinear_weights<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_trilinear_add", BOUNCE_KERNEL(trilinear_probe_accumulate<L, f32, vec3>))
        .add("irradiance_volume_lookup", "iv_weighted_add", BOUNCE_KERNEL(weighted_probe_accumulate<L, f32, vec3>))
        .add("irradiance_volume_lookup", "iv_average", BOUNCE_KERNEL(probe_average<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_oct_encode", BOUNCE_KERNEL(octahedral_encode<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_oct_bilinear", BOUNCE_KERNEL(octahedral_bilinear<f32>))
        .add("irradiance_volume_lookup", "iv_oct_texel", BOUNCE_KERNEL(octahedral_texel_index<f32>))
        .add("irradiance_volume_lookup", "iv_bilinear_moments", BOUNCE_KERNEL(bilinear_moments<f32>))
        .add("irradiance_volume_lookup", "iv_view", BOUNCE_KERNEL(view_direction<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_spacing", BOUNCE_KERNEL(cell_spacing<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_bias", BOUNCE_KERNEL(self_shadow_biased<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_probe_to_point", BOUNCE_KERNEL(probe_to_point<f32, vec3>))
        .add("irradiance_volume_lookup", "iv_visibility_weight", BOUNCE_KERNEL(visibility_probe_weight<f32, vec3>));
}

void radiosity(catalog& c) {
    c.add("radiosity item buffer", "radiosity_to_shooter_frame", BOUNCE_KERNEL(to_shooter_frame<f32, vec3>))
        .add("radiosity item buffer", "radiosity_stereographic_texel", BOUNCE_KERNEL(stereographic_item_texel<f32, vec3, vec2>))
        .add("radiosity item buffer", "radiosity_hemicube_texel", BOUNCE_KERNEL(hemicube_item_texel<f32, vec3>))
        .add("radiosity item buffer", "radiosity_hemicube_first_row", BOUNCE_KERNEL(hemicube_face_first_row<f32>))
        .add("radiosity item buffer", "radiosity_parallel_texel", BOUNCE_KERNEL(parallel_item_texel<f32, vec3, vec2>))
        .add("radiosity item buffer", "radiosity_parallel_sees", BOUNCE_KERNEL(parallel_item_sees<f32, vec3>))
        .add("radiosity item buffer", "radiosity_item_sees", BOUNCE_KERNEL(item_buffer_sees<f32, vec3>))
        .add("radiosity stereographic", "radiosity_item_coords", BOUNCE_KERNEL(stereographic_item_coords<f32, vec3, vec2>))
        .add("radiosity stereographic", "radiosity_texel_direction", BOUNCE_KERNEL(stereographic_texel_direction<f32, vec3, vec2>))
        .add("radiosity stereographic", "radiosity_plane_depth", BOUNCE_KERNEL(item_plane_depth<f32, vec3>))
        .add("radiosity hemicube", "radiosity_frame_coords", BOUNCE_KERNEL(frame_coords<f32, vec3>))
        .add("radiosity hemicube", "radiosity_face_clip", BOUNCE_KERNEL(hemicube_face_clip<f32, vec3, vec4>))
        .add("radiosity parallel", "radiosity_parallel_coords", BOUNCE_KERNEL(parallel_item_coords<f32, vec3, vec2>))
        .add("radiosity shot", "radiosity_form_factor", BOUNCE_KERNEL(element_form_factor<f32, vec3>))
        .add("radiosity shot", "radiosity_near_field", BOUNCE_KERNEL(near_field_opens<f32, vec3>))
        .add("radiosity shot", "radiosity_receiving_side", BOUNCE_KERNEL(receiving_side<f32, vec3>))
        .add("radiosity shot", "radiosity_side_normal", BOUNCE_KERNEL(side_normal<f32, vec3>))
        .add("radiosity direct", "radiosity_light_side", BOUNCE_KERNEL(light_hemisphere_side<f32, vec3>))
        .add("radiosity direct", "radiosity_point_irradiance", BOUNCE_KERNEL(point_light_irradiance<f32, vec3>))
        .add("radiosity direct", "radiosity_directional_irradiance", BOUNCE_KERNEL(directional_light_irradiance<f32, vec3>))
        .add("radiosity direct", "radiosity_spot_irradiance", BOUNCE_KERNEL(spot_light_irradiance<f32, vec3>))
        .add("radiosity display", "radiosity_display", BOUNCE_KERNEL(radiosity_with_ambient<f32, vec3>))
        .add("radiosity display", "radiosity_display_at_least", BOUNCE_KERNEL(radiosity_with_ambient_at_least_direct<f32, vec3>))
        .add("radiosity display", "radiosity_mixed_ambient", BOUNCE_KERNEL(mixed_ambient<f32, vec3>))
        .add("radiosity ambient window", "radiosity_mixed_deficit", BOUNCE_KERNEL(mixed_ambient_deficit<f32, vec3>));
}

#undef BOUNCE_KERNEL

}  // namespace

std::vector<emitted_kernel> emitted_kernels(compute_target target) {
    catalog c(target);
    splatting(c);
    direct_and_gbuffer(c);
    indirect(c);
    volume(c);
    radiosity(c);
    return c.take();
}

}  // namespace bounce::gl
