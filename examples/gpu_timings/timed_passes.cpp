// The fixed set of GL passes, each a library type driven through its public API (as
// examples/ and tests/gl* drive them), timed by gpu_timer.hpp.
#include "timed_passes.hpp"

#include <bounce/cornell_box.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/indirect_renderer.hpp>
#include <bounce/gl/irradiance_volume.hpp>
#include <bounce/gl/radiosity.hpp>
#include <bounce/gl/rsm_renderer.hpp>
#include <bounce/gl/splat_pass.hpp>
#include <bounce/radiosity/lightmap_atlas.hpp>
#include <bounce/sampling.hpp>
#include <bounce/volume/probe_octree.hpp>

#include <cmath>
#include <string>

#include <glm/geometric.hpp>

namespace bounce::gpu_timings {

owned_scene timing_scene(int subdivide) {
    owned_scene s;
    build_cornell_box(s);
    for (int level = 0; level < subdivide; ++level) {
        owned_scene finer = s;
        finer.positions.clear();
        finer.normals.clear();
        finer.triangles.clear();
        finer.material_of.clear();
        const auto add = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 n, std::uint32_t m) {
            const auto base = std::uint32_t(finer.positions.size());
            finer.positions.insert(finer.positions.end(), {a, b, c});
            finer.normals.insert(finer.normals.end(), {n, n, n});
            finer.triangles.emplace_back(base, base + 1, base + 2);
            finer.material_of.push_back(m);
        };
        for (std::size_t t = 0; t < s.triangles.size(); ++t) {
            const glm::uvec3 tri = s.triangles[t];
            const glm::vec3 a = s.positions[tri.x], b = s.positions[tri.y], c = s.positions[tri.z];
            const glm::vec3 ab = 0.5f * (a + b), bc = 0.5f * (b + c), ca = 0.5f * (c + a), n = s.normals[tri.x];
            const std::uint32_t m = s.material_of[t];
            add(a, ab, ca, n, m);
            add(ab, b, bc, n, m);
            add(ca, bc, c, n, m);
            add(ab, bc, ca, n, m);
        }
        s = std::move(finer);
    }
    return s;
}

std::vector<irradiance_record> fixed_records(const owned_scene& scene, std::size_t count) {
    std::vector<double> cumulative;
    double total = 0;
    for (const glm::uvec3 t : scene.triangles) {
        const glm::vec3 a = scene.positions[t.x], b = scene.positions[t.y], c = scene.positions[t.z];
        total += 0.5 * double(glm::length(glm::cross(b - a, c - a)));
        cumulative.push_back(total);
    }
    const auto [lo, hi] = scene.view().bounds();
    const float diagonal = glm::length(hi - lo);
    pcg32 rng(2026, 32);
    std::vector<irradiance_record> records(count);
    for (irradiance_record& r : records) {
        const double pick = double(rng.next_float()) * total;
        std::size_t t = std::size_t(std::lower_bound(cumulative.begin(), cumulative.end(), pick) - cumulative.begin());
        t = std::min(t, scene.triangles.size() - 1);
        const glm::uvec3 tri = scene.triangles[t];
        float u = rng.next_float(), v = rng.next_float();
        if (u + v > 1.f) u = 1.f - u, v = 1.f - v;
        const glm::vec3 a = scene.positions[tri.x], b = scene.positions[tri.y], c = scene.positions[tri.z];
        r.position = a + u * (b - a) + v * (c - a);
        r.normal = glm::normalize(glm::cross(b - a, c - a));
        const float shade = 0.5f + 0.5f * std::sin(7.f * r.position.x + 5.f * r.position.z);
        r.irradiance = glm::vec3(1.f + shade, 0.8f + 0.5f * shade, 0.6f + 0.3f * shade);
        for (int k = 0; k < 3; ++k) {
            r.rotation[k] = 0.1f * r.irradiance[k] * glm::vec3(shade, 1.f - shade, 0.5f);
            r.translation[k] = 0.2f * r.irradiance[k] * glm::vec3(0.5f, shade, 1.f - shade) / diagonal;
        }
        r.radius = diagonal * (0.1f + 0.3f * rng.next_float());
    }
    return records;
}

