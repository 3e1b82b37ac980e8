// hemisphere_study: single-plane hemisphere sampling (Gautron 2008, section 8.4, Table 8.1)
// against a full-hemisphere Monte Carlo reference, on K random visible points of a scene.
//
//   build/bin/hemisphere_study --scene ../shared/scenes/sponza/scene.json --resolution 64
//       --aperture 126 --points 10000 --json study.json        (one command line)
//   build/bin/hemisphere_study --scene ... --sweep --sweep-points 1000 --json sweep.json
//
// Per point, irradiance from the plane's pixels with four weightings (plane only, coverage
// ratio, border stretching, fall-off stretching), from two samplers: the GL raster sampler
// (gl::hemisphere_raster: shadow-mapped direct light, atlas batches, PBO read-back and CPU
// sums, or the GPU reduction) and the ray-cast sampler (the same plane's pixel rays through
// Embree, shaded with the reference integrator's direct light), which separates the
// estimator's error from rasterization's. Error: relative RMS of luminance,
// sqrt(mean((E - E_ref)^2)) / sqrt(mean(E_ref^2)), as in the seed's Table 8.1.
#include <bounce/study/content_hash.hpp>
#include <bounce/embree/accel.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/embree/plane_sampler.hpp>
#include <bounce/embree/reference.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/reference_cache.hpp>
#include <bounce/study/run_report.hpp>
#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/luminance.hpp>
#include <bounce/plane_camera.hpp>
#include <bounce/plane_weights.hpp>
#include <bounce/radial_profile.hpp>
#include <bounce/io/image_io.hpp>
#include <bounce/io/scene.hpp>
#include <bounce/sampling.hpp>

#ifdef BOUNCE_STUDY_WITH_GL
#include <bounce/gl/context.hpp>
#include <bounce/gl/direct_light.hpp>
#include <bounce/gl/gbuffer_pass.hpp>
#include <bounce/gl/hemisphere_raster.hpp>
#include <bounce/gl/objects.hpp>
#include <bounce/gl/raster_record_sampler.hpp>
#endif

#include <CLI/CLI.hpp>
#include "../common/cli_number_checks.hpp"
#include <fmt/core.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <numeric>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace fs = std::filesystem;
using namespace bounce;
using json = nlohmann::ordered_json;

