#include <bounce/study/hemisphere_comparison.hpp>

#include <bounce/cpu/plane_estimate.hpp>
#include <bounce/embree/plane_sampler.hpp>
#include <bounce/embree/ray_cast_gbuffer.hpp>
#include <bounce/io/output_files.hpp>
#include <bounce/luminance.hpp>
#include <bounce/cache/plane_weights.hpp>
#include <bounce/cache/radial_profile.hpp>
#include <bounce/sampling.hpp>
#include <bounce/study/content_hash.hpp>
#include <bounce/study/image_comparison.hpp>
#include <bounce/study/stage_timer.hpp>

#include <fmt/core.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <fstream>
#include <iterator>
#include <numeric>

namespace bounce::study {

namespace {

double luminance(const glm::dvec3& c) { return rec709_luminance<double, glm::dvec3>(c); }

template <class T>
std::vector<T> prefix(const std::vector<T>& v, std::size_t n) {
    return std::vector<T>(v.begin(), v.begin() + std::ptrdiff_t(std::min(n, v.size())));
}

// The cached halves: a then b, size() glm::vec3 each, nothing else.
bool load_halves(const std::filesystem::path& file, std::vector<glm::vec3>& a, std::vector<glm::vec3>& b) {
    std::ifstream in(file, std::ios::binary);
    if (!in) return false;
    in.read(reinterpret_cast<char*>(a.data()), std::streamsize(a.size() * sizeof(glm::vec3)));
    in.read(reinterpret_cast<char*>(b.data()), std::streamsize(b.size() * sizeof(glm::vec3)));
    return bool(in) && in.peek() == std::char_traits<char>::eof();
}

void store_halves(const std::filesystem::path& file, const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
    std::error_code ec;
    std::filesystem::create_directories(file.parent_path(), ec);
    if (ec) throw io::output_error(file, "cannot make its folder: " + ec.message());
    const std::filesystem::path tmp = file.string() + ".tmp";
    {
        std::ofstream out(tmp, std::ios::binary);
        out.write(reinterpret_cast<const char*>(a.data()), std::streamsize(a.size() * sizeof(glm::vec3)));
        out.write(reinterpret_cast<const char*>(b.data()), std::streamsize(b.size() * sizeof(glm::vec3)));
        out.close();
        if (!out) {
            std::filesystem::remove(tmp, ec);
            throw io::output_error(tmp, "could not write the cached reference");
        }
    }
    std::filesystem::rename(tmp, file, ec);
    if (ec) throw io::output_error(file, "could not move the cached reference into place: " + ec.message());
}

}  // namespace

// ---- points and reference ---------------------------------------------------------------

surface_points surface_points::first(std::size_t n) const { return {prefix(positions, n), prefix(normals, n)}; }

surface_points visible_points(const embree::accel& bvh, const scene_view& scene, const bounce::camera& cam,
                              std::size_t count, std::uint64_t seed, std::size_t side) {
    require(side >= 1, "side", "must be at least 1");
    const auto g = embree::ray_cast_gbuffer(bvh, scene, cam, side, side);
    std::vector<std::size_t> covered;
    for (std::size_t y = 0; y < side; ++y)
        for (std::size_t x = 0; x < side; ++x)
            if (std::isfinite(g.depth(x, y))) covered.push_back(y * side + x);
    if (covered.size() < count)
        throw parameter_error("points", "the camera sees only " + std::to_string(covered.size()) + " pixels of " +
                                            std::to_string(side) + "^2");
    pcg32 rng(seed);
    surface_points pts;
    for (std::size_t k = 0; k < count; ++k) {
        const std::size_t j = k + std::size_t(rng.next_u32()) % (covered.size() - k);
        std::swap(covered[k], covered[j]);
        const std::size_t x = covered[k] % side, y = covered[k] / side;
        pts.positions.push_back(g.position(x, y));
        pts.normals.push_back(glm::normalize(g.normal(x, y)));
    }
    return pts;
}

void point_reference_settings::validate() const {
    require(spp >= 1, "spp", "must be at least 1");
    require(target > 0 && target < 1, "target", "must lie in (0, 1)");
}

std::vector<glm::dvec3> point_reference::first(std::size_t n) const { return prefix(irradiance, n); }

point_reference indirect_point_reference(const embree::reference_integrator& ref, const surface_points& pts,
                                         const point_reference_settings& s) {
    s.validate();
    require(pts.normals.size() == pts.size(), "points", "one normal per position");
    std::uint32_t spp = s.spp;
    for (std::uint32_t attempt = 0;; ++attempt) {
        fnv1a_hash key;  // the points as (position, normal) pairs, as the first version hashed them
        for (std::size_t k = 0; k < pts.size(); ++k) {
            key.value(pts.positions[k]);
            key.value(pts.normals[k]);
        }
        key.value(spp);
        key.value(s.seed);
        if (!s.device_config.empty()) key.text(s.device_config);
        const std::filesystem::path file =
            s.cache_dir / fmt::format("hemisphere-reference-{}-{}pts-{}spp-{:016x}.bin", s.scene_name, pts.size(), spp,
                                      key.digest());
        std::vector<glm::vec3> a(pts.size()), b(pts.size());
        const bool loaded = s.use_cache && load_halves(file, a, b);
        if (!loaded) {
            fmt::print(stderr, "  reference: {} points x 2 x {} rays...\n", pts.size(), spp);
            tbb::parallel_for(std::size_t(0), pts.size(), [&](std::size_t k) {
                const glm::vec3 p = pts.positions[k], n = pts.normals[k];
                a[k] = ref.indirect_irradiance(p, n, spp, embree::derive_seed(s.seed, 1, k));
                b[k] = ref.indirect_irradiance(p, n, spp, embree::derive_seed(s.seed, 2, k));
            });
            if (s.use_cache) store_halves(file, a, b);
        }
        point_reference r;
        r.spp = spp;
        r.from_cache = loaded;
        double diff2 = 0, sig2 = 0;
        for (std::size_t k = 0; k < pts.size(); ++k) {
            r.irradiance.push_back((glm::dvec3(a[k]) + glm::dvec3(b[k])) / 2.0);
            const double d = luminance(a[k]) - luminance(b[k]), m = luminance(r.irradiance.back());
            diff2 += d * d;
            sig2 += m * m;
        }
        r.own_rel_rms = sig2 > 0 ? std::sqrt(diff2) / 2 / std::sqrt(sig2) : 0;
        if (r.own_rel_rms <= s.target || attempt >= 3) return r;
        fmt::print(stderr, "  reference error {:.3f}% above {:.2f}%: doubling the rays\n", 100 * r.own_rel_rms,
                   100 * s.target);
        spp *= 2;
    }
}

// ---- estimates and their errors -----------------------------------------------------------

std::vector<glm::dvec3> plane_estimates::coverage() const {
    std::vector<glm::dvec3> c;
    for (const auto& e : plane) c.push_back(e * coverage_scale);
    return c;
}

std::vector<glm::dvec3> plane_estimates::falloff() const { return falloff({}); }

std::vector<glm::dvec3> plane_estimates::falloff(std::span<const double> kappas) const {
    require(kappas.empty() || kappas.size() == size(), "kappas", "must be empty or have one entry per record");
    std::vector<glm::dvec3> f;
    for (std::size_t k = 0; k < size(); ++k) f.push_back(plane[k] + (kappas.empty() ? kappa : kappas[k]) * (stretch[k] - plane[k]));
    return f;
}

double plane_estimates::records_per_s() const { return ms > 0 ? 1000.0 * double(size()) / ms : 0.0; }

double point_rel_rms(std::span<const glm::dvec3> x, std::span<const glm::dvec3> ref) {
    require(x.size() == ref.size() && !x.empty(), "estimates", "must have one entry per reference point");
    image<glm::vec3> xi(x.size(), 1), ri(ref.size(), 1);
    for (std::size_t k = 0; k < x.size(); ++k) {
        xi(k, 0) = glm::vec3(x[k]);
        ri(k, 0) = glm::vec3(ref[k]);
    }
    return compare_luminance(xi.view(), ri.view()).rel_rms;
}

nlohmann::ordered_json plane_estimate_errors(const plane_estimates& e, std::span<const glm::dvec3> ref) {
    return {{"rms_plane", point_rel_rms(e.plane, ref)},
            {"rms_coverage", point_rel_rms(e.coverage(), ref)},
            {"rms_stretch", point_rel_rms(e.stretch, ref)},
            {"rms_falloff", point_rel_rms(e.falloff(), ref)},
            {"falloff_kappa", e.kappa},
            {"rms_falloff_running", point_rel_rms(e.falloff(e.running_kappa), ref)},
            {"falloff_kappa_first_batch", e.running_kappa.empty() ? 1.0 : e.running_kappa.front()}};
}

nlohmann::ordered_json with_headline_errors(const nlohmann::ordered_json& errors) {
    nlohmann::ordered_json out = errors;
    for (const char* sampler : {"ray_cast", "raster"})
        if (errors.contains(sampler))
            for (const auto& [k, v] : errors[sampler].items()) out[k] = v;
    if (out.contains("rms_stretch")) out["rel_rms"] = out["rms_stretch"];
    return out;
}

std::vector<glm::dvec3> irradiance_of(std::span<const hemisphere_estimate> estimates) {
    std::vector<glm::dvec3> e;
    for (const auto& x : estimates) e.push_back(x.irradiance);
    return e;
}

double max_relative_luminance_difference(std::span<const glm::dvec3> x, std::span<const glm::dvec3> ref) {
    require(x.size() == ref.size(), "x", "must have one entry per reference value");
    double worst = 0;
    for (std::size_t k = 0; k < x.size(); ++k) {
        const double c = luminance(ref[k]), d = std::abs(luminance(x[k]) - c);
        worst = std::max(worst, c > 0 ? d / c : d);
    }
    return worst;
}

// ---- summing planes -----------------------------------------------------------------------

struct plane_estimate_sums::impl {
    plane_weights plane, stretch;
    bool profile;
    tbb::enumerable_thread_specific<radial_profile> profiles;
    impl(const plane_camera& cam, bool with_profile)
        : plane(make_plane_weights(cam, plane_weighting::plane)),
          stretch(make_plane_weights(cam, plane_weighting::stretch)), profile(with_profile),
          profiles([cam] { return radial_profile(cam); }) {}
};

plane_estimate_sums::plane_estimate_sums(const plane_camera& camera, std::size_t count, bool profile)
    : impl_((camera.validate(), std::make_unique<impl>(camera, profile))) {
    out_.plane.resize(count);
    out_.stretch.resize(count);
    out_.running_kappa.assign(count, 1.0);
    out_.coverage_scale = make_plane_weights(camera, plane_weighting::coverage).scale;
}

plane_estimate_sums::~plane_estimate_sums() = default;

void plane_estimate_sums::add(std::size_t k, plane_view v) {
    require(k < out_.size(), "record", "index beyond the records' count");
    out_.stretch[k] = cpu::estimate_plane(impl_->stretch, v).irradiance;
    out_.plane[k] = cpu::estimate_plane(impl_->plane, v).irradiance;
    if (impl_->profile) impl_->profiles.local().add(v.radiance);
}

void plane_estimate_sums::add(std::size_t first, std::span<const plane_view> planes) {
    tbb::parallel_for(std::size_t(0), planes.size(), [&](std::size_t k) { add(first + k, planes[k]); });
}

void plane_estimate_sums::end_batch(std::size_t first, std::size_t last) {
    require(impl_->profile, "profile", "these sums keep no running profile");
    require(first <= last && last <= out_.size(), "batch", "records beyond the count");
    // Every plane so far: the threads' profiles pooled (each holds what its thread added).
    auto& profiles = impl_->profiles;
    double kappa = 1.0;  // border stretching before any plane, as the raster's running mode
    if (!profiles.empty()) {
        radial_profile all = *profiles.begin();
        for (auto it = std::next(profiles.begin()); it != profiles.end(); ++it) all.merge(*it);
        kappa = all.falloff_factor();
    }
    std::fill(out_.running_kappa.begin() + std::ptrdiff_t(first), out_.running_kappa.begin() + std::ptrdiff_t(last), kappa);
}

plane_estimates plane_estimate_sums::result(double ms) const {
    plane_estimates e = out_;
    e.kappa = e.running_kappa.empty() ? 1.0 : e.running_kappa.back();
    e.ms = ms;
    return e;
}

plane_estimates ray_cast_plane_estimates(const embree::reference_integrator& ref, const surface_points& pts,
                                         const plane_camera& camera, std::size_t batch) {
    require(batch >= 1, "batch", "must be at least 1");
    plane_estimate_sums sums(camera, pts.size(), true);
    const auto t0 = std::chrono::steady_clock::now();
    for (std::size_t first = 0; first < pts.size(); first += batch) {
        const std::size_t count = std::min(batch, pts.size() - first);
        embree::sample_planes(ref, camera, std::span(pts.positions).subspan(first, count),
                              std::span(pts.normals).subspan(first, count),
                              [&](std::size_t k, plane_view v) { sums.add(first + k, v); });
        sums.end_batch(first, first + count);
    }
    return sums.result(ms_since(t0));
}

// ---- texel differences --------------------------------------------------------------------

plane_texel_difference::plane_texel_difference(const embree::reference_integrator& ref, const plane_camera& camera,
                                               const surface_points& points)
    : ref_(ref), camera_((camera.validate(), camera)), points_(points),
      weights_(make_plane_weights(camera, plane_weighting::plane).irradiance), squared_(points.size(), 0.0),
      norm_(points.size(), 0.0) {}

void plane_texel_difference::add(std::size_t first, std::span<const plane_view> planes) {
    require(first + planes.size() <= points_.size(), "planes", "more planes than points");
    const std::size_t N = camera_.resolution;
    for (const plane_view& v : planes)
        require(v.radiance.width() == N && v.radiance.height() == N, "planes", "must be resolution x resolution");
    tbb::parallel_for(std::size_t(0), planes.size(), [&](std::size_t k) {
        image<glm::vec3> radiance(N, N);
        image<float> distance(N, N);
        const std::size_t p = first + k;
        embree::sample_plane(ref_, camera_, points_.positions[p], points_.normals[p], radiance.view(), distance.view());
        double sq = 0, nm = 0;
        for (std::size_t j = 0; j < N; ++j)
            for (std::size_t i = 0; i < N; ++i) {
                const double w = weights_[j * N + i];
                const double lr = luminance(glm::dvec3(planes[k].radiance(i, j)));
                const double lc = luminance(glm::dvec3(radiance(i, j)));
                sq += w * (lr - lc) * (lr - lc);
                nm += w * lc * lc;
            }
        squared_[p] += sq;
        norm_[p] += nm;
    });
}

double plane_texel_difference::value() const {
    const double total = std::accumulate(squared_.begin(), squared_.end(), 0.0);
    const double total_norm = std::accumulate(norm_.begin(), norm_.end(), 0.0);
    return total_norm > 0 ? std::sqrt(total / total_norm) : 0.0;
}

// ---- the sweep and the per-point table ----------------------------------------------------

nlohmann::ordered_json plane_sweep(std::span<const plane_sweep_sampler> samplers, std::span<const glm::dvec3> ref,
                                   double turn_deg, bool hashed_turn,
                                   const std::function<void(const nlohmann::ordered_json& row)>& on_row) {
    nlohmann::ordered_json rows = nlohmann::ordered_json::array();
    for (std::uint32_t n : {16u, 32u, 48u, 64u, 96u, 128u})
        for (double ap : {90.0, 105.0, 120.0, 126.0, 135.0, 140.0, 150.0}) {
            const plane_camera cam{n, ap, turn_deg, hashed_turn};
            for (const plane_sweep_sampler& s : samplers) {
                const plane_estimates e = s.estimate(cam);
                nlohmann::ordered_json row = {{"sampler", s.name}, {"resolution", n}, {"aperture", ap}};
                const nlohmann::ordered_json errors = plane_estimate_errors(e, ref);
                for (const auto& [k, v] : errors.items()) row[k] = v;
                row["records_per_s"] = e.records_per_s();
                if (on_row) on_row(row);
                rows.push_back(std::move(row));
            }
        }
    return rows;
}

void write_plane_points_csv(const std::filesystem::path& file, const surface_points& pts,
                            std::span<const glm::dvec3> ref,
                            std::span<const std::pair<std::string, const plane_estimates*>> estimates) {
    require(ref.size() == pts.size(), "reference", "must have one entry per point");
    for (const auto& [name, e] : estimates)
        require(e && e->size() == pts.size(), "estimates", "must have one entry per point");
    std::string csv = "px,py,pz,nx,ny,nz,reference";
    for (const auto& [name, e] : estimates) csv += fmt::format(",{0}_plane,{0}_coverage,{0}_stretch,{0}_falloff", name);
    csv += "\n";
    std::vector<std::vector<glm::dvec3>> falloffs;
    for (const auto& [name, e] : estimates) falloffs.push_back(e->falloff());
    for (std::size_t k = 0; k < pts.size(); ++k) {
        const glm::vec3 p = pts.positions[k], n = pts.normals[k];
        csv += fmt::format("{},{},{},{},{},{},{}", p.x, p.y, p.z, n.x, n.y, n.z, luminance(ref[k]));
        for (std::size_t s = 0; s < estimates.size(); ++s) {
            const plane_estimates& e = *estimates[s].second;
            csv += fmt::format(",{},{},{},{}", luminance(e.plane[k]), luminance(e.plane[k] * e.coverage_scale),
                               luminance(e.stretch[k]), luminance(falloffs[s][k]));
        }
        csv += "\n";
    }
    io::write_text_file(file, csv);
}

}  // namespace bounce::study