namespace {

// A uniform octree of the given depth over the scene's box whose probes hold a smooth
// made-up radiance field with its gradients: the lookup's cost depends on the octree, not
// on where the numbers came from.
irradiance_volume timing_volume(const scene_view& scene, int depth) {
    irradiance_volume_settings st;
    st.min_depth = st.max_depth = depth;
    st.distance_ratio = st.neighbour_change = st.gradient_ratio = st.cull_tolerance = 0;
    st.geometry_triangles = 0;
    const auto [lo, hi] = scene.bounds();
    const auto source = [](std::span<const glm::vec3> p, std::span<irradiance_probe> out) {
        for (std::size_t j = 0; j < p.size(); ++j) {
            out[j] = {};
            out[j].position = p[j];
            for (std::size_t i = 0; i < out[j].radiance.size(); ++i) {
                const float a = 0.3f * float(i + 1), x = p[j].x, y = p[j].y, z = p[j].z;
                out[j].radiance[i] = glm::vec3(std::sin(a * x) + 1.5f, std::cos(a * y) + z, 0.5f * x * y + 1.f) / float(i + 1);
                out[j].gradient[0][i] = glm::vec3(a * std::cos(a * x), 0.f, 0.5f * y) / float(i + 1);
                out[j].gradient[1][i] = glm::vec3(0.f, -a * std::sin(a * y), 0.5f * x) / float(i + 1);
                out[j].gradient[2][i] = glm::vec3(0.f, 1.f, 0.f) / float(i + 1);
            }
            out[j].harmonic_mean_distance = 1.f;
        }
    };
    return irradiance_volume::build(scene, lo, hi, st, source);
}

// What every pass shares: the scene on the GPU, its shadow-mapped direct light, the fixed
// record set, its reflective shadow maps and an irradiance volume.
struct gpu_scene {
    owned_scene scene;
    scene_view view;
    gl::scene_mesh mesh;
    gl::direct_light light;
    std::vector<irradiance_record> records;
    gl::rsm_renderer rsm;
    irradiance_volume volume;
    gl::irradiance_volume_buffers volume_buffers;
    gl::irradiance_volume_lookup lookup;