namespace {

using clock_type = std::chrono::steady_clock;
double seconds_since(clock_type::time_point t0) {
    return std::chrono::duration<double>(clock_type::now() - t0).count();
}

struct study_point {
    glm::vec3 p, n;
};

// K distinct covered pixels of a ray-cast G-buffer of the scene's camera, chosen by a partial
// Fisher-Yates shuffle from a fixed seed: points the camera sees, with their facing normals.
std::vector<study_point> pick_points(const embree::accel& bvh, const io::scene& scene, std::size_t K,
                                     std::uint64_t seed) {
    const std::size_t side = 512;
    const auto g = embree::ray_cast_gbuffer(bvh, scene, scene.camera, side, side);
    std::vector<std::size_t> covered;
    for (std::size_t y = 0; y < side; ++y)
        for (std::size_t x = 0; x < side; ++x)
            if (std::isfinite(g.depth(x, y))) covered.push_back(y * side + x);
    if (covered.size() < K)
        throw parameter_error("points", "the camera sees only " + std::to_string(covered.size()) + " pixels of " +
                                            std::to_string(side) + "^2");
    pcg32 rng(seed);
    std::vector<study_point> pts;
    for (std::size_t k = 0; k < K; ++k) {
        const std::size_t j = k + std::size_t(rng.next_u32()) % (covered.size() - k);
        std::swap(covered[k], covered[j]);
        const std::size_t x = covered[k] % side, y = covered[k] / side;
        pts.push_back({g.position(x, y), glm::normalize(g.normal(x, y))});
    }
    return pts;
}

double luminance(const glm::dvec3& c) { return rec709_luminance<double, glm::dvec3>(c); }

// Relative RMS error of luminance (study::compare_luminance on K x 1 images).
double rel_rms(const std::vector<glm::dvec3>& E, const std::vector<glm::dvec3>& ref) {
    image<glm::vec3> x(E.size(), 1), r(ref.size(), 1);
    for (std::size_t k = 0; k < E.size(); ++k) {
        x(k, 0) = glm::vec3(E[k]);
        r(k, 0) = glm::vec3(ref[k]);
    }
    return study::compare_luminance(x.view(), r.view()).rel_rms;
}

// ---- the reference -----------------------------------------------------------------------

struct reference_set {
    std::vector<glm::dvec3> E;  // mean of the two halves
    double own_error = 0;       // relative RMS error of E itself, from the two halves
    std::uint32_t spp = 0;      // rays per half
    bool from_cache = false;
};

// Two independent halves of `spp` stratified rays each per point (derive_seed streams 1 and
// 2): their difference measures the error of their mean, rms(E_a - E_b) / 2 relative to
// rms(E). If that exceeds `target`, the sample count doubles (up to 8 times the start).
// Cached in `cache_dir` under a hash of the points, the sample count, the seed and, when
// one pins Embree's kernels, the device's configuration (as the image references are).
reference_set compute_reference(const embree::reference_integrator& ref, const io::scene& scene,
                                const std::vector<study_point>& pts, std::uint32_t spp, std::uint64_t seed,
                                double target, const fs::path& cache_dir, bool use_cache,
                                const std::string& device_config) {
    for (std::uint32_t attempt = 0;; ++attempt) {
        study::fnv1a_hash key;
        key.bytes(pts.data(), pts.size() * sizeof(study_point));
        key.value(spp);
        key.value(seed);
        if (!device_config.empty()) key.text(device_config);
        const std::uint64_t h = key.digest();
        const fs::path file = cache_dir / fmt::format("hemisphere-reference-{}-{}pts-{}spp-{:016x}.bin", scene.name,
                                                      pts.size(), spp, h);
        std::vector<glm::vec3> a(pts.size()), b(pts.size());
        bool loaded = false;
        if (use_cache) {
            std::ifstream in(file, std::ios::binary);
            if (in) {
                in.read(reinterpret_cast<char*>(a.data()), std::streamsize(a.size() * sizeof(glm::vec3)));
                in.read(reinterpret_cast<char*>(b.data()), std::streamsize(b.size() * sizeof(glm::vec3)));
                loaded = bool(in) && in.peek() == std::char_traits<char>::eof();
            }
        }
        if (!loaded) {
            fmt::print(stderr, "  reference: {} points x 2 x {} rays...\n", pts.size(), spp);
            tbb::parallel_for(std::size_t(0), pts.size(), [&](std::size_t k) {
                a[k] = ref.indirect_irradiance(pts[k].p, pts[k].n, spp, embree::derive_seed(seed, 1, k));
                b[k] = ref.indirect_irradiance(pts[k].p, pts[k].n, spp, embree::derive_seed(seed, 2, k));
            });
            if (use_cache) {
                fs::create_directories(cache_dir);
                const fs::path tmp = file.string() + ".tmp";
                {
                    std::ofstream out(tmp, std::ios::binary);
                    out.write(reinterpret_cast<const char*>(a.data()), std::streamsize(a.size() * sizeof(glm::vec3)));
                    out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size() * sizeof(glm::vec3)));
                }
                fs::rename(tmp, file);
            }
        }
        reference_set r;
        r.spp = spp;
        r.from_cache = loaded;
        double diff2 = 0, sig2 = 0;
        for (std::size_t k = 0; k < pts.size(); ++k) {
            r.E.push_back((glm::dvec3(a[k]) + glm::dvec3(b[k])) / 2.0);
            const double d = luminance(a[k]) - luminance(b[k]), m = luminance(r.E.back());
            diff2 += d * d;
            sig2 += m * m;
        }
        r.own_error = sig2 > 0 ? std::sqrt(diff2) / 2 / std::sqrt(sig2) : 0;
        if (r.own_error <= target || attempt >= 3) return r;
        fmt::print(stderr, "  reference error {:.3f}% above {:.2f}%: doubling the rays\n", 100 * r.own_error,
                   100 * target);
        spp *= 2;
    }
}

// ---- estimates ---------------------------------------------------------------------------

// Irradiance per point for the four weightings, from the plane and stretch sums of each
// record (coverage and fall-off are linear in them: E_cov = pi / sum(w_plane) E_plane,
// E_falloff = E_plane + kappa (E_stretch - E_plane)), and the records' kappa: pooled over
// the whole run, and running (what a renderer can know: the profile of the batches made so
// far, the record's own batch included).
struct estimates {
    std::vector<glm::dvec3> plane, stretch;
    std::vector<double> running_kappa;  // per point
    double coverage_scale = 1, kappa = 1;
    double seconds = 0;  // wall time of sampling and summing all records

    std::vector<glm::dvec3> coverage() const {
        std::vector<glm::dvec3> c;
        for (const auto& e : plane) c.push_back(e * coverage_scale);
        return c;
    }
    std::vector<glm::dvec3> falloff(std::span<const double> kappas = {}) const {
        std::vector<glm::dvec3> f;
        for (std::size_t k = 0; k < plane.size(); ++k)
            f.push_back(plane[k] + (kappas.empty() ? kappa : kappas[k]) * (stretch[k] - plane[k]));
        return f;
    }
    json errors(const std::vector<glm::dvec3>& ref) const {
        return {{"rms_plane", rel_rms(plane, ref)},
                {"rms_coverage", rel_rms(coverage(), ref)},
                {"rms_stretch", rel_rms(stretch, ref)},
                {"rms_falloff", rel_rms(falloff(), ref)},
                {"falloff_kappa", kappa},
                {"rms_falloff_running", rel_rms(falloff(running_kappa), ref)},
                {"falloff_kappa_first_batch", running_kappa.empty() ? 1.0 : running_kappa.front()}};
    }
};

struct tables {
    plane_weights plane, stretch;
    explicit tables(const plane_camera& cam)
        : plane(make_plane_weights(cam, plane_weighting::plane)), stretch(make_plane_weights(cam, plane_weighting::stretch)) {}
    double coverage_scale() const { return make_plane_weights(plane.camera, plane_weighting::coverage).scale; }
};

// The ray-cast sampler: each pixel's ray from p + eps n through the plane, shaded with the
// reference integrator's incoming radiance (Kd / pi * E_direct at the hit, shadow rays).
// Batches of `batch` points in order, as a renderer makes them (parallel within a batch).
estimates ray_cast(const embree::reference_integrator& ref, const std::vector<study_point>& pts, const plane_camera& cam,
                   std::size_t batch) {
    const tables t(cam);
    estimates out;
    out.plane.resize(pts.size());
    out.stretch.resize(pts.size());
    out.running_kappa.resize(pts.size());
    out.coverage_scale = t.coverage_scale();
    tbb::enumerable_thread_specific<radial_profile> profiles([&] { return radial_profile(cam); });
    // Every plane so far: the threads' profiles pooled (each holds what its thread added).
    const auto pooled = [&] {
        radial_profile all = *profiles.begin();
        for (auto it = std::next(profiles.begin()); it != profiles.end(); ++it) all.merge(*it);
        return all;
    };
    const auto t0 = clock_type::now();
    for (std::size_t first = 0; first < pts.size(); first += batch) {
        const std::size_t last = std::min(pts.size(), first + batch);
        tbb::parallel_for(first, last, [&](std::size_t k) {
            const auto [p, n] = pts[k];
            image<glm::vec3> radiance(cam.resolution, cam.resolution);
            image<float> distance(cam.resolution, cam.resolution);
            embree::sample_plane(ref, cam, p, n, radiance.view(), distance.view());
            const plane_view v{radiance.view(), distance.view()};
            out.stretch[k] = cpu::estimate_plane(t.stretch, v).irradiance;
            out.plane[k] = cpu::estimate_plane(t.plane, v).irradiance;
            profiles.local().add(radiance.view());
        });
        std::fill(out.running_kappa.begin() + std::ptrdiff_t(first), out.running_kappa.begin() + std::ptrdiff_t(last),
                  pooled().falloff_factor());
    }
    out.seconds = seconds_since(t0);
    out.kappa = out.running_kappa.empty() ? 1.0 : out.running_kappa.back();
    return out;
}

#ifdef BOUNCE_STUDY_WITH_GL
struct gl_scene {
    gl::scene_mesh mesh;
    gl::direct_light light;
    gl_scene(const io::scene& s, const gl::direct_light_options& shadows) : mesh(s), light(s, mesh, shadows) {}
};

// Points first .. first + batch - 1 (fewer at the end) as the raster sampler takes them.
void batch_points(const std::vector<study_point>& pts, std::size_t first, std::size_t batch,
                  std::vector<glm::vec3>& positions, std::vector<glm::vec3>& normals) {
    positions.clear();
    normals.clear();
    for (std::size_t k = first; k < std::min(pts.size(), first + batch); ++k) {
        positions.push_back(pts[k].p);
        normals.push_back(pts[k].n);
    }
}