    explicit gpu_scene(const settings& s)
        : scene(timing_scene(s.subdivide)), view(scene.view()), mesh(view), light(view, mesh),
          records(fixed_records(scene, s.records)), rsm(view, mesh, {s.rsm_resolution, 60.f}),
          volume(timing_volume(view, s.volume_depth)), volume_buffers(volume) {
        rsm.render();
    }
};

void time_indirect(gpu_scene& g, timestamp_timer& timer, const settings& s, const gl::gbuffer_textures& tex,
                   std::vector<pass_timing>& out) {
    gl::texture result(gl::texel_format::rgba32f, tex.width(), tex.height());
    struct variant {
        const char* name;
        indirect_technique technique;
        interleave_pattern pattern;
        std::size_t count;
    };
    const variant variants[] = {
        {"rsm_gather", indirect_technique::rsm_gather, {1, 1}, s.gather_samples},
        {"rsm_gather_8x8", indirect_technique::rsm_gather, {8, 8}, s.gather_samples},
        {"sii", indirect_technique::sii, {1, 1}, s.sii_vpls},
        {"sii_8x8", indirect_technique::sii, {8, 8}, s.sii_vpls},
    };
    const float clamp = scene_clamp_distance(g.view);
    for (const variant& v : variants) {
        indirect_options o;
        o.technique = v.technique;
        o.pattern = v.pattern;
        o.count = v.count;
        o.light.min_distance2 = clamp * clamp;
        gl::indirect_renderer renderer(o);
        const std::string what = v.technique == indirect_technique::sii
                                     ? std::to_string(v.count) + " VPLs selected on the host from the read-back maps, splatted"
                                     : std::to_string(v.count) + " disc samples per pixel and map gathered";
        out.push_back(timer.repeat(v.name,
                                   what + " over " + std::to_string(g.rsm.maps().size()) + " maps, " +
                                       std::to_string(v.pattern.n) + "x" + std::to_string(v.pattern.m) +
                                       " interleaving (split, shade, gather, blur)",
                                   1, s.repetitions, [&] { renderer.render(tex, g.scene.camera, g.rsm.maps(), result); }));
    }
}

pass_timing time_volume_lookup(gpu_scene& g, timestamp_timer& timer, const settings& s, const gl::gbuffer_pass& pass) {
    const bounce::gbuffer<float> read = pass.read();
    std::vector<glm::vec3> points, normals;
    for (std::size_t y = 0; y < read.height(); ++y)
        for (std::size_t x = 0; x < read.width(); ++x)
            if (std::isfinite(read.depth(x, y))) {
                points.push_back(read.position(x, y));
                normals.push_back(read.normal(x, y));
            }
    return timer.repeat("volume_lookup",
                        "trilinear lookup at the " + std::to_string(points.size()) +
                            " covered pixels' points (upload, compute pass, read-back)",
                        1, s.repetitions,
                        [&] { (void)g.lookup.light_points(g.volume_buffers, points, normals, gl::volume_interpolation::trilinear); });
}

image_passes time_image(gpu_scene& g, timestamp_timer& timer, const settings& s, std::size_t w, std::size_t h) {
    image_passes out{w, h, {}};
    const camera& cam = g.scene.camera;
    const int reps = s.repetitions;
    gl::gbuffer_pass gbuffer;
    out.passes.push_back(timer.repeat("gbuffer", "raster G-buffer: position/depth, normal, albedo (RGBA32F)", 1, reps,
                                      [&] { gbuffer.render(g.mesh, cam, w, h); }));
    const gl::gbuffer_textures tex = gl::textures_of(gbuffer);
    out.passes.push_back(timer.repeat("direct_light",
                                      "shadow-mapped direct radiance of " + std::to_string(g.light.light_count()) +
                                          " light(s), 16-tap PCF, full-screen pass",
                                      1, reps, [&] { g.light.render(tex); }));
    gl::splat_pass splats;
    splats.upload(g.records);
    const splat_params params;
    out.passes.push_back(timer.repeat("ic_splat",
                                      "splat " + std::to_string(g.records.size()) +
                                          " records (ward_smooth, gradients, a = 0.2) into a cleared buffer",
                                      1, reps, [&] { splats.splat(tex, cam, params, weighting_kind::ward_smooth); },
                                      [&] { splats.clear(w, h); }));
    gl::compose_pass compose;
    out.passes.push_back(timer.repeat("ic_normalize", "normalize the splat buffer and add the direct radiance", 1, reps,
                                      [&] { compose.compose(splats.splat_texture(), &g.light.radiance()); }));
    time_indirect(g, timer, s, tex, out.passes);
    out.passes.push_back(time_volume_lookup(g, timer, s, gbuffer));
    return out;
}

void time_radiosity(const gpu_scene& g, timestamp_timer& timer, const settings& s, scene_passes& out) {
    const lightmap_atlas atlas = build_lightmap_atlas(g.view, {.elements = s.elements});
    out.radiosity_elements = atlas.texel.size();
    gl::radiosity_options o;
    o.resolution = s.item_buffer;
    o.timed_stages = false;
    const auto step = [](gl::progressive_radiosity& solver) {
        if (!solver.step()) throw gl::gl_error("gpu_timings: the radiosity solve ran out of unshot power; ask for fewer repetitions");
    };
    gl::progressive_radiosity shot(g.view, atlas, o);
    out.passes.push_back(timer.repeat("radiosity_shot",
                                      "one progressive-radiosity step with the stereographic item buffer (" +
                                          std::to_string(s.item_buffer) + " px): shooter read-back, item buffer, "
                                          "distribution, reduction",
                                      1, s.repetitions, [&] { step(shot); }));
    o.visibility = gl::radiosity_visibility::none;
    gl::progressive_radiosity unoccluded(g.view, atlas, o);
    out.passes.push_back(timer.repeat("radiosity_shot_unoccluded", "the same step without visibility (no item buffer)", 1,
                                      s.repetitions, [&] { step(unoccluded); }));
    o.visibility = gl::radiosity_visibility::stereographic;
    o.timed_stages = true;
    gl::progressive_radiosity staged(g.view, atlas, o);
    step(staged);
    pass_timing item;
    item.name = "radiosity_item_buffer";
    item.method = "wall_clock_finish";
    item.covers = "the visibility stage of a step (shooter read-back, tessellation, item-buffer draw), host clock "
                  "between the solver's glFinish calls";
    for (int i = 0; i < s.repetitions; ++i) {
        const double before = staged.timings().visibility_ms;
        step(staged);
        item.ms.push_back(staged.timings().visibility_ms - before);
    }
    out.passes.push_back(std::move(item));
}

pass_timing time_hemisphere(const gpu_scene& g, timestamp_timer& timer, const settings& s) {
    gl::hemisphere_raster_options o;
    o.camera = plane_camera{s.plane_resolution, 126.0};
    o.batch = s.plane_batch;
    gl::hemisphere_raster raster(g.view, g.mesh, g.light, o);
    std::vector<glm::vec3> positions, normals;
    for (std::size_t k = 0; k < s.plane_batch; ++k) {
        const irradiance_record& r = g.records[k % g.records.size()];
        positions.push_back(r.position);
        normals.push_back(r.normal);
    }
    pass_timing t = timer.repeat("hemisphere_raster",
                                 std::to_string(s.plane_batch) + " planes of " + std::to_string(s.plane_resolution) + "x" +
                                     std::to_string(s.plane_resolution) +
                                     " px (126 deg) in one instanced draw, shaded with the direct light",
                                 1, s.repetitions, [&] { raster.render(positions, normals); });
    const auto per_second = [&](const std::vector<double>& ms) {
        const double median_s = summarize(ms).median_ms * 1e-3;
        return median_s > 0 ? double(s.plane_batch) / median_s : 0.0;
    };
    t.extra.emplace_back("planes_per_second", per_second(t.ms));
    t.extra.emplace_back("planes_per_second_wall", per_second(t.wall_ms));
    return t;
}

}  // namespace

timing_run run_timings(const settings& s, const std::vector<std::pair<std::size_t, std::size_t>>& sizes) {
    timestamp_timer timer;
    gpu_scene g(s);
    timing_run run;
    run.scene.triangles = g.scene.triangles.size();
    run.scene.rsm_maps = g.rsm.maps().size();
    run.scene.volume_probes = g.volume.probes().size();
    run.scene.passes.push_back(timer.repeat("rsm_maps",
                                            std::to_string(g.rsm.maps().size()) + " reflective shadow maps of " +
                                                std::to_string(s.rsm_resolution) + "^2 texels (position, normal, flux)",
                                            1, s.repetitions, [&] { g.rsm.render(); }));
    time_radiosity(g, timer, s, run.scene);
    run.scene.passes.push_back(time_hemisphere(g, timer, s));
    for (const auto& [w, h] : sizes) run.images.push_back(time_image(g, timer, s, w, h));
    return run;
}

}  // namespace bounce::gpu_timings