struct raster_result {
    estimates cpu;              // PBO read-back + CPU sums (cpu::estimate_plane)
    double gpu_seconds = 0;     // render + GPU reduction (stretch table), all records
    double cpu_gpu_difference = 0;  // max relative difference of E_stretch between the two sums
    double running_seconds = 0;     // the record sampler's running fall-off mode, all records
    double running_cpu_gpu_difference = 0;  // max relative difference of its E from the CPU sums' running fall-off
};

// The raster sampler over all points in batches: render batch b, start its read-back, and
// sum batch b - 1 on the CPU while the GPU works (double-buffered PBOs). Then the same
// batches through gl::raster_record_sampler's running fall-off mode, whose kappa per batch
// is the running profile's (the CPU sums take it, so that every weighting is summed the same
// way), and again with the GPU reduction of the stretch table instead of the read-back.
raster_result raster(const io::scene& scene, const gl_scene& g, const std::vector<study_point>& pts,
                     const plane_camera& cam, std::size_t batch) {
    const tables t(cam);
    gl::hemisphere_raster_options o;
    o.camera = cam;
    o.batch = batch;
    gl::hemisphere_raster r(scene, g.mesh, g.light, o);
    raster_result out;
    out.cpu.plane.resize(pts.size());
    out.cpu.stretch.resize(pts.size());
    out.cpu.running_kappa.resize(pts.size());
    out.cpu.coverage_scale = t.coverage_scale();
    std::vector<glm::vec3> positions, normals;
    const auto load = [&](std::size_t first) { batch_points(pts, first, batch, positions, normals); };
    const auto sum = [&](std::size_t first) {
        const auto planes = r.finish_read();
        tbb::parallel_for(std::size_t(0), planes.size(), [&](std::size_t k) {
            out.cpu.stretch[first + k] = cpu::estimate_plane(t.stretch, planes.view(k)).irradiance;
            out.cpu.plane[first + k] = cpu::estimate_plane(t.plane, planes.view(k)).irradiance;
        });
    };
    const auto t0 = clock_type::now();
    std::optional<std::size_t> previous;
    for (std::size_t first = 0; first < pts.size(); first += batch) {
        load(first);
        r.render(positions, normals);
        r.start_read();
        if (previous) sum(*previous);
        previous = first;
    }
    if (previous) sum(*previous);
    out.cpu.seconds = seconds_since(t0);

    // The running profile as a renderer has it: every batch summed on the GPU with the kappa
    // of all planes rendered so far, its own batch included (gl::falloff_mode::running).
    gl::raster_record_sampler running(r, radius_limits{}, {plane_weighting::falloff, gl::falloff_mode::running});
    batch_points(pts, 0, pts.size(), positions, normals);
    std::vector<hemisphere_estimate> running_est(pts.size());
    const auto t2 = clock_type::now();
    running.estimate(positions, normals, running_est, out.cpu.running_kappa);
    out.running_seconds = seconds_since(t2);
    out.cpu.kappa = running.falloff_kappa();  // after the last batch: pooled over the run
    const auto running_cpu = out.cpu.falloff(out.cpu.running_kappa);
    for (std::size_t k = 0; k < pts.size(); ++k) {
        const double c = luminance(running_cpu[k]), d = std::abs(luminance(running_est[k].irradiance) - c);
        out.running_cpu_gpu_difference = std::max(out.running_cpu_gpu_difference, c > 0 ? d / c : d);
    }

    r.set_weights(t.stretch);
    std::vector<glm::dvec3> gpu(pts.size());
    const auto t1 = clock_type::now();
    for (std::size_t first = 0; first < pts.size(); first += batch) {
        load(first);
        r.render(positions, normals);
        const auto e = r.reduce();
        for (std::size_t k = 0; k < e.size(); ++k) gpu[first + k] = e[k].irradiance;
    }
    out.gpu_seconds = seconds_since(t1);
    for (std::size_t k = 0; k < pts.size(); ++k) {
        const double c = luminance(out.cpu.stretch[k]), d = std::abs(luminance(gpu[k]) - c);
        out.cpu_gpu_difference = std::max(out.cpu_gpu_difference, c > 0 ? d / c : d);
    }
    return out;
}

// How far the raster planes are from ray-cast planes of the same points, texel by texel:
// sqrt(sum w_i (L_raster - L_ray)^2 / sum w_i L_ray^2) over every texel of every point, on
// luminance, w_i the texel's cosine-weighted solid angle. Unlike the irradiance errors,
// errors of opposite sign (a shadow-map leak here, acne there) cannot cancel, so this is
// the measure to set the shadow maps' bias by.
double plane_texel_difference(const embree::reference_integrator& ref, const io::scene& scene, const gl_scene& g,
                              const std::vector<study_point>& pts, const plane_camera& cam, std::size_t batch) {
    const tables t(cam);
    gl::hemisphere_raster_options o;
    o.camera = cam;
    o.batch = batch;
    gl::hemisphere_raster r(scene, g.mesh, g.light, o);
    const std::size_t texels = std::size_t(cam.resolution) * cam.resolution;
    std::vector<double> squared(pts.size(), 0.0), norm(pts.size(), 0.0);  // per point: summed in order below
    std::vector<glm::vec3> positions, normals;
    for (std::size_t first = 0; first < pts.size(); first += batch) {
        batch_points(pts, first, batch, positions, normals);
        r.render(positions, normals);
        r.start_read();
        const auto planes = r.finish_read();
        tbb::parallel_for(std::size_t(0), planes.size(), [&](std::size_t k) {
            image<glm::vec3> radiance(cam.resolution, cam.resolution);
            image<float> distance(cam.resolution, cam.resolution);
            embree::sample_plane(ref, cam, pts[first + k].p, pts[first + k].n, radiance.view(), distance.view());
            const glm::vec3* raster = planes.radiance[k].data();
            for (std::size_t i = 0; i < texels; ++i) {
                const double lr = rec709_luminance<double, glm::dvec3>(glm::dvec3(raster[i]));
                const double lc = rec709_luminance<double, glm::dvec3>(glm::dvec3(radiance.data()[i]));
                squared[first + k] += t.plane.irradiance[i] * (lr - lc) * (lr - lc);
                norm[first + k] += t.plane.irradiance[i] * lc * lc;
            }
        });
    }
    const double total = std::accumulate(squared.begin(), squared.end(), 0.0);
    const double total_norm = std::accumulate(norm.begin(), norm.end(), 0.0);
    return total_norm > 0 ? std::sqrt(total / total_norm) : 0.0;
}
#endif

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"bounce hemisphere study: single-plane sampling (plane, coverage, stretching, fall-off) vs a "
                 "Monte Carlo reference"};
    std::string scene_arg = "sponza";
    std::uint32_t resolution = 64, reference_spp = 16384;
    double aperture = 126.0, reference_target = 0.005, turn = 0.0;
    bool hashed_turn = false;
    std::size_t points = 10000, sweep_points = 1000, batch = 64;
    std::uint64_t seed = 1;
    int shadow_resolution = 4096;
#ifdef BOUNCE_STUDY_WITH_GL
    gl::direct_light_options shadows;  // its resolution comes from shadow_resolution
#endif
    bool sweep = false, no_raster = false, no_ray_cast = false, no_cache = false;
    std::size_t texel_points = 0;
    fs::path json_path, points_csv, cache_dir = study::default_cache_dir();
    app.add_option("--scene", scene_arg, "cornell, a scene.json, its folder, an .obj, or a name under the scenes folder")
        ->capture_default_str();
    app.add_option("--resolution", resolution, "plane resolution N (N x N pixels)")
        ->check(CLI::Range(1u, 1024u))
        ->capture_default_str();
    app.add_option("--aperture", aperture, "full angle of the plane's square field of view, degrees")
        ->check(CLI::Range(1.0, 179.0))
        ->capture_default_str();
    app.add_option("--plane-turn", turn, "turn of every plane about its normal from orthonormal_basis(n), degrees in [0, 90)")
        ->check(examples::quarter_turn_deg)
        ->capture_default_str();
    app.add_flag("--hashed-turn", hashed_turn, "also turn each plane by its own angle in [0, 90) degrees, hashed from its point");
    app.add_option("--points", points, "random visible points (fixed seed)")->check(CLI::Range(1, 200000))->capture_default_str();
    app.add_option("--seed", seed, "seed of the points and of the reference")->capture_default_str();
    app.add_option("--reference-spp", reference_spp, "reference rays per point and half (doubled until the error target)")
        ->check(CLI::Range(16u, 1u << 22))
        ->capture_default_str();
    app.add_option("--reference-target", reference_target, "largest acceptable relative RMS error of the reference")
        ->check(CLI::Range(1e-4, 0.5))
        ->capture_default_str();
    app.add_flag("--sweep", sweep, "also run resolutions 16..128 x apertures 90..150");
    app.add_option("--sweep-points", sweep_points, "points per setting of the sweep (the first of --points)")
        ->check(CLI::Range(1, 200000))
        ->capture_default_str();
    app.add_option("--batch", batch, "records per raster atlas, and per step of the running fall-off profile")
        ->check(CLI::Range(1, 1024))
        ->capture_default_str();
    app.add_option("--shadow-resolution", shadow_resolution, "texels per side of the raster sampler's shadow maps")
        ->check(CLI::Range(64, 8192))
        ->capture_default_str();
#ifdef BOUNCE_STUDY_WITH_GL
    app.add_option("--shadow-normal-offset", shadows.normal_offset_texels,
                   "raster sampler: shadow lookups moved this many texels along n")
        ->check(examples::finite_non_negative)->capture_default_str();
    app.add_option("--shadow-slope-bias", shadows.slope_bias, "raster sampler: shadow depth bias in depth slopes per texel")
        ->check(examples::finite_non_negative)->capture_default_str();
#endif
    app.add_option("--texel-points", texel_points,
                   "also compare raster and ray-cast planes texel by texel on this many points (the first of --points)")
        ->capture_default_str();
    app.add_flag("--no-raster", no_raster, "skip the GL raster sampler");
    app.add_flag("--no-ray-cast", no_ray_cast, "skip the Embree ray-cast sampler");
    app.add_option("--cache-dir", cache_dir, "where the reference is cached ($BOUNCE_CACHE)")->capture_default_str();
    app.add_flag("--no-cache", no_cache, "neither read nor write the reference cache");
    app.add_option("--json", json_path, "run report");
    app.add_option("--points-csv", points_csv, "per-point luminance of the reference and of every estimate (CSV)");
    CLI11_PARSE(app, argc, argv);

    try {
        const io::scene scene = io::load_scene_arg(scene_arg);
        const plane_camera cam{resolution, aperture, turn, hashed_turn};
        cam.validate();
        const embree::accel bvh(scene);
        const embree::reference_integrator ref(bvh, scene);
        const std::size_t K = std::max(points, sweep ? sweep_points : std::size_t(0));
        const auto pts = pick_points(bvh, scene, K, seed);
        fmt::print("hemisphere_study: {} ({} triangles), {} points, plane {}^2 at {} deg, turned {} deg{}\n", scene.name,
                   scene.triangles.size(), K, resolution, aperture, turn, hashed_turn ? " + hashed" : "");

        const auto t_ref = clock_type::now();
        const reference_set reference =
            compute_reference(ref, scene, pts, reference_spp, seed, reference_target, cache_dir, !no_cache,
                              bvh.owner().config());
        const double reference_seconds = seconds_since(t_ref);
        fmt::print("  reference: 2 x {} rays per point, own error {:.3f}% ({}, {:.1f} s)\n", reference.spp,
                   100 * reference.own_error, reference.from_cache ? "cache" : "computed", reference_seconds);

        const auto first = [&](const std::vector<study_point>& v, std::size_t n) {
            return std::vector<study_point>(v.begin(), v.begin() + std::ptrdiff_t(std::min(n, v.size())));
        };
        const auto first_ref = [&](std::size_t n) {
            return std::vector<glm::dvec3>(reference.E.begin(), reference.E.begin() + std::ptrdiff_t(std::min(n, reference.E.size())));
        };
        const auto main_pts = first(pts, points);
        const auto main_ref = first_ref(points);

        json report_error = json::object(), records_per_s = json::object(), extra = json::object();
        const auto print_row = [](const char* sampler, const json& e, double rps) {
            fmt::print("  {:<16} plane {:6.2f}%  coverage {:6.2f}%  stretch {:6.2f}%  falloff {:6.2f}% (kappa {:.3f}; "
                       "running {:6.2f}%)  {:8.1f} records/s\n",
                       sampler, 100 * e["rms_plane"].get<double>(), 100 * e["rms_coverage"].get<double>(),
                       100 * e["rms_stretch"].get<double>(), 100 * e["rms_falloff"].get<double>(),
                       e["falloff_kappa"].get<double>(), 100 * e["rms_falloff_running"].get<double>(), rps);
        };

#ifdef BOUNCE_STUDY_WITH_GL
        std::optional<gl::context> context;
        std::optional<gl_scene> gls;
        if (!no_raster) {
            try {
                context.emplace();
                shadows.shadow_resolution = shadow_resolution;
                shadows.validate();
                gls.emplace(scene, shadows);
                fmt::print("  GL: {} ({})\n", context->renderer(), context->platform());
            } catch (const gl::gl_error& e) {
                fmt::print(stderr, "  no GL raster sampler: {}\n", e.what());
                no_raster = true;
            }
        }
        const auto run_raster = [&](const std::vector<study_point>& p, const plane_camera& c) {
            return raster(scene, *gls, p, c, std::min(batch, p.size()));
        };
#else
        no_raster = true;
#endif
        std::optional<estimates> raster_main, ray_main;
        if (!no_raster) {
#ifdef BOUNCE_STUDY_WITH_GL
            const auto r = run_raster(main_pts, cam);
            raster_main = r.cpu;
            const json e = r.cpu.errors(main_ref);
            report_error["raster"] = e;
            records_per_s["raster"] = double(main_pts.size()) / r.cpu.seconds;
            records_per_s["raster_gpu_sum"] = double(main_pts.size()) / r.gpu_seconds;
            extra["raster_cpu_gpu_max_relative_difference"] = r.cpu_gpu_difference;
            records_per_s["raster_falloff_running"] = double(main_pts.size()) / r.running_seconds;
            extra["raster_running_cpu_gpu_max_relative_difference"] = r.running_cpu_gpu_difference;
            print_row("raster (CPU sum)", e, double(main_pts.size()) / r.cpu.seconds);
            fmt::print("  raster (GPU sum)  {:8.1f} records/s; CPU and GPU sums differ by at most {:.2e} (relative)\n",
                       double(main_pts.size()) / r.gpu_seconds, r.cpu_gpu_difference);
            fmt::print("  raster (running)  {:8.1f} records/s (record sampler, running fall-off: read-back, profile, GPU "
                       "sum); its sums differ from the CPU's by at most {:.2e} (relative)\n",
                       double(main_pts.size()) / r.running_seconds, r.running_cpu_gpu_difference);
            if (texel_points > 0) {
                const auto tp = first(pts, std::min(texel_points, pts.size()));
                const double d = plane_texel_difference(ref, scene, *gls, tp, cam, std::min(batch, tp.size()));
                report_error["raster_texel_difference"] = d;
                fmt::print("  raster against ray-cast planes, texel by texel ({} points): {:.2f}%\n", tp.size(), 100 * d);
            }
#endif
        }
        if (!no_ray_cast) {
            ray_main = ray_cast(ref, main_pts, cam, batch);
            const json e = ray_main->errors(main_ref);
            report_error["ray_cast"] = e;
            records_per_s["ray_cast"] = double(main_pts.size()) / ray_main->seconds;
            print_row("ray cast", e, double(main_pts.size()) / ray_main->seconds);
        }
        // The headline figures: the raster sampler's (the seed's method) where it ran.
        for (const char* sampler : {"ray_cast", "raster"})
            if (report_error.contains(sampler)) {
                // A copy: inserting into report_error may move the object being iterated.
                const json figures = report_error[sampler];
                for (const auto& [k, v] : figures.items()) report_error[k] = v;
            }
        if (report_error.contains("rms_stretch")) report_error["rel_rms"] = report_error["rms_stretch"];

        json sweep_rows = json::array();
        if (sweep) {
            const auto sp = first(pts, sweep_points);
            const auto sref = first_ref(sweep_points);
            for (std::uint32_t n : {16u, 32u, 48u, 64u, 96u, 128u})
                for (double ap : {90.0, 105.0, 120.0, 126.0, 135.0, 140.0, 150.0}) {
                    const plane_camera c{n, ap, turn, hashed_turn};
                    const auto add_row = [&](const char* sampler, const estimates& e) {
                        json row = {{"sampler", sampler}, {"resolution", n}, {"aperture", ap}};
                        const json errors = e.errors(sref);
                        for (const auto& [k, v] : errors.items()) row[k] = v;
                        row["records_per_s"] = double(sp.size()) / e.seconds;
                        sweep_rows.push_back(row);
                        print_row(fmt::format("{} {}^2 {}", sampler, n, ap).c_str(), row, row["records_per_s"].get<double>());
                    };
                    if (!no_ray_cast) add_row("ray_cast", ray_cast(ref, sp, c, batch));
#ifdef BOUNCE_STUDY_WITH_GL
                    if (!no_raster) add_row("raster", run_raster(sp, c).cpu);
#endif
                }
        }

        if (!points_csv.empty()) {
            // One row per point: where it is, the reference, and each sampler's four estimates
            // (luminance), so outliers can be found and plotted.
            std::ofstream csv(points_csv);
            csv << "px,py,pz,nx,ny,nz,reference";
            for (const auto& [name, e] : {std::pair{"raster", &raster_main}, std::pair{"ray_cast", &ray_main}})
                if (*e) csv << fmt::format(",{0}_plane,{0}_coverage,{0}_stretch,{0}_falloff", name);
            csv << "\n";
            std::vector<std::vector<glm::dvec3>> falloffs;
            for (const auto* e : {&raster_main, &ray_main})
                if (*e) falloffs.push_back((*e)->falloff());
            for (std::size_t k = 0; k < main_pts.size(); ++k) {
                const auto& [p, n] = main_pts[k];
                csv << fmt::format("{},{},{},{},{},{},{}", p.x, p.y, p.z, n.x, n.y, n.z, luminance(main_ref[k]));
                std::size_t f = 0;
                for (const auto* e : {&raster_main, &ray_main})
                    if (*e) {
                        const estimates& est = **e;
                        csv << fmt::format(",{},{},{},{}", luminance(est.plane[k]), luminance(est.plane[k] * est.coverage_scale),
                                           luminance(est.stretch[k]), luminance(falloffs[f++][k]));
                    }
                csv << "\n";
            }
            if (!csv) throw parameter_error("points-csv", "could not write " + points_csv.string());
        }

        if (!json_path.empty()) {
            study::run_report report;
            report.technique = "hemisphere_study";
            report.scene = scene.name;
            report.width = resolution;
            report.height = resolution;
            report.backend = no_raster ? "embree" : (no_ray_cast ? "gl" : "gl+embree");
            report.parameters["resolution"] = resolution;
            report.parameters["aperture_deg"] = aperture;
            report.parameters["plane_turn_deg"] = turn;
            report.parameters["hashed_turn"] = hashed_turn;
            report.parameters["points"] = points;
            report.parameters["seed"] = seed;
            report.parameters["batch"] = batch;
            report.parameters["embree_config"] = bvh.owner().config();
            report.parameters["shadow_resolution"] = shadow_resolution;
#ifdef BOUNCE_STUDY_WITH_GL
            report.parameters["shadow_normal_offset"] = shadows.normal_offset_texels;
            report.parameters["shadow_slope_bias"] = shadows.slope_bias;
#endif
            report.parameters["reference_spp_per_half"] = reference.spp;
#ifdef BOUNCE_STUDY_WITH_GL
            if (context && !no_raster) report.gl_renderer = context->renderer();
#endif
            report.set_count("records", points);
            json j = report.to_json();
            j["timings_ms"] = json::object();
            if (raster_main) j["timings_ms"]["raster"] = 1000 * raster_main->seconds;
            if (ray_main) j["timings_ms"]["ray_cast"] = 1000 * ray_main->seconds;
            j["timings_ms"]["reference"] = 1000 * reference_seconds;
            j["error"] = report_error;
            j["records_per_s"] = records_per_s;
            j["reference"] = {{"rays_per_point", 2 * reference.spp},
                              {"own_rel_rms", reference.own_error},
                              {"from_cache", reference.from_cache}};
            for (const auto& [k, v] : extra.items()) j[k] = v;
            if (sweep) {
                j["sweep_points"] = sweep_points;
                j["sweep"] = sweep_rows;
            }
            if (json_path.has_parent_path()) fs::create_directories(json_path.parent_path());
            std::ofstream(json_path) << j.dump(2) << "\n";
            fmt::print("wrote {}\n", json_path.string());
        }
    } catch (const bounce::error& e) {
        fmt::print(stderr, "hemisphere_study: {}\n", e.what());
        return 1;
    }
    return 0;
}
